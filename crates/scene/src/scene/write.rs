//! The scene writer: a [`SceneModel`] as a TOML scene, its meshes as OBJ files and its
//! scripts as Lua files, for `gantry convert` (a CoppeliaSim `.ttt` becomes text a user
//! can diff and edit).
//!
//! Pure: it returns the files as `(relative path, bytes)` and the caller writes them.
//! Loading the written TOML with [`super::load_scene`] gives the same model: the same
//! objects in the same order (so the same handles), poses to the last bit or within
//! 1e-12 (Euler angles are used only where they give the rotation back that closely,
//! else a quaternion), the same meshes' triangles, scripts' text and settings.
//! Numbers are written as the shortest decimal that reads back as the same `f64`
//! (`f32` for colours and mesh coordinates).
//!
//! What the format cannot hold is listed in [`SceneFiles::notes`] and in a
//! `# gantry convert:` comment at the top of the TOML.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::Arc;

use super::model::{
    CollectionModel, CollectionScope, Geometry, IkGroupModel, IkMethodModel, JointMode, JointType, LightModel,
    LightType, MassModel, MeshData, ObjectModel, ObjectModelKind, PathModel, Projection, ProximityModel, RenderMode,
    SceneModel, ShapeModel, TextureModel, VisionModel, VisualTexture,
};
use super::obj_write::write_obj;
use crate::math::{Pose, Quat, euler_from_quat, quat_from_euler, quat_to_array};

/// Largest difference between a rotation and the one its written Euler angles give
/// back (quaternion components) for the angles to be written; otherwise the quaternion
/// is. Near gimbal lock the Euler form loses far more than this.
const EULER_TOLERANCE: f64 = 1e-12;

/// The files of a converted scene.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SceneFiles {
    /// Paths relative to the output folder, and contents: the TOML scene first, then
    /// meshes (`meshes/*.obj`), scripts (`scripts/*.lua`) and textures (`textures/*.png`
    /// and their coordinates, `textures/*.uv`).
    pub files: Vec<(PathBuf, Vec<u8>)>,
    /// What the scene file could not hold (also at the top of the TOML).
    pub notes: Vec<String>,
}

/// Why a model cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// A value is NaN or infinite: the loader refuses such scene files.
    #[error("object '{object}': {what} is not a finite number")]
    NotFinite {
        /// The object's name in the written file (or `[simulation]`).
        object: String,
        /// Which value.
        what: String,
    },
}

/// Writes `model` as `<stem>.toml` plus its meshes and scripts. `source` (the file it
/// came from) is named in the header comment.
///
/// # Errors
/// [`WriteError::NotFinite`] when a pose, size or parameter is not finite.
pub fn write_scene(model: &SceneModel, stem: &str, source: &str) -> Result<SceneFiles, WriteError> {
    let mut w = Writer {
        out: String::new(),
        files: Vec::new(),
        notes: Vec::new(),
        meshes: HashMap::new(),
        used_files: std::collections::HashSet::new(),
        object: String::new(),
        textures: model.textures.clone(),
        texture_files: HashMap::new(),
    };
    let names = unique_names(&model.objects);
    w.settings(model)?;
    for (k, o) in model.objects.iter().enumerate() {
        w.object = names[k].clone();
        w.object_entry(o, k, &names)?;
    }
    for [a, b] in &model.dummy_links {
        w.out.push_str("\n[[dummy_link]]\n");
        let _ = writeln!(w.out, "dummies = [{}, {}]", quote(&names[*a]), quote(&names[*b]));
    }
    for [a, b] in &model.ball_links {
        w.out.push_str("\n[[dummy_link]]\n");
        let _ = writeln!(w.out, "dummies = [{}, {}]", quote(&names[*a]), quote(&names[*b]));
        w.out.push_str("free_rotation = true\n");
    }
    for r in &model.referenced_handles {
        w.out.push_str("\n[[reference]]\n");
        let _ = writeln!(w.out, "object = {}", quote(&names[r.object]));
        let _ = writeln!(w.out, "tag = {}", quote(&r.tag));
        let targets: Vec<String> = r.targets.iter().map(|&t| quote(&names[t])).collect();
        let _ = writeln!(w.out, "objects = [{}]", targets.join(", "));
    }
    for p in &model.user_parameters {
        w.out.push_str("\n[[user_parameter]]\n");
        let _ = writeln!(w.out, "object = {}", quote(&names[p.object]));
        let _ = writeln!(w.out, "name = {}", quote(&p.name));
        let _ = writeln!(w.out, "unit = {}", quote(&p.unit));
        let _ = writeln!(w.out, "value = {}", quote(&p.value));
    }
    for g in &model.ik_groups {
        w.ik_group(g, &names)?;
    }
    for c in &model.collections {
        w.collection(c, &names);
    }
    for s in &model.scripts {
        let name = &names[s.object];
        let file = w.file_name("scripts", name, "lua");
        w.files.push((file.clone().into(), s.source.clone().into_bytes()));
        w.out.push_str("\n[[script]]\n");
        let _ = writeln!(w.out, "object = {}", quote(name));
        let _ = writeln!(w.out, "file = {}", quote(&file));
    }
    let body = std::mem::take(&mut w.out);

    let mut head = String::new();
    let _ = writeln!(
        head,
        "# {}: converted by `gantry convert` from {}.",
        one_line(stem),
        one_line(source)
    );
    head.push_str(
        "# Lengths in metres, angles in degrees (joint values of revolute joints too); see docs/scene-format.md.\n",
    );
    for n in &w.notes {
        let _ = writeln!(head, "# gantry convert: {}", one_line(n));
    }
    for warning in &model.warnings {
        let _ = writeln!(head, "# import: {}", one_line(warning));
    }
    head.push_str(&body);
    let mut files = vec![(PathBuf::from(format!("{stem}.toml")), head.into_bytes())];
    files.append(&mut w.files);
    Ok(SceneFiles { files, notes: w.notes })
}

struct Writer {
    /// The TOML being written.
    out: String,
    /// Mesh and script files.
    files: Vec<(PathBuf, Vec<u8>)>,
    notes: Vec<String>,
    /// Mesh files already written, by the address of their data (a mesh shared by a
    /// collision and a visual part, or by several shapes, is written once).
    meshes: HashMap<*const MeshData, String>,
    /// The file names given so far, lower case, for unique file names.
    used_files: std::collections::HashSet<String>,
    /// Name of the object being written, for errors.
    object: String,
    /// The scene's texture images, and the PNG file of each written so far.
    textures: Vec<TextureModel>,
    texture_files: HashMap<usize, String>,
}

impl Writer {
    /// One `[[ik_group]]` with its `[[ik_group.element]]` tables.
    fn ik_group(&mut self, g: &IkGroupModel, names: &[String]) -> Result<(), WriteError> {
        self.out.push_str("\n[[ik_group]]\n");
        let _ = writeln!(self.out, "name = {}", quote(&g.name));
        let method = match g.method {
            IkMethodModel::PseudoInverse => "pseudo_inverse",
            IkMethodModel::DampedLeastSquares => "damped_least_squares",
        };
        let _ = writeln!(self.out, "method = {}", quote(method));
        let _ = writeln!(self.out, "damping = {}", self.num("ik_group damping", g.damping)?);
        let _ = writeln!(self.out, "max_iterations = {}", g.max_iterations);
        let _ = writeln!(self.out, "explicit = {}", g.explicit);
        for e in &g.elements {
            self.out.push_str("\n[[ik_group.element]]\n");
            let _ = writeln!(self.out, "tip = {}", quote(&names[e.tip]));
            let _ = writeln!(self.out, "target = {}", quote(&names[e.target]));
            if let Some(b) = e.base {
                let _ = writeln!(self.out, "base = {}", quote(&names[b]));
            }
            let parts: Vec<&str> = [(1, "x"), (2, "y"), (4, "z"), (8, "alpha_beta"), (16, "gamma")]
                .into_iter()
                .filter(|(bit, _)| e.constraints & bit != 0)
                .map(|(_, n)| n)
                .collect();
            let _ = writeln!(self.out, "constraints = {}", quote(&parts.join("+")));
        }
        Ok(())
    }

    /// One `[[collection]]` with its `[[collection.item]]` tables.
    fn collection(&mut self, c: &CollectionModel, names: &[String]) {
        self.out.push_str("\n[[collection]]\n");
        let _ = writeln!(self.out, "name = {}", quote(&c.name));
        for i in &c.items {
            self.out.push_str("\n[[collection.item]]\n");
            let scope = match i.scope {
                CollectionScope::Object => "object",
                CollectionScope::Tree => "tree",
                CollectionScope::Chain => "chain",
                CollectionScope::All => "all",
            };
            let _ = writeln!(self.out, "scope = \"{scope}\"");
            if let Some(o) = i.object {
                let _ = writeln!(self.out, "object = {}", quote(&names[o]));
            }
            if i.remove {
                self.out.push_str("remove = true\n");
            }
            if i.exclude_base {
                self.out.push_str("exclude_base = true\n");
            }
        }
    }

    fn settings(&mut self, model: &SceneModel) -> Result<(), WriteError> {
        let s = &model.settings;
        self.object = "[simulation]".into();
        self.out.push_str("\n[simulation]\n");
        self.key("dt", s.dt)?;
        let _ = writeln!(self.out, "substeps = {}", s.substeps);
        let _ = writeln!(self.out, "collisions_every_substep = {}", s.collisions_every_substep);
        let _ = writeln!(self.out, "solver_iterations = {}", s.solver_iterations);
        self.key3("gravity", s.gravity)?;
        if s.seed != 0 {
            let _ = writeln!(self.out, "seed = {}", s.seed);
        }
        if let Some(c) = s.background {
            self.key3("background", c)?;
        }
        let srv = &model.server;
        if srv.bind.is_some() || srv.text_port.is_some() || srv.zmq_port.is_some() || srv.http_port.is_some() {
            self.out.push_str("\n[server]\n");
            if let Some(b) = &srv.bind {
                let _ = writeln!(self.out, "bind = {}", quote(b));
            }
            for (key, port) in [
                ("text_port", srv.text_port),
                ("zmq_port", srv.zmq_port),
                ("http_port", srv.http_port),
            ] {
                if let Some(p) = port {
                    let _ = writeln!(self.out, "{key} = {p}");
                }
            }
        }
        Ok(())
    }

    fn object_entry(&mut self, o: &ObjectModel, k: usize, names: &[String]) -> Result<(), WriteError> {
        self.out.push_str("\n[[object]]\n");
        let _ = writeln!(self.out, "name = {}", quote(&names[k]));
        let _ = writeln!(self.out, "kind = \"{}\"", kind_name(&o.kind));
        if o.alias != names[k] {
            let _ = writeln!(self.out, "alias = {}", quote(&o.alias));
        }
        if let Some(p) = o.parent {
            let _ = writeln!(self.out, "parent = {}", quote(&names[p]));
        }
        if o.layer != 1 {
            let _ = writeln!(self.out, "layer = {}", o.layer);
        }
        if o.model_base {
            self.out.push_str("model_base = true\n");
        }
        if !o.extension.is_empty() {
            let _ = writeln!(self.out, "extension_string = {}", quote(&o.extension));
        }
        self.pose(&o.local)?;
        match &o.kind {
            ObjectModelKind::Shape(s) => self.shape(s),
            ObjectModelKind::Joint(j) => {
                let unit = |v: f64| {
                    if j.joint_type == JointType::Revolute {
                        v.to_degrees()
                    } else {
                        v
                    }
                };
                let joint = match j.joint_type {
                    JointType::Revolute => "revolute",
                    JointType::Prismatic => "prismatic",
                    JointType::Fixed => "fixed",
                };
                let _ = writeln!(self.out, "joint = \"{joint}\"");
                let _ = writeln!(self.out, "mode = \"{}\"", JointMode::name(j.mode));
                if let Some((lo, hi)) = j.limits {
                    self.key_n("limits", &[unit(lo), unit(hi)])?;
                }
                if j.cyclic {
                    self.out.push_str("cyclic = true\n");
                }
                self.key("initial", unit(j.initial))?;
                self.key("target_position", unit(j.target_position))?;
                self.key("target_velocity", unit(j.target_velocity))?;
                self.key("max_force", j.max_force)?;
                self.key("kp", j.kp)?;
                self.key("kd", j.kd)?;
                self.key("damping", j.damping)?;
                self.key("friction", j.friction)?;
                if let Some(v) = j.max_velocity {
                    self.key("max_velocity", unit(v))?;
                }
                if let Some(m) = &j.mimic {
                    let multiplier = self.num("mimic multiplier", m.multiplier)?;
                    let offset = self.num("mimic offset", unit(m.offset))?;
                    let _ = writeln!(
                        self.out,
                        "mimic = {{ leader = {}, multiplier = {multiplier}, offset = {offset} }}",
                        quote(&names[m.leader]),
                    );
                }
                Ok(())
            }
            ObjectModelKind::ProximitySensor(p) => self.proximity(p),
            ObjectModelKind::VisionSensor(v) => self.vision(v),
            ObjectModelKind::Camera(c) => self.key("fov_deg", c.fov.to_degrees()),
            ObjectModelKind::Light(l) => self.light(l),
            ObjectModelKind::Path(p) => self.path_object(p),
            ObjectModelKind::Dummy | ObjectModelKind::ForceSensor | ObjectModelKind::Graph => Ok(()),
        }
    }

    /// The proximity sensor's keys: the one place that knows every volume.
    fn proximity(&mut self, p: &ProximityModel) -> Result<(), WriteError> {
        match *p {
            ProximityModel::Ray { offset, range } => {
                self.out.push_str("sensor = \"ray\"\n");
                self.key("offset", offset)?;
                self.key("range", range)
            }
            ProximityModel::Cone {
                offset,
                range,
                half_angle,
            } => {
                self.out.push_str("sensor = \"cone\"\n");
                self.key("offset", offset)?;
                self.key("range", range)?;
                self.key("angle_deg", (2.0 * half_angle).to_degrees())
            }
            ProximityModel::Pyramid {
                offset,
                range,
                near_size,
                far_size,
            } => {
                self.out.push_str("sensor = \"pyramid\"\n");
                self.key("offset", offset)?;
                self.key("range", range)?;
                self.key_n("size_near", &near_size)?;
                self.key_n("size_far", &far_size)
            }
            ProximityModel::Cylinder {
                offset,
                range,
                radius,
                radius_far,
            } => {
                self.out.push_str("sensor = \"cylinder\"\n");
                self.key("offset", offset)?;
                self.key("range", range)?;
                self.key("radius", radius)?;
                self.key("radius_far", radius_far)
            }
            ProximityModel::Disc {
                offset,
                range,
                half_angle,
                thickness,
            } => {
                self.out.push_str("sensor = \"disc\"\n");
                self.key("offset", offset)?;
                self.key("range", range)?;
                self.key("angle_deg", (2.0 * half_angle).to_degrees())?;
                self.key("thickness", thickness)
            }
        }
    }

    /// The light's keys, all of them (a light has few).
    fn light(&mut self, l: &LightModel) -> Result<(), WriteError> {
        let t = match l.light_type {
            LightType::Omnidirectional => "omnidirectional",
            LightType::Spot => "spot",
            LightType::Directional => "directional",
        };
        let _ = writeln!(self.out, "light = \"{t}\"\non = {}", l.on);
        self.key3("diffuse", l.diffuse)?;
        self.key3("specular", l.specular)?;
        let _ = writeln!(self.out, "spot_exponent = {}", l.spot_exponent);
        self.key("spot_cutoff_deg", l.spot_cutoff.to_degrees())?;
        self.key3("attenuation", l.attenuation)?;
        let _ = writeln!(self.out, "casts_shadows = {}", l.casts_shadows);
        Ok(())
    }

    /// The old path's keys: its control points one per line.
    fn path_object(&mut self, p: &PathModel) -> Result<(), WriteError> {
        self.out.push_str("ctrl_points = [\n");
        for c in &p.ctrl_points {
            let items = c
                .iter()
                .map(|x| self.num("ctrl_points", *x))
                .collect::<Result<Vec<_>, _>>()?;
            let _ = writeln!(self.out, "    [{}],", items.join(", "));
        }
        self.out.push_str("]\n");
        let _ = writeln!(self.out, "closed = {}", p.closed);
        self.key("smoothness", p.smoothness)?;
        let _ = writeln!(self.out, "subdiv = {}", p.subdiv);
        Ok(())
    }

    /// The vision sensor's keys.
    fn vision(&mut self, v: &VisionModel) -> Result<(), WriteError> {
        let _ = writeln!(self.out, "resolution = [{}, {}]", v.resolution[0], v.resolution[1]);
        let projection = match v.projection {
            Projection::Perspective => "perspective",
            Projection::Orthographic => "orthographic",
        };
        let _ = writeln!(self.out, "projection = \"{projection}\"");
        self.key("fov_deg", v.fov.to_degrees())?;
        self.key("ortho_size", v.ortho_size)?;
        self.key("near", v.near)?;
        self.key("far", v.far)?;
        if v.render_mode == RenderMode::ColorCoded {
            self.out.push_str("render_mode = \"color_coded\"\n");
        }
        if v.ignore_rgb {
            self.out.push_str("ignore_rgb = true\n");
        }
        if v.ignore_depth {
            self.out.push_str("ignore_depth = true\n");
        }
        if let Some(r) = v.ros2_rate {
            self.key("ros2_rate", r)?;
        }
        if let Some(c) = v.background {
            self.key3("background", c)?;
        }
        Ok(())
    }

    fn shape(&mut self, s: &ShapeModel) -> Result<(), WriteError> {
        let _ = writeln!(self.out, "dynamic = {}", s.dynamic);
        match s.mass {
            MassModel::Density(d) => self.key("density", d)?,
            MassModel::Mass(m) => self.key("mass", m)?,
            MassModel::Inertial {
                mass,
                com,
                frame,
                inertia,
            } => {
                self.key("mass", mass)?;
                self.key3("center_of_mass", com)?;
                self.key_n("inertia", &inertia)?;
                if frame != [0.0, 0.0, 0.0, 1.0] {
                    self.key_n("inertia_frame", &frame)?;
                }
            }
        }
        self.key("friction", s.friction)?;
        self.key("restitution", s.restitution)?;
        if s.collision_group != u32::MAX {
            let _ = writeln!(self.out, "collision_group = {:#010x}", s.collision_group);
        }
        if s.collision_mask != u32::MAX {
            let _ = writeln!(self.out, "collision_mask = {:#010x}", s.collision_mask);
        }
        let _ = writeln!(self.out, "respondable = {}", s.respondable);
        let _ = writeln!(self.out, "detectable = {}", s.detectable);
        let _ = writeln!(self.out, "measurable = {}", s.measurable);
        if !s.collidable {
            let _ = writeln!(self.out, "collidable = false");
        }
        let _ = writeln!(self.out, "self_collision = {}", s.self_collision);

        // A mesh without triangles is refused by the mesh loader (a file with nothing
        // to draw or collide with is almost always a mistake), so it is left out, said.
        let empty = |g: &Geometry| matches!(g, Geometry::Mesh(m) if m.indices.is_empty());
        let geoms: Vec<_> = s.geoms.iter().filter(|g| !empty(&g.geometry)).collect();
        let visuals: Vec<_> = s.visuals.iter().filter(|v| !empty(&v.geometry)).collect();
        let dropped = s.geoms.len() + s.visuals.len() - geoms.len() - visuals.len();
        if dropped > 0 {
            self.notes.push(format!(
                "{}: {dropped} mesh part(s) without triangles left out",
                self.object
            ));
        }
        // Parts drawn as they collide are written once ("both"); otherwise the
        // collision parts, then the visual ones, as the loader reads them back.
        let paired = geoms.len() == visuals.len()
            && geoms
                .iter()
                .zip(&visuals)
                .all(|(g, v)| g.local == v.local && same_geometry(&g.geometry, &v.geometry));
        if paired && geoms.len() == 1 && geoms[0].local == Pose::identity() {
            self.geometry(&geoms[0].geometry)?;
            self.color(visuals[0].color)?;
            self.texture(visuals[0].texture.as_ref())?;
            return Ok(());
        }
        if geoms.is_empty() && visuals.is_empty() {
            self.out.push_str("part = []\n");
            return Ok(());
        }
        if paired {
            for (g, v) in geoms.iter().zip(&visuals) {
                self.out.push_str("\n[[object.part]]\n");
                self.geometry(&g.geometry)?;
                self.pose(&g.local)?;
                self.color(v.color)?;
                self.texture(v.texture.as_ref())?;
            }
        } else {
            for g in &geoms {
                self.out.push_str("\n[[object.part]]\nrole = \"collision\"\n");
                self.geometry(&g.geometry)?;
                self.pose(&g.local)?;
            }
            for v in &visuals {
                self.out.push_str("\n[[object.part]]\nrole = \"visual\"\n");
                self.geometry(&v.geometry)?;
                self.pose(&v.local)?;
                self.color(v.color)?;
                self.texture(v.texture.as_ref())?;
            }
        }
        Ok(())
    }

    fn geometry(&mut self, g: &Geometry) -> Result<(), WriteError> {
        match g {
            Geometry::Box { half_extents } => {
                self.out.push_str("shape = \"box\"\n");
                self.key3("size", half_extents.map(|h| 2.0 * h))
            }
            Geometry::Sphere { radius } => {
                self.out.push_str("shape = \"sphere\"\n");
                self.key("radius", *radius)
            }
            Geometry::Cylinder { radius, length } => {
                self.out.push_str("shape = \"cylinder\"\n");
                self.key("radius", *radius)?;
                self.key("length", *length)
            }
            Geometry::Capsule { radius, length } => {
                self.out.push_str("shape = \"capsule\"\n");
                self.key("radius", *radius)?;
                self.key("length", *length)
            }
            Geometry::Mesh(m) => {
                let file = self.mesh_file(m)?;
                self.out.push_str("shape = \"mesh\"\n");
                let _ = writeln!(self.out, "mesh = {}", quote(&file));
                Ok(())
            }
        }
    }

    /// The mesh's file, written on first use.
    fn mesh_file(&mut self, m: &Arc<MeshData>) -> Result<String, WriteError> {
        if let Some(f) = self.meshes.get(&Arc::as_ptr(m)) {
            return Ok(f.clone());
        }
        if m.vertices.iter().flatten().any(|v| !v.is_finite()) {
            return Err(self.not_finite("a mesh vertex"));
        }
        let name = self.object.clone();
        let file = self.file_name("meshes", &name, "obj");
        let (text, parts_kept) = write_obj(m, &format!("{} ({})", name, m.source.display()));
        if !parts_kept {
            self.notes.push(format!(
                "the convex parts of {}'s mesh are not sections of its triangles; {file} collides as one hull",
                self.object
            ));
        }
        self.files.push((file.clone().into(), text.into_bytes()));
        self.meshes.insert(Arc::as_ptr(m), file.clone());
        Ok(file)
    }

    /// `dir/<base>.<ext>`, with `_2`, `_3`, ... for a base name taken before.
    fn file_name(&mut self, dir: &str, base: &str, ext: &str) -> String {
        let clean: String = base
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        let clean = if clean.is_empty() { "object".into() } else { clean };
        let mut n = 1;
        loop {
            let file = if n == 1 {
                format!("{dir}/{clean}.{ext}")
            } else {
                format!("{dir}/{clean}_{n}.{ext}")
            };
            // Compared without case: `Link.obj` and `link.obj` are one file on macOS
            // and Windows.
            if self.used_files.insert(file.to_ascii_lowercase()) {
                return file;
            }
            n += 1;
        }
    }

    /// `position` and `orientation_deg` (or `quaternion`), each left out when zero.
    fn pose(&mut self, p: &Pose) -> Result<(), WriteError> {
        let t = p.translation.vector;
        if t != nalgebra::Vector3::zeros() {
            self.key3("position", [t.x, t.y, t.z])?;
        }
        let q = p.rotation;
        if q == Quat::identity() {
            return Ok(());
        }
        let deg = euler_from_quat(&q).map(f64::to_degrees);
        let back = quat_from_euler(deg.map(f64::to_radians));
        // q and -q are the same rotation.
        let close = |a: &Quat, b: &Quat| (a.coords - b.coords).amax() <= EULER_TOLERANCE;
        if close(&back, &q) || close(&back, &Quat::new_unchecked(-q.into_inner())) {
            self.key3("orientation_deg", deg)
        } else {
            self.key_n("quaternion", &quat_to_array(&q))
        }
    }

    /// A part's `texture = { ... }`: its image as a PNG file (once per texture), its
    /// fixed coordinates as a text file beside it.
    fn texture(&mut self, t: Option<&VisualTexture>) -> Result<(), WriteError> {
        let Some(t) = t else { return Ok(()) };
        let Some(image) = self.textures.get(t.texture).cloned() else {
            self.notes.push(format!(
                "{}: its texture {} does not exist; left out",
                self.object, t.texture
            ));
            return Ok(());
        };
        let file = match self.texture_files.get(&t.texture) {
            Some(f) => f.clone(),
            None => {
                let png = match super::texture_file::encode_png(image.resolution, &image.rgba) {
                    Ok(p) => p,
                    Err(e) => {
                        self.notes
                            .push(format!("{}: texture '{}' not written: {e}", self.object, image.name));
                        return Ok(());
                    }
                };
                let file = self.file_name("textures", &image.name, "png");
                self.files.push((file.clone().into(), png));
                self.texture_files.insert(t.texture, file.clone());
                file
            }
        };
        let mapping = match t.mapping {
            1 => "cylinder",
            2 => "sphere",
            3 => "cube",
            _ => "plane",
        };
        let p = t.frame.translation.vector;
        let position = [p.x, p.y, p.z]
            .iter()
            .map(|v| self.num("texture position", *v))
            .collect::<Result<Vec<_>, _>>()?;
        let quaternion = quat_to_array(&t.frame.rotation)
            .iter()
            .map(|v| self.num("texture quaternion", *v))
            .collect::<Result<Vec<_>, _>>()?;
        let scaling = t
            .scaling
            .iter()
            .map(|v| self.num("texture scaling", *v))
            .collect::<Result<Vec<_>, _>>()?;
        let _ = write!(
            self.out,
            "texture = {{ image = {}, name = {}, mapping = \"{mapping}\", options = {}, scaling = [{}], position = [{}], quaternion = [{}]",
            quote(&file),
            quote(&image.name),
            t.options,
            scaling.join(", "),
            position.join(", "),
            quaternion.join(", ")
        );
        if let Some(c) = &t.coordinates {
            if c.iter().any(|v| !v.is_finite()) {
                return Err(self.not_finite("a texture coordinate"));
            }
            let name = self.object.clone();
            let uv = self.file_name("textures", &name, "uv");
            self.files.push((
                uv.clone().into(),
                super::texture_file::write_coordinates(c).into_bytes(),
            ));
            let _ = write!(self.out, ", coordinates = {}", quote(&uv));
        }
        self.out.push_str(" }\n");
        Ok(())
    }

    fn color(&mut self, c: [f32; 3]) -> Result<(), WriteError> {
        if c.iter().any(|v| !v.is_finite()) {
            return Err(self.not_finite("a colour"));
        }
        let _ = writeln!(
            self.out,
            "color = [{}, {}, {}]",
            f32_text(c[0]),
            f32_text(c[1]),
            f32_text(c[2])
        );
        Ok(())
    }

    fn key(&mut self, key: &str, v: f64) -> Result<(), WriteError> {
        let text = self.num(key, v)?;
        let _ = writeln!(self.out, "{key} = {text}");
        Ok(())
    }

    fn key3(&mut self, key: &str, v: [f64; 3]) -> Result<(), WriteError> {
        self.key_n(key, &v)
    }

    fn key_n(&mut self, key: &str, v: &[f64]) -> Result<(), WriteError> {
        let items = v.iter().map(|x| self.num(key, *x)).collect::<Result<Vec<_>, _>>()?;
        let _ = writeln!(self.out, "{key} = [{}]", items.join(", "));
        Ok(())
    }

    /// The shortest decimal that reads back as `v` (Rust's `Debug` form: `1.0`, `1e-7`,
    /// both valid TOML floats).
    fn num(&self, what: &str, v: f64) -> Result<String, WriteError> {
        if v.is_finite() {
            Ok(format!("{v:?}"))
        } else {
            Err(self.not_finite(what))
        }
    }

    fn not_finite(&self, what: &str) -> WriteError {
        WriteError::NotFinite {
            object: self.object.clone(),
            what: what.to_owned(),
        }
    }
}

/// The scene file's name of a kind.
fn kind_name(kind: &ObjectModelKind) -> &'static str {
    match kind {
        ObjectModelKind::Shape(_) => "shape",
        ObjectModelKind::Joint(_) => "joint",
        ObjectModelKind::Dummy => "dummy",
        ObjectModelKind::ProximitySensor(_) => "proximity_sensor",
        ObjectModelKind::VisionSensor(_) => "vision_sensor",
        ObjectModelKind::ForceSensor => "force_sensor",
        ObjectModelKind::Graph => "graph",
        ObjectModelKind::Camera(_) => "camera",
        ObjectModelKind::Light(_) => "light",
        ObjectModelKind::Path(_) => "path",
    }
}

/// A unique `name` per object, from its alias: `/` (which parent references split
/// on) becomes `_`, and a repeated alias gets `_2`, `_3`, ... in tree order.
fn unique_names(objects: &[ObjectModel]) -> Vec<String> {
    let mut taken = std::collections::HashSet::new();
    let mut out = Vec::with_capacity(objects.len());
    for o in objects {
        let base = o.alias.replace('/', "_");
        let base = if base.is_empty() {
            kind_name(&o.kind).to_owned()
        } else {
            base
        };
        let mut name = base.clone();
        let mut n = 1;
        while !taken.insert(name.clone()) {
            n += 1;
            name = format!("{base}_{n}");
        }
        out.push(name);
    }
    out
}

fn same_geometry(a: &Geometry, b: &Geometry) -> bool {
    match (a, b) {
        (Geometry::Box { half_extents: x }, Geometry::Box { half_extents: y }) => x == y,
        (Geometry::Sphere { radius: x }, Geometry::Sphere { radius: y }) => x == y,
        (Geometry::Cylinder { radius: r1, length: l1 }, Geometry::Cylinder { radius: r2, length: l2 })
        | (Geometry::Capsule { radius: r1, length: l1 }, Geometry::Capsule { radius: r2, length: l2 }) => {
            r1 == r2 && l1 == l2
        }
        (Geometry::Mesh(x), Geometry::Mesh(y)) => Arc::ptr_eq(x, y) || **x == **y,
        _ => false,
    }
}

/// A TOML basic string.
fn quote(s: &str) -> String {
    toml::Value::String(s.to_owned()).to_string()
}

/// A note or warning on one comment line.
fn one_line(s: &str) -> String {
    s.chars().map(|c| if c.is_control() { ' ' } else { c }).collect()
}

/// The shortest decimal of `v` that reads back as `v` through an `f64` (how the loader
/// reads colours), else the `f64` value's own.
fn f32_text(v: f32) -> String {
    let short = format!("{v:?}");
    if short.parse::<f64>().is_ok_and(|d| d as f32 == v) {
        short
    } else {
        format!("{:?}", f64::from(v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::model::{ShapeModel, UserParameter};

    fn dummy(alias: &str) -> ObjectModel {
        ObjectModel {
            alias: alias.into(),
            parent: None,
            local: Pose::identity(),
            model_base: false,
            extension: String::new(),
            layer: 1,
            kind: ObjectModelKind::Dummy,
        }
    }

    #[test]
    fn names_are_unique_and_hold_no_slash() {
        let objects = [dummy("a"), dummy("a"), dummy("a_2"), dummy("x/y"), dummy("")];
        assert_eq!(unique_names(&objects), ["a", "a_2", "a_2_2", "x_y", "dummy"]);
    }

    #[test]
    fn colours_read_back_as_the_same_f32() {
        for v in [0.8f32, 1.0 / 3.0, 0.55, 1e-7, 0.0, 1.0] {
            let text = f32_text(v);
            assert_eq!(text.parse::<f64>().expect("a number") as f32, v, "{text}");
        }
        assert_eq!(f32_text(0.8), "0.8");
    }

    fn scene(objects: Vec<ObjectModel>) -> SceneModel {
        SceneModel {
            name: "s".into(),
            base_dir: PathBuf::new(),
            path: PathBuf::new(),
            settings: crate::scene::model::SimSettings::default(),
            server: crate::scene::model::ServerSettings::default(),
            objects,
            scripts: Vec::new(),
            dummy_links: Vec::new(),
            ball_links: Vec::new(),
            referenced_handles: Vec::new(),
            user_parameters: Vec::new(),
            ik_groups: Vec::new(),
            collections: Vec::new(),
            urdf_robots: Vec::new(),
            warnings: Vec::new(),
            textures: Vec::new(),
        }
    }

    #[test]
    fn the_vision_background_round_trips_and_stays_unset_when_unset() {
        // Unset: no key written, none read back (black, as before).
        let plain = scene(Vec::new());
        assert!(!written(&plain).contains("background"), "{}", written(&plain));
        assert_eq!(read(&written(&plain)).settings.background, None);
        // Set: written under [simulation] and read back exactly.
        let mut grey = scene(Vec::new());
        grey.settings.background = Some([0.804f32, 0.867, 0.916].map(f64::from));
        let text = written(&grey);
        assert!(text.contains("\nbackground = ["), "{text}");
        assert_eq!(read(&text).settings.background, grey.settings.background);
        // Out of range is an error naming the key.
        let bad = read_err("[simulation]\nbackground = [0.5, 1.5, 0]\n");
        assert!(bad.contains("background"), "{bad}");
    }

    #[test]
    fn user_parameters_round_trip_and_bad_ones_are_refused() {
        let mut model = scene(vec![dummy("sensor"), dummy("other")]);
        model.user_parameters = vec![
            UserParameter {
                object: 0,
                name: "horizontalAngle".into(),
                unit: "degrees (5-360)".into(),
                value: "360".into(),
            },
            UserParameter {
                object: 1,
                name: "label".into(),
                unit: String::new(),
                value: "a \"quoted\" text".into(),
            },
        ];
        let text = written(&model);
        let back = read(&text);
        let named = |m: &SceneModel| -> Vec<(String, String, String, String)> {
            m.user_parameters
                .iter()
                .map(|p| {
                    (
                        m.objects[p.object].alias.clone(),
                        p.name.clone(),
                        p.unit.clone(),
                        p.value.clone(),
                    )
                })
                .collect()
        };
        assert_eq!(named(&back), named(&model), "{text}");

        let head = "[[object]]\nname = \"a\"\nkind = \"dummy\"\n";
        let unknown = read_err(&format!(
            "{head}[[user_parameter]]\nobject = \"b\"\nname = \"x\"\nvalue = \"1\"\n"
        ));
        assert!(unknown.contains('b'), "{unknown}");
        let twice = read_err(&format!(
            "{head}[[user_parameter]]\nobject = \"a\"\nname = \"x\"\nvalue = \"1\"\n\
             [[user_parameter]]\nobject = \"a\"\nname = \"x\"\nvalue = \"2\"\n"
        ));
        assert!(twice.contains("given twice"), "{twice}");
        let typo = read_err(&format!(
            "{head}[[user_parameter]]\nobject = \"a\"\nname = \"x\"\nvalu = \"1\"\n"
        ));
        assert!(typo.contains("valu"), "{typo}");
    }

    /// The scene file `write_scene` makes of `model`.
    fn written(model: &SceneModel) -> String {
        let files = write_scene(model, "s", "s.toml").expect("writes");
        String::from_utf8(files.files[0].1.clone()).expect("utf-8")
    }

    /// A scene text loaded.
    fn read(text: &str) -> SceneModel {
        crate::scene::load_scene_text(
            &crate::scene::MapFiles::default(),
            text,
            std::path::Path::new("s.toml"),
            &crate::scene::LoadOptions::default(),
        )
        .expect("loads")
    }

    fn read_err(text: &str) -> String {
        crate::scene::load_scene_text(
            &crate::scene::MapFiles::default(),
            text,
            std::path::Path::new("s.toml"),
            &crate::scene::LoadOptions::default(),
        )
        .expect_err("refused")
        .to_string()
    }

    #[test]
    fn what_cannot_be_written_is_said_at_the_top() {
        let empty = Geometry::Mesh(Arc::new(MeshData {
            source: "e".into(),
            vertices: vec![[0.0; 3]],
            indices: Vec::new(),
            parts: Vec::new(),
        }));
        let shape = ObjectModel {
            kind: ObjectModelKind::Shape(ShapeModel::single(empty, [1.0; 3])),
            ..dummy("hollow")
        };
        let files = write_scene(&scene(vec![shape]), "s", "s.ttt").expect("writes");
        assert_eq!(files.notes, ["hollow: 2 mesh part(s) without triangles left out"]);
        let text = String::from_utf8(files.files[0].1.clone()).expect("utf-8");
        assert!(
            text.contains("\n# gantry convert: hollow: 2 mesh part(s) without triangles left out\n"),
            "{text}"
        );
        assert!(text.contains("part = []"), "{text}");
    }

    #[test]
    fn a_one_part_shape_is_written_with_the_object_keys() {
        let model = SceneModel {
            name: "s".into(),
            base_dir: PathBuf::new(),
            path: PathBuf::new(),
            settings: crate::scene::model::SimSettings::default(),
            server: crate::scene::model::ServerSettings::default(),
            objects: vec![ObjectModel {
                kind: ObjectModelKind::Shape(ShapeModel::single(
                    Geometry::Box {
                        half_extents: [0.5, 0.25, 0.125],
                    },
                    [1.0, 0.0, 0.0],
                )),
                local: Pose::translation(0.0, 0.0, 0.5),
                ..dummy("box")
            }],
            scripts: Vec::new(),
            dummy_links: Vec::new(),
            ball_links: Vec::new(),
            referenced_handles: Vec::new(),
            user_parameters: Vec::new(),
            ik_groups: Vec::new(),
            collections: Vec::new(),
            urdf_robots: Vec::new(),
            warnings: Vec::new(),
            textures: Vec::new(),
        };
        let files = write_scene(&model, "s", "s.ttt").expect("writes");
        assert_eq!(files.files.len(), 1);
        let text = String::from_utf8(files.files[0].1.clone()).expect("utf-8");
        assert!(
            text.contains(
                "name = \"box\"\nkind = \"shape\"\nposition = [0.0, 0.0, 0.5]\ndynamic = false\ndensity = 1000.0\n"
            ),
            "{text}"
        );
        assert!(
            text.contains("shape = \"box\"\nsize = [1.0, 0.5, 0.25]\ncolor = [1.0, 0.0, 0.0]\n"),
            "{text}"
        );
        assert!(
            !text.contains("[[object.part]]") && !text.contains("orientation"),
            "{text}"
        );
    }
}
