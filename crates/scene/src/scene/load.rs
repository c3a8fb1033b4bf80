//! The resolver: raw file (stage 1) to [`SceneModel`] (stage 2).
//!
//! Names become indices, degrees become radians, files are read (URDFs, meshes,
//! scripts) and defaults are applied. Errors point at the file, line and column of the
//! offending entry and say how to fix it.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use toml::Spanned;

use super::coppelia::load_coppelia_file;
use super::error::{LoadError, line_col};
use super::files::{Files, normalize, stem};
use super::floor::{floor_object, put_on_floor};
use super::model::{
    CameraModel, CollectionItemModel, CollectionModel, CollectionScope, GeomModel, Geometry, IkElementModel,
    IkGroupModel, IkMethodModel, JointMode, JointModel, JointType, LightModel, LightType, MAX_VISION_IMAGE_BYTES,
    MAX_VISION_RESOLUTION, MassModel, MimicModel, ObjectModel, ObjectModelKind, PathModel, Projection, ProximityModel,
    ReferencedHandles, RenderMode, SceneModel, ScriptModel, ServerSettings, ShapeModel, SimSettings, TextureModel,
    UrdfRobotModel, UserParameter, VISION_BYTES_PER_PIXEL, VisionModel, VisualModel, VisualTexture, vision_image_bytes,
};
use super::raw::{RawObject, RawPart, RawRobot, RawScene, RawTexture, unknown_keys};
use super::urdf::{DEFAULT_KD, DEFAULT_KP, UrdfInclude, UrdfIndex, import_urdf};
use crate::math::{Pose, pose_from_euler, quat_from_array};

/// Two dummies (object indices) held together by a loop closure.
type DummyPair = [usize; 2];

/// Default damping of velocity-mode joints, N·m·s/rad: the gain of the velocity servo.
pub const DEFAULT_VELOCITY_KD: f64 = 10.0;

/// Viscous damping of a scene-file joint in a simulated mode, N·m·s/rad (N·s/m): what
/// rapier gave every multibody joint before URDF `<dynamics>` set it per joint (URDF
/// joints without `<dynamics>` get 0, as in PyBullet). It keeps the shipped scenes as
/// they were tuned, and a free-wheeling rover at rest on its frictionless caster from
/// creeping away on contact noise.
const TOML_JOINT_DAMPING: f64 = 0.1;

/// Colour of a shape or visual part that gives none.
const DEFAULT_COLOR: [f32; 3] = [0.8, 0.8, 0.8];

/// Options that come from the command line rather than the scene.
#[derive(Debug, Clone, Default)]
pub struct LoadOptions {
    /// Extra folders for `package://` mesh references.
    pub package_paths: Vec<PathBuf>,
    /// For a bare URDF: let the base move freely instead of fixing it to the world.
    pub free_base: bool,
}

/// Loads a scene file (`.toml`) or a bare URDF (`.urdf`, placed on a floor).
///
/// # Errors
/// Any [`LoadError`]: unreadable or malformed files, invalid content.
pub fn load_scene(files: &dyn Files, path: &Path, opts: &LoadOptions) -> Result<SceneModel, LoadError> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("urdf") => load_bare_urdf(files, path, opts),
        Some("ttt" | "ttm") => load_coppelia_file(files, path),
        Some("toml") => {
            let bytes = files.read(path).map_err(|e| LoadError::Io {
                path: path.to_owned(),
                source: e,
                hint: String::new(),
            })?;
            let text = String::from_utf8(bytes).map_err(|_| LoadError::Syntax {
                path: path.to_owned(),
                line: 1,
                column: 1,
                message: "the scene file is not UTF-8 text".into(),
            })?;
            load_scene_text(files, &text, path, opts)
        }
        _ => Err(LoadError::Invalid {
            path: path.to_owned(),
            line: 1,
            column: 1,
            message:
                "unknown scene type: give a .toml scene file, a .urdf robot or a CoppeliaSim .ttt scene or .ttm model"
                    .into(),
        }),
    }
}

/// A URDF on a 5 x 5 m floor, base fixed unless `opts.free_base` (PyBullet's `useFixedBase`).
fn load_bare_urdf(files: &dyn Files, path: &Path, opts: &LoadOptions) -> Result<SceneModel, LoadError> {
    let mut model = load_urdf_model(files, path, opts)?;
    model.warnings = dedup(std::mem::take(&mut model.warnings));
    put_on_floor(&mut model);
    Ok(model)
}

/// A URDF robot as a scene of its own objects (no floor, default settings), named after
/// the file, with the import's warnings; the model `sim.loadModel` inserts.
pub(super) fn load_urdf_model(files: &dyn Files, path: &Path, opts: &LoadOptions) -> Result<SceneModel, LoadError> {
    let (objects, robot, warnings) = load_urdf_objects(files, path, opts)?;
    Ok(SceneModel {
        name: stem(path),
        base_dir: path.parent().map(Path::to_owned).unwrap_or_default(),
        path: path.to_owned(),
        settings: SimSettings::default(),
        server: ServerSettings::default(),
        objects,
        scripts: Vec::new(),
        dummy_links: Vec::new(),
        ball_links: Vec::new(),
        referenced_handles: Vec::new(),
        user_parameters: Vec::new(),
        ik_groups: Vec::new(),
        collections: Vec::new(),
        urdf_robots: vec![robot],
        warnings,
        textures: Vec::new(),
    })
}

/// A URDF robot's objects on their own (no floor), its base fixed unless
/// `opts.free_base`, with where its links and joints landed and the import's warnings.
fn load_urdf_objects(
    files: &dyn Files,
    path: &Path,
    opts: &LoadOptions,
) -> Result<(Vec<ObjectModel>, UrdfRobotModel, Vec<String>), LoadError> {
    let mut objects = Vec::new();
    let mut warnings = Vec::new();
    let include = UrdfInclude {
        fixed_base: !opts.free_base,
        ..UrdfInclude::default()
    };
    let index = import_urdf(files, path, &include, &opts.package_paths, &mut objects, &mut warnings)?;
    Ok((objects, index.robot_model(), dedup(warnings)))
}

/// Resolves the text of a scene file. `path` names the file in messages and anchors
/// relative paths.
///
/// # Errors
/// Any [`LoadError`].
pub fn load_scene_text(
    files: &dyn Files,
    text: &str,
    path: &Path,
    opts: &LoadOptions,
) -> Result<SceneModel, LoadError> {
    let syntax = |e: toml::de::Error| {
        let (line, column) = e.span().map_or((1, 1), |s| line_col(text, s.start));
        LoadError::Syntax {
            path: path.to_owned(),
            line,
            column,
            message: e.message().to_owned(),
        }
    };
    let doc: toml::Table = toml::from_str(text).map_err(syntax)?;
    let raw: RawScene = toml::from_str(text).map_err(syntax)?;
    let base_dir = path.parent().map(Path::to_owned).unwrap_or_default();
    let mut r = Resolver {
        files,
        text,
        path,
        base_dir: &base_dir,
        opts,
        objects: Vec::new(),
        scripts: Vec::new(),
        warnings: unknown_keys(&doc),
        urdf_robots: Vec::new(),
        names: Names::new(),
        mimics: Vec::new(),
        textures: Vec::new(),
        texture_files: HashMap::new(),
    };
    let settings = r.settings(&raw)?;
    let server = raw
        .server
        .as_ref()
        .map_or_else(ServerSettings::default, |s| ServerSettings {
            bind: s.bind.clone(),
            text_port: s.text_port,
            zmq_port: s.zmq_port,
            http_port: s.http_port,
        });
    if let Some(f) = &raw.floor
        && let Some(size) = f.size
        && !size.iter().all(|v| v.is_finite() && *v > 0.0)
    {
        return r.err_at(
            r.find_key("size"),
            format!("[floor] size = {size:?}: both sides must be > 0 metres"),
        );
    }
    if let Some(f) = &raw.floor {
        r.objects.push(floor_object(
            f.size.unwrap_or([5.0, 5.0]),
            f.friction.unwrap_or(1.0),
            f.color.unwrap_or([0.55, 0.55, 0.5]),
        ));
    }
    r.tree(&raw)?;
    for s in &raw.script {
        let object = r.reference(&s.object)?;
        r.attach_script(object, &s.file)?;
    }
    r.resolve_mimics()?;
    let (dummy_links, ball_links) = r.dummy_links(&raw)?;
    let referenced_handles = r.references(&raw)?;
    let user_parameters = r.user_parameters(&raw)?;
    let ik_groups = r.ik_groups(&raw)?;
    let collections = r.collections(&raw)?;
    Ok(SceneModel {
        name: stem(path),
        base_dir: base_dir.clone(),
        path: path.to_owned(),
        settings,
        server,
        objects: r.objects,
        scripts: r.scripts,
        dummy_links,
        ball_links,
        referenced_handles,
        user_parameters,
        ik_groups,
        collections,
        urdf_robots: r.urdf_robots,
        warnings: dedup(r.warnings),
        textures: r.textures,
    })
}

/// The `sim.ik_*_constraint` bits of a constraints name: `pose`, `position`,
/// `orientation`, or components joined by `+` (`x+y`, `alpha_beta+gamma`).
fn ik_constraints(text: &str) -> Option<u8> {
    let mut bits = 0;
    for part in text.split('+') {
        bits |= match part.trim() {
            "pose" => 31,
            "position" => 7,
            "orientation" => 24,
            "x" => 1,
            "y" => 2,
            "z" => 4,
            "alpha_beta" => 8,
            "gamma" => 16,
            _ => return None,
        };
    }
    Some(bits)
}

/// Drops repeated warnings, keeping the first of each in order: a URDF included twice
/// has the same problems twice, and they are worth saying once.
pub fn dedup(warnings: Vec<String>) -> Vec<String> {
    let mut seen = std::collections::HashSet::new();
    warnings.into_iter().filter(|w| seen.insert(w.clone())).collect()
}

/// What a name in the file refers to, once emitted.
#[derive(Debug, Clone)]
enum Emitted {
    Object(usize),
    Robot(UrdfIndex),
}

/// An entry of the file: an `[[object]]` or a `[[robot]]`.
#[derive(Clone, Copy)]
enum Entry<'a> {
    Object(&'a RawObject),
    Robot(&'a RawRobot),
}

struct Resolver<'a> {
    files: &'a dyn Files,
    text: &'a str,
    path: &'a Path,
    base_dir: &'a Path,
    opts: &'a LoadOptions,
    objects: Vec<ObjectModel>,
    scripts: Vec<ScriptModel>,
    warnings: Vec<String>,
    /// The `[[robot]]`s emitted so far.
    urdf_robots: Vec<UrdfRobotModel>,
    names: Names,
    /// Joints that follow another, resolved once every object exists: the follower's
    /// index, the leader's name, and the multiplier and offset in model units.
    mimics: Vec<(usize, Spanned<String>, f64, f64)>,
    /// Texture images read so far, and the index of each by its resolved file.
    textures: Vec<TextureModel>,
    texture_files: HashMap<PathBuf, usize>,
}

/// The geometry keys of an `[[object]]` or an `[[object.part]]`.
struct GeometryKeys<'a> {
    size: Option<[f64; 3]>,
    radius: Option<f64>,
    length: Option<f64>,
    mesh: Option<&'a Spanned<String>>,
    scale: Option<[f64; 3]>,
}

/// Names of emitted entries, for `parent` and `[[script]] object` references.
type Names = HashMap<String, Emitted>;

impl Resolver<'_> {
    fn err_at<T>(&self, span: std::ops::Range<usize>, message: impl Into<String>) -> Result<T, LoadError> {
        let (line, column) = line_col(self.text, span.start);
        Err(LoadError::Invalid {
            path: self.path.to_owned(),
            line,
            column,
            message: message.into(),
        })
    }

    fn settings(&self, raw: &RawScene) -> Result<SimSettings, LoadError> {
        let mut s = SimSettings::default();
        if let Some(sim) = &raw.simulation {
            if let Some(dt) = sim.dt {
                if !(dt.is_finite() && dt > 0.0 && dt <= 1.0) {
                    return self.err_at(
                        self.find_key("dt"),
                        format!("dt = {dt}: the time step must be in (0, 1] s"),
                    );
                }
                s.dt = dt;
            }
            if let Some(n) = sim.substeps {
                if !(1..=1000).contains(&n) {
                    return self.err_at(
                        self.find_key("substeps"),
                        format!("substeps = {n}: use 1 to 1000 physics substeps"),
                    );
                }
                s.substeps = n;
            }
            if let Some(every) = sim.collisions_every_substep {
                s.collisions_every_substep = every;
            }
            if let Some(seed) = sim.seed {
                s.seed = seed;
            }
            if let Some(n) = sim.solver_iterations {
                if !(1..=100).contains(&n) {
                    return self.err_at(
                        self.find_key("solver_iterations"),
                        format!("solver_iterations = {n}: use 1 to 100 solver iterations per substep"),
                    );
                }
                s.solver_iterations = n;
            }
            if let Some(g) = sim.gravity {
                if g.iter().any(|v| !v.is_finite()) {
                    return self.err_at(self.find_key("gravity"), "gravity must be finite");
                }
                s.gravity = g;
            }
            if let Some(c) = sim.background {
                if !c.iter().all(|v| (0.0..=1.0).contains(v)) {
                    return self.err_at(
                        self.find_key("background"),
                        format!("background = {c:?}: colour components must be from 0 to 1"),
                    );
                }
                s.background = Some(c);
            }
        }
        Ok(s)
    }

    /// The byte offset of the first `key =` in the text, for errors on plain values.
    fn find_key(&self, key: &str) -> std::ops::Range<usize> {
        // The first line that assigns the key, ignoring comments.
        let mut offset = 0;
        for line in self.text.split_inclusive('\n') {
            let code = line.split('#').next().unwrap_or_default().trim_start();
            if let Some(rest) = code.strip_prefix(key)
                && rest.trim_start().starts_with('=')
            {
                let start = offset + (line.len() - line.trim_start().len());
                return start..start;
            }
            offset += line.len();
        }
        0..0
    }
}

impl Resolver<'_> {
    /// Emits every object and robot so that parents come before children.
    fn tree(&mut self, raw: &RawScene) -> Result<(), LoadError> {
        let mut entries: Vec<Entry<'_>> = raw.object.iter().map(Entry::Object).collect();
        entries.extend(raw.robot.iter().map(Entry::Robot));
        let mut by_name: HashMap<String, usize> = HashMap::new();
        for (i, e) in entries.iter().enumerate() {
            let name = self.entry_name(e)?;
            if name.get_ref().contains('/') {
                return self.err_at(name.span(), format!("name '{}' must not contain '/'", name.get_ref()));
            }
            if by_name.insert(name.get_ref().clone(), i).is_some() || name.get_ref() == "Floor" && raw.floor.is_some() {
                return self.err_at(
                    name.span(),
                    format!("duplicate name '{}': every object and robot needs a unique name (set `alias` to reuse an alias)", name.get_ref()),
                );
            }
        }
        if raw.floor.is_some() {
            self.names.insert("Floor".into(), Emitted::Object(0));
        }
        // 0 = not emitted, 1 = being emitted (on the current parent chain), 2 = done.
        let mut state = vec![0u8; entries.len()];
        for i in 0..entries.len() {
            self.emit(&entries, &by_name, &mut state, i, 0)?;
        }
        Ok(())
    }

    fn entry_name(&self, e: &Entry<'_>) -> Result<Spanned<String>, LoadError> {
        Ok(match e {
            Entry::Object(o) => o.name.clone(),
            Entry::Robot(r) => match &r.name {
                Some(n) => n.clone(),
                None => {
                    // Without a name, the robot is referred to by its URDF file stem.
                    let stem = Path::new(r.urdf.get_ref())
                        .file_stem()
                        .and_then(|s| s.to_str())
                        .unwrap_or("robot");
                    Spanned::new(r.urdf.span(), stem.to_owned())
                }
            },
        })
    }

    fn emit(
        &mut self,
        entries: &[Entry<'_>],
        by_name: &HashMap<String, usize>,
        state: &mut [u8],
        i: usize,
        depth: usize,
    ) -> Result<(), LoadError> {
        if state[i] == 2 {
            return Ok(());
        }
        let entry = entries[i];
        let name = self.entry_name(&entry)?;
        if state[i] == 1 || depth > entries.len() {
            return self.err_at(
                name.span(),
                format!(
                    "'{}' is its own ancestor: the parent references form a cycle",
                    name.get_ref()
                ),
            );
        }
        state[i] = 1;
        let parent_ref = match entry {
            Entry::Object(o) => o.parent.clone(),
            Entry::Robot(r) => r.parent.clone(),
        };
        // Emit the parent's entry first.
        if let Some(p) = &parent_ref {
            let head = p.get_ref().split('/').next().unwrap_or_default();
            match by_name.get(head) {
                Some(&pi) => self.emit(entries, by_name, state, pi, depth + 1)?,
                None if self.names.contains_key(head) => {}
                None => {
                    return self.err_at(
                        p.span(),
                        format!(
                            "parent '{}' is not defined in this scene; define an object or robot with that name",
                            p.get_ref()
                        ),
                    );
                }
            }
        }
        let parent = match &parent_ref {
            Some(p) => Some(self.reference(p)?),
            None => None,
        };
        let emitted = match entry {
            Entry::Object(o) => Emitted::Object(self.object(o, parent)?),
            Entry::Robot(r) => Emitted::Robot(self.robot(r, parent, name.get_ref())?),
        };
        self.names.insert(name.get_ref().clone(), emitted);
        state[i] = 2;
        Ok(())
    }

    /// Resolves `name` or `robot/link-or-joint` to an object index.
    fn reference(&self, r: &Spanned<String>) -> Result<usize, LoadError> {
        let text = r.get_ref();
        let (head, tail) = match text.split_once('/') {
            Some((h, t)) => (h, Some(t)),
            None => (text.as_str(), None),
        };
        match (self.names.get(head), tail) {
            (Some(Emitted::Object(i)), None) => Ok(*i),
            (Some(Emitted::Robot(idx)), None) => Ok(idx.base),
            (Some(Emitted::Robot(idx)), Some(part)) => match idx.links.get(part).or_else(|| idx.joints.get(part)) {
                Some(&i) => Ok(i),
                None => self.err_at(r.span(), format!("robot '{head}' has no link or joint named '{part}'")),
            },
            (Some(Emitted::Object(_)), Some(_)) => self.err_at(
                r.span(),
                format!("'{head}' is an object, not a robot; use 'robot/link' only for URDF robots"),
            ),
            (None, _) => self.err_at(r.span(), format!("'{text}' is not defined in this scene")),
        }
    }

    fn relative(&self, file: &str) -> PathBuf {
        normalize(&self.base_dir.join(file))
    }

    fn attach_script(&mut self, object: usize, file: &Spanned<String>) -> Result<(), LoadError> {
        let path = self.relative(file.get_ref());
        let source = match self.files.read(&path) {
            Ok(bytes) => match String::from_utf8(bytes) {
                Ok(s) => s,
                Err(_) => {
                    return self.err_at(file.span(), format!("script '{}' is not UTF-8 text", path.display()));
                }
            },
            Err(e) => {
                return self.err_at(file.span(), format!("cannot read script '{}': {e}", path.display()));
            }
        };
        self.scripts.push(ScriptModel { object, path, source });
        Ok(())
    }

    fn pose(position: Option<[f64; 3]>, orientation_deg: Option<[f64; 3]>) -> Pose {
        let e = orientation_deg.unwrap_or([0.0; 3]).map(f64::to_radians);
        pose_from_euler(position.unwrap_or([0.0; 3]), e)
    }

    /// A pose from `position` and either `orientation_deg` or `quaternion` (not both);
    /// `what` names the entry in messages.
    fn pose_with_quaternion(
        &self,
        span: std::ops::Range<usize>,
        what: &str,
        position: Option<[f64; 3]>,
        orientation_deg: Option<[f64; 3]>,
        quaternion: Option<[f64; 4]>,
    ) -> Result<Pose, LoadError> {
        let Some(q) = quaternion else {
            return Ok(Self::pose(position, orientation_deg));
        };
        if orientation_deg.is_some() {
            return self.err_at(span, format!("{what}: give orientation_deg or quaternion, not both"));
        }
        let Some(rotation) = quat_from_array(q) else {
            return self.err_at(
                span,
                format!("{what}: quaternion {q:?} must be finite and not zero ([x, y, z, w])"),
            );
        };
        let [x, y, z] = position.unwrap_or([0.0; 3]);
        Ok(Pose::from_parts(nalgebra::Translation3::new(x, y, z), rotation))
    }

    fn object(&mut self, o: &RawObject, parent: Option<usize>) -> Result<usize, LoadError> {
        let here = o.name.span();
        let nums: [(&str, Option<f64>); 16] = [
            ("radius", o.radius),
            ("length", o.length),
            ("mass", o.mass),
            ("density", o.density),
            ("friction", o.friction),
            ("restitution", o.restitution),
            ("max_force", o.max_force),
            ("kp", o.kp),
            ("kd", o.kd),
            ("range", o.range),
            ("offset", o.offset),
            ("near", o.near),
            ("radius_far", o.radius_far),
            ("thickness", o.thickness),
            ("damping", o.damping),
            ("max_velocity", o.max_velocity),
        ];
        for (key, v) in nums {
            if let Some(v) = v
                && !(v.is_finite() && v >= 0.0)
            {
                return self.err_at(
                    here,
                    format!(
                        "object '{}': {key} = {v} must be a finite number >= 0",
                        o.name.get_ref()
                    ),
                );
            }
        }
        let finite3 = |v: Option<[f64; 3]>| v.is_none_or(|a| a.iter().all(|x| x.is_finite()));
        if !finite3(o.position)
            || !finite3(o.orientation_deg)
            || !finite3(o.size)
            || !finite3(o.scale)
            || !finite3(o.center_of_mass)
            || o.inertia.is_some_and(|i| i.iter().any(|x| !x.is_finite()))
        {
            return self.err_at(
                here,
                format!(
                    "object '{}': position, orientation, size, scale, center_of_mass and inertia must be finite",
                    o.name.get_ref()
                ),
            );
        }
        let kind = match o.kind.get_ref().as_str() {
            "shape" => ObjectModelKind::Shape(self.shape(o)?),
            "joint" => ObjectModelKind::Joint(self.joint(o)?),
            "dummy" => ObjectModelKind::Dummy,
            "proximity_sensor" => ObjectModelKind::ProximitySensor(self.proximity(o)?),
            "vision_sensor" => ObjectModelKind::VisionSensor(self.vision(o)?),
            "force_sensor" => ObjectModelKind::ForceSensor,
            "graph" => ObjectModelKind::Graph,
            "camera" => ObjectModelKind::Camera(self.camera(o)?),
            "light" => ObjectModelKind::Light(self.light(o)?),
            "path" => ObjectModelKind::Path(self.path_object(o)?),
            other => {
                return self.err_at(
                    o.kind.span(),
                    format!("unknown kind '{other}'; use shape, joint, dummy, proximity_sensor, vision_sensor, force_sensor, graph, camera, light or path"),
                );
            }
        };
        let layer = match &o.layer {
            None => 1,
            Some(l) => match u16::try_from(*l.get_ref()) {
                Ok(bits) => bits,
                Err(_) => {
                    return self.err_at(
                        l.span(),
                        format!(
                            "object '{}': layer is the bits of layers 1 to 16, 0..=65535; got {}",
                            o.name.get_ref(),
                            l.get_ref()
                        ),
                    );
                }
            },
        };
        let index = self.objects.len();
        self.objects.push(ObjectModel {
            alias: o.alias.clone().unwrap_or_else(|| o.name.get_ref().clone()),
            parent,
            local: self.pose_with_quaternion(
                here.clone(),
                &format!("object '{}'", o.name.get_ref()),
                o.position,
                o.orientation_deg,
                o.quaternion,
            )?,
            model_base: o.model_base.unwrap_or(false),
            extension: o.extension_string.clone().unwrap_or_default(),
            layer,
            kind,
        });
        if let Some(s) = &o.script {
            self.attach_script(index, s)?;
        }
        Ok(index)
    }

    fn shape(&mut self, o: &RawObject) -> Result<ShapeModel, LoadError> {
        let name = o.name.get_ref();
        let color = o.color.unwrap_or(DEFAULT_COLOR);
        let (geoms, visuals) = match (&o.part, &o.shape) {
            (Some(_), Some(kind)) => {
                return self.err_at(
                    kind.span(),
                    format!("shape '{name}': give `shape` or `[[object.part]]` tables, not both"),
                );
            }
            (Some(parts), None) => self.parts(name, parts)?,
            (None, Some(kind)) => {
                let keys = GeometryKeys {
                    size: o.size,
                    radius: o.radius,
                    length: o.length,
                    mesh: o.mesh.as_ref(),
                    scale: o.scale,
                };
                let geometry = self.geometry(name, kind, &keys)?;
                let local = Pose::identity();
                (
                    vec![GeomModel {
                        geometry: geometry.clone(),
                        local,
                    }],
                    vec![VisualModel {
                        geometry,
                        local,
                        color,
                        texture: match &o.texture {
                            Some(t) => Some(self.texture(&format!("shape '{name}'"), t)?),
                            None => None,
                        },
                    }],
                )
            }
            (None, None) => {
                return self.err_at(
                    o.name.span(),
                    format!("shape '{name}' needs `shape = \"box\" | \"sphere\" | \"cylinder\" | \"capsule\" | \"mesh\"` or `[[object.part]]` tables"),
                );
            }
        };
        let mass = match (o.mass, o.density, o.inertia) {
            (Some(_), Some(_), _) => {
                return self.err_at(o.name.span(), format!("shape '{name}': give mass or density, not both"));
            }
            (Some(mass), None, Some(inertia)) => MassModel::Inertial {
                mass,
                com: o.center_of_mass.unwrap_or([0.0; 3]),
                frame: match o.inertia_frame {
                    None => [0.0, 0.0, 0.0, 1.0],
                    Some(q) => match quat_from_array(q) {
                        // Kept as written (normalised), so that a converted scene
                        // reads back the frame it was written with.
                        Some(_) => q,
                        None => {
                            return self.err_at(
                                o.name.span(),
                                format!("shape '{name}': inertia_frame {q:?} must be a finite, non-zero quaternion [x, y, z, w]"),
                            );
                        }
                    },
                },
                inertia,
            },
            (_, _, Some(_)) => {
                return self.err_at(
                    o.name.span(),
                    format!("shape '{name}': `inertia` needs `mass` (and no `density`)"),
                );
            }
            (Some(m), None, None) => MassModel::Mass(m),
            (None, Some(d), None) => MassModel::Density(d),
            (None, None, None) => MassModel::Density(1000.0),
        };
        if o.inertia.is_none() && (o.center_of_mass.is_some() || o.inertia_frame.is_some()) {
            return self.err_at(
                o.name.span(),
                format!("shape '{name}': center_of_mass and inertia_frame need `inertia` (and `mass`)"),
            );
        }
        Ok(ShapeModel {
            geoms,
            visuals,
            dynamic: o.dynamic.unwrap_or(false),
            mass,
            friction: o.friction.unwrap_or(0.5),
            restitution: match o.restitution {
                Some(e) if e > 1.0 => {
                    return self.err_at(
                        o.name.span(),
                        format!("shape '{name}': restitution {e} must be between 0 and 1"),
                    );
                }
                e => e.unwrap_or(0.0),
            },
            collision_group: o.collision_group.unwrap_or(u32::MAX),
            collision_mask: o.collision_mask.unwrap_or(u32::MAX),
            respondable: o.respondable.unwrap_or(true),
            detectable: o.detectable.unwrap_or(true),
            measurable: o.measurable.unwrap_or(true),
            collidable: o.collidable.unwrap_or(true),
            // Scene-file mechanisms keep CoppeliaSim's rule: their parts collide unless
            // collision groups or a joint between them say otherwise.
            self_collision: o.self_collision.unwrap_or(true),
        })
    }

    /// The collision and visual parts of a shape given as `[[object.part]]` tables, in
    /// file order.
    fn parts(&mut self, name: &str, parts: &[RawPart]) -> Result<(Vec<GeomModel>, Vec<VisualModel>), LoadError> {
        let mut geoms = Vec::new();
        let mut visuals = Vec::new();
        for (k, p) in parts.iter().enumerate() {
            let label = format!("shape '{name}' part {}", k + 1);
            let Some(kind) = &p.shape else {
                let here = p.role.as_ref().map_or_else(|| self.find_key("part"), Spanned::span);
                return self.err_at(
                    here,
                    format!("{label} needs `shape = \"box\" | \"sphere\" | \"cylinder\" | \"capsule\" | \"mesh\"`"),
                );
            };
            let finite3 = |v: Option<[f64; 3]>| v.is_none_or(|a| a.iter().all(|x| x.is_finite()));
            if !finite3(p.position) || !finite3(p.orientation_deg) || !finite3(p.size) || !finite3(p.scale) {
                return self.err_at(
                    kind.span(),
                    format!("{label}: position, orientation, size and scale must be finite"),
                );
            }
            let keys = GeometryKeys {
                size: p.size,
                radius: p.radius,
                length: p.length,
                mesh: p.mesh.as_ref(),
                scale: p.scale,
            };
            let geometry = self.geometry(name, kind, &keys)?;
            let local = self.pose_with_quaternion(kind.span(), &label, p.position, p.orientation_deg, p.quaternion)?;
            let (collide, draw) = match p.role.as_ref().map(|r| (r, r.get_ref().as_str())) {
                None | Some((_, "both")) => (true, true),
                Some((_, "collision")) => (true, false),
                Some((_, "visual")) => (false, true),
                Some((r, other)) => {
                    return self.err_at(
                        r.span(),
                        format!("{label}: unknown role '{other}'; use both, collision or visual"),
                    );
                }
            };
            if collide {
                geoms.push(GeomModel {
                    geometry: geometry.clone(),
                    local,
                });
            }
            let texture = match &p.texture {
                Some(t) if draw => Some(self.texture(&label, t)?),
                Some(t) => return self.err_at(t.image.span(), format!("{label}: a collision part wears no texture")),
                None => None,
            };
            if draw {
                visuals.push(VisualModel {
                    geometry,
                    local,
                    color: p.color.unwrap_or(DEFAULT_COLOR),
                    texture,
                });
            }
        }
        Ok((geoms, visuals))
    }

    /// One primitive or mesh from its keys; `kind` is the `shape` value.
    /// A part's `texture`: its image read once per file, its coordinates file read and
    /// checked for whole triangles (the world checks them against the mesh).
    fn texture(&mut self, label: &str, t: &RawTexture) -> Result<VisualTexture, LoadError> {
        let path = self.relative(t.image.get_ref());
        let texture = match self.texture_files.get(&path) {
            Some(&i) => i,
            None => {
                let bytes = match self.files.read(&path) {
                    Ok(b) => b,
                    Err(e) => {
                        return self.err_at(
                            t.image.span(),
                            format!("{label}: cannot read '{}': {e}", path.display()),
                        );
                    }
                };
                let (resolution, rgba) = match super::texture_file::decode_png(&bytes) {
                    Ok(image) => image,
                    Err(e) => return self.err_at(t.image.span(), format!("{label}: '{}': {e}", path.display())),
                };
                let name = t.name.clone().unwrap_or_else(|| stem(&path));
                self.textures.push(TextureModel {
                    name,
                    resolution,
                    rgba: Arc::new(rgba),
                });
                self.texture_files.insert(path, self.textures.len() - 1);
                self.textures.len() - 1
            }
        };
        let mapping = match t.mapping.as_ref().map(|m| (m, m.get_ref().as_str())) {
            None | Some((_, "plane")) => 0,
            Some((_, "cylinder")) => 1,
            Some((_, "sphere")) => 2,
            Some((_, "cube")) => 3,
            Some((m, other)) => {
                return self.err_at(
                    m.span(),
                    format!("{label}: unknown texture mapping '{other}'; use plane, cylinder, sphere or cube"),
                );
            }
        };
        let scaling = t.scaling.unwrap_or([1.0, 1.0]);
        let position = t.position.unwrap_or([0.0; 3]);
        if !scaling.iter().chain(&position).all(|v| v.is_finite()) {
            return self.err_at(
                t.image.span(),
                format!("{label}: the texture's scaling and position must be finite"),
            );
        }
        let rotation = match t.quaternion {
            None => nalgebra::UnitQuaternion::identity(),
            Some(q) => match quat_from_array(q) {
                Some(q) => q,
                None => {
                    return self.err_at(
                        t.image.span(),
                        format!("{label}: the texture's quaternion is not a rotation"),
                    );
                }
            },
        };
        let coordinates = match &t.coordinates {
            None => None,
            Some(file) => {
                let path = self.relative(file.get_ref());
                let text = match self.files.read(&path) {
                    Ok(b) => String::from_utf8_lossy(&b).into_owned(),
                    Err(e) => {
                        return self.err_at(file.span(), format!("{label}: cannot read '{}': {e}", path.display()));
                    }
                };
                match super::texture_file::read_coordinates(&text) {
                    Ok(c) if c.len() % 6 == 0 => Some(Arc::new(c)),
                    Ok(c) => {
                        return self.err_at(
                            file.span(),
                            format!(
                                "{label}: {} coordinates are not whole triangles (6 a triangle)",
                                c.len()
                            ),
                        );
                    }
                    Err(e) => return self.err_at(file.span(), format!("{label}: '{}': {e}", path.display())),
                }
            }
        };
        Ok(VisualTexture {
            texture,
            mapping,
            options: t.options.unwrap_or(0),
            scaling,
            frame: Pose::from_parts(
                nalgebra::Translation3::new(position[0], position[1], position[2]),
                rotation,
            ),
            coordinates,
        })
    }

    fn geometry(&self, name: &str, kind: &Spanned<String>, o: &GeometryKeys<'_>) -> Result<Geometry, LoadError> {
        let need = |v: Option<f64>, key: &str| -> Result<f64, LoadError> {
            match v {
                Some(v) if v > 0.0 => Ok(v),
                _ => self.err_at(
                    kind.span(),
                    format!("{} '{name}' needs `{key}` > 0 (metres)", kind.get_ref()),
                ),
            }
        };
        Ok(match kind.get_ref().as_str() {
            "box" => match o.size {
                Some(s) if s.iter().all(|v| *v > 0.0) => Geometry::Box {
                    half_extents: s.map(|v| v / 2.0),
                },
                _ => {
                    return self.err_at(
                        kind.span(),
                        format!("box '{name}' needs `size = [x, y, z]` (full extents, metres, all > 0)"),
                    );
                }
            },
            "sphere" => Geometry::Sphere {
                radius: need(o.radius, "radius")?,
            },
            "cylinder" => Geometry::Cylinder {
                radius: need(o.radius, "radius")?,
                length: need(o.length, "length")?,
            },
            "capsule" => Geometry::Capsule {
                radius: need(o.radius, "radius")?,
                length: need(o.length, "length")?,
            },
            "mesh" => {
                let Some(file) = o.mesh else {
                    return self.err_at(kind.span(), format!("mesh '{name}' needs `mesh = \"file.stl\"`"));
                };
                let path = self.relative(file.get_ref());
                match super::mesh::load_mesh(self.files, &path, o.scale.unwrap_or([1.0; 3])) {
                    Ok(m) => Geometry::Mesh(m),
                    Err(e) => return self.err_at(file.span(), e.to_string()),
                }
            }
            other => {
                return self.err_at(
                    kind.span(),
                    format!("unknown shape '{other}'; use box, sphere, cylinder, capsule or mesh"),
                );
            }
        })
    }

    fn joint_mode(&self, mode: Option<&Spanned<String>>) -> Result<JointMode, LoadError> {
        match mode.map(|m| (m, m.get_ref().as_str())) {
            None | Some((_, "kinematic")) => Ok(JointMode::Kinematic),
            Some((_, "position")) => Ok(JointMode::Position),
            Some((_, "velocity")) => Ok(JointMode::Velocity),
            Some((_, "free")) => Ok(JointMode::Free),
            Some((_, "force")) => Ok(JointMode::Force),
            Some((m, other)) => self.err_at(
                m.span(),
                format!("unknown joint mode '{other}'; use kinematic, position, velocity, free or force"),
            ),
        }
    }

    fn joint(&mut self, o: &RawObject) -> Result<JointModel, LoadError> {
        let name = o.name.get_ref();
        let joint_type = match o.joint.as_ref().map(|j| (j, j.get_ref().as_str())) {
            Some((_, "revolute")) => JointType::Revolute,
            Some((_, "prismatic")) => JointType::Prismatic,
            Some((_, "fixed")) => JointType::Fixed,
            Some((j, other)) => {
                return self.err_at(
                    j.span(),
                    format!("unknown joint type '{other}'; use revolute, prismatic or fixed"),
                );
            }
            None => {
                return self.err_at(
                    o.name.span(),
                    format!("joint '{name}' needs `joint = \"revolute\" | \"prismatic\" | \"fixed\"`"),
                );
            }
        };
        // Scene files give revolute quantities in degrees; the model is in radians.
        let unit = |v: f64| {
            if joint_type == JointType::Revolute {
                v.to_radians()
            } else {
                v
            }
        };
        let cyclic = o.cyclic.unwrap_or(false);
        if cyclic && (joint_type != JointType::Revolute || o.limits.is_some()) {
            return self.err_at(
                o.name.span(),
                format!("joint '{name}': only revolute joints without limits can be cyclic"),
            );
        }
        let limits = match o.limits {
            Some([lo, hi]) if lo.is_finite() && hi.is_finite() && lo <= hi => Some((unit(lo), unit(hi))),
            Some([lo, hi]) => {
                return self.err_at(
                    o.name.span(),
                    format!("joint '{name}': limits [{lo}, {hi}] must be finite with min <= max"),
                );
            }
            None => None,
        };
        let mode = self.joint_mode(o.mode.as_ref())?;
        let initial = unit(o.initial.unwrap_or(0.0));
        if let Some(m) = &o.mimic {
            let multiplier = m.multiplier.unwrap_or(1.0);
            let offset = m.offset.unwrap_or(0.0);
            if !(multiplier.is_finite() && offset.is_finite()) {
                return self.err_at(
                    m.leader.span(),
                    format!("joint '{name}': mimic multiplier and offset must be finite"),
                );
            }
            // The follower's index is the next one: the object is pushed right after.
            self.mimics
                .push((self.objects.len(), m.leader.clone(), multiplier, unit(offset)));
        }
        Ok(JointModel {
            joint_type,
            mode,
            limits,
            cyclic,
            initial,
            target_position: o.target_position.map_or(initial, unit),
            target_velocity: unit(o.target_velocity.unwrap_or(0.0)),
            max_force: o.max_force.unwrap_or(100.0),
            kp: o.kp.unwrap_or(DEFAULT_KP),
            kd: o.kd.unwrap_or(match mode {
                // A velocity controller is all damping: torque = kd (w* - w).
                JointMode::Velocity => DEFAULT_VELOCITY_KD,
                _ => DEFAULT_KD,
            }),
            damping: o.damping.unwrap_or(TOML_JOINT_DAMPING),
            friction: o.friction.unwrap_or(0.0),
            max_velocity: match o.max_velocity {
                Some(v) if v > 0.0 => Some(unit(v)),
                Some(_) => {
                    return self.err_at(
                        o.name.span(),
                        format!("joint '{name}': max_velocity must be > 0 (leave it out for no limit)"),
                    );
                }
                None => None,
            },
            // Set by `resolve_mimics` once the leader exists.
            mimic: None,
        })
    }

    fn proximity(&self, o: &RawObject) -> Result<ProximityModel, LoadError> {
        let range = o.range.unwrap_or(0.15);
        let offset = o.offset.unwrap_or(0.0);
        if range <= 0.0 {
            return self.err_at(
                o.name.span(),
                format!("proximity sensor '{}': range must be > 0", o.name.get_ref()),
            );
        }
        match o.sensor.as_ref().map(|s| (s, s.get_ref().as_str())) {
            Some((_, "ray")) => Ok(ProximityModel::Ray { offset, range }),
            None | Some((_, "cone")) => {
                let angle = o.angle_deg.unwrap_or(30.0);
                if !(angle > 0.0 && angle < 180.0) {
                    return self.err_at(
                        o.name.span(),
                        format!("proximity sensor '{}': angle_deg must be in (0, 180)", o.name.get_ref()),
                    );
                }
                Ok(ProximityModel::Cone {
                    offset,
                    range,
                    half_angle: (angle / 2.0).to_radians(),
                })
            }
            Some((_, "pyramid")) => {
                let near_size = o.size_near.unwrap_or([0.0, 0.0]);
                let Some(far_size) = o.size_far else {
                    return self.err_at(
                        o.name.span(),
                        format!(
                            "pyramid proximity sensor '{}' needs size_far = [x, y] (m)",
                            o.name.get_ref()
                        ),
                    );
                };
                let sizes = near_size.iter().chain(&far_size);
                if !sizes.clone().all(|&w| w >= 0.0) || sizes.sum::<f64>() <= 0.0 {
                    return self.err_at(
                        o.name.span(),
                        format!(
                            "proximity sensor '{}': size_near and size_far must be >= 0 and not all 0",
                            o.name.get_ref()
                        ),
                    );
                }
                Ok(ProximityModel::Pyramid {
                    offset,
                    range,
                    near_size,
                    far_size,
                })
            }
            Some((_, "cylinder")) => {
                let radius = o.radius.unwrap_or(0.05);
                let radius_far = o.radius_far.unwrap_or(radius);
                if !(radius >= 0.0 && radius_far >= 0.0 && radius + radius_far > 0.0) {
                    return self.err_at(
                        o.name.span(),
                        format!(
                            "proximity sensor '{}': radius and radius_far must be >= 0 and not both 0",
                            o.name.get_ref()
                        ),
                    );
                }
                Ok(ProximityModel::Cylinder {
                    offset,
                    range,
                    radius,
                    radius_far,
                })
            }
            Some((_, "disc")) => {
                let angle = o.angle_deg.unwrap_or(360.0);
                let thickness = o.thickness.unwrap_or(0.01);
                if !(angle > 0.0 && angle <= 360.0 && thickness > 0.0) {
                    return self.err_at(
                        o.name.span(),
                        format!(
                            "proximity sensor '{}': a disc needs angle_deg in (0, 360] and thickness > 0",
                            o.name.get_ref()
                        ),
                    );
                }
                Ok(ProximityModel::Disc {
                    offset,
                    range,
                    half_angle: (angle / 2.0).to_radians(),
                    thickness,
                })
            }
            Some((s, other)) => self.err_at(
                s.span(),
                format!("unknown proximity sensor type '{other}'; use ray, cone, pyramid, cylinder or disc"),
            ),
        }
    }

    fn vision(&self, o: &RawObject) -> Result<VisionModel, LoadError> {
        let [w, h] = o.resolution.unwrap_or([256, 256]);
        if !(1..=MAX_VISION_RESOLUTION).contains(&w) || !(1..=MAX_VISION_RESOLUTION).contains(&h) {
            return self.err_at(
                o.name.span(),
                format!(
                    "vision sensor '{}': resolution must be 1..={MAX_VISION_RESOLUTION} per side",
                    o.name.get_ref()
                ),
            );
        }
        // The images of every sensor so far, this one included, within the cap.
        let before: u64 = self
            .objects
            .iter()
            .filter_map(|o| match &o.kind {
                ObjectModelKind::VisionSensor(v) => Some(vision_image_bytes(v.resolution)),
                _ => None,
            })
            .sum();
        let total = before + vision_image_bytes([w, h]);
        if total > MAX_VISION_IMAGE_BYTES {
            return self.err_at(
                o.name.span(),
                format!(
                    "vision sensor '{}': {w}x{h} brings the scene's vision images (RGB and depth, {VISION_BYTES_PER_PIXEL} bytes a pixel) to {} MiB, over the {} MiB cap",
                    o.name.get_ref(),
                    total.div_ceil(1 << 20),
                    MAX_VISION_IMAGE_BYTES >> 20
                ),
            );
        }
        let projection = match &o.projection {
            None => Projection::Perspective,
            Some(p) => match p.get_ref().as_str() {
                "perspective" => Projection::Perspective,
                "orthographic" => Projection::Orthographic,
                other => {
                    return self.err_at(
                        p.span(),
                        format!("unknown projection '{other}'; use perspective or orthographic"),
                    );
                }
            },
        };
        let render_mode = match &o.render_mode {
            None => RenderMode::Visible,
            Some(m) => match m.get_ref().as_str() {
                "visible" => RenderMode::Visible,
                "color_coded" => RenderMode::ColorCoded,
                other => {
                    return self.err_at(
                        m.span(),
                        format!("unknown render mode '{other}'; use visible or color_coded"),
                    );
                }
            },
        };
        if let Some(r) = o.ros2_rate
            && !(r.is_finite() && r >= 0.0)
        {
            return self.err_at(
                o.name.span(),
                format!(
                    "vision sensor '{}': ros2_rate {r} must be 0 (no images) or a positive number of Hz",
                    o.name.get_ref()
                ),
            );
        }
        if o.background.is_some_and(|c| !c.iter().all(|v| (0.0..=1.0).contains(v))) {
            return self.err_at(
                o.name.span(),
                format!(
                    "vision sensor '{}': background colour components must be from 0 to 1",
                    o.name.get_ref()
                ),
            );
        }
        let fov = o.fov_deg.unwrap_or(60.0);
        let ortho_size = o.ortho_size.unwrap_or(1.0);
        let near = o.near.unwrap_or(0.01);
        let far = o.far.unwrap_or(1.0);
        if !(fov > 0.0
            && fov < 180.0
            && ortho_size > 0.0
            && ortho_size.is_finite()
            && near > 0.0
            && far > near
            && far.is_finite())
        {
            return self.err_at(
                o.name.span(),
                format!(
                    "vision sensor '{}': need 0 < fov_deg < 180, ortho_size > 0 and 0 < near < far",
                    o.name.get_ref()
                ),
            );
        }
        Ok(VisionModel {
            resolution: [w, h],
            projection,
            fov: fov.to_radians(),
            ortho_size,
            near,
            far,
            render_mode,
            ignore_rgb: o.ignore_rgb.unwrap_or(false),
            ignore_depth: o.ignore_depth.unwrap_or(false),
            ros2_rate: o.ros2_rate,
            background: o.background,
        })
    }

    /// Points each `mimic` follower at its leader, which must be a joint.
    fn resolve_mimics(&mut self) -> Result<(), LoadError> {
        for (follower, leader_ref, multiplier, offset) in std::mem::take(&mut self.mimics) {
            let leader = self.reference(&leader_ref)?;
            if leader == follower || !matches!(self.objects[leader].kind, ObjectModelKind::Joint(_)) {
                return self.err_at(
                    leader_ref.span(),
                    format!("mimic leader '{}' must be another joint", leader_ref.get_ref()),
                );
            }
            if let ObjectModelKind::Joint(j) = &mut self.objects[follower].kind {
                j.mimic = Some(MimicModel {
                    leader,
                    multiplier,
                    offset,
                });
            }
        }
        Ok(())
    }

    /// The `[[reference]]` entries: each names an object, a tag and the objects it holds.
    fn references(&self, raw: &RawScene) -> Result<Vec<ReferencedHandles>, LoadError> {
        let mut out = Vec::with_capacity(raw.reference.len());
        for r in &raw.reference {
            let object = self.reference(&r.object)?;
            let targets = r.objects.iter().map(|t| self.reference(t)).collect::<Result<_, _>>()?;
            out.push(ReferencedHandles {
                object,
                tag: r.tag.clone().unwrap_or_default(),
                targets,
            });
        }
        Ok(out)
    }

    /// The `[[user_parameter]]` tables: a named object, a non-empty name not given
    /// twice for the same object.
    fn user_parameters(&self, raw: &RawScene) -> Result<Vec<UserParameter>, LoadError> {
        let mut out: Vec<UserParameter> = Vec::with_capacity(raw.user_parameter.len());
        for p in &raw.user_parameter {
            let object = self.reference(&p.object)?;
            let name = p.name.get_ref();
            if name.is_empty() || out.iter().any(|o| o.object == object && &o.name == name) {
                return self.err_at(
                    p.name.span(),
                    format!("user_parameter: name '{name}' is empty or given twice for this object"),
                );
            }
            out.push(UserParameter {
                object,
                name: name.clone(),
                unit: p.unit.clone().unwrap_or_default(),
                value: p.value.clone(),
            });
        }
        Ok(out)
    }

    /// The `[[ik_group]]` tables: unique names, elements whose tip and target are
    /// dummies, a known method, and settings in range. Whether each chain has a joint
    /// between base and tip is checked when the world is built.
    fn ik_groups(&self, raw: &RawScene) -> Result<Vec<IkGroupModel>, LoadError> {
        let mut out: Vec<IkGroupModel> = Vec::with_capacity(raw.ik_group.len());
        for g in &raw.ik_group {
            let name = g.name.get_ref();
            if name.is_empty() || out.iter().any(|o| &o.name == name) {
                return self.err_at(g.name.span(), format!("ik_group: name '{name}' is empty or used twice"));
            }
            let method = match g.method.as_ref().map(|m| m.get_ref().as_str()) {
                None | Some("pseudo_inverse") => IkMethodModel::PseudoInverse,
                Some("damped_least_squares") => IkMethodModel::DampedLeastSquares,
                Some(other) => {
                    let span = g.method.as_ref().map_or(g.name.span(), Spanned::span);
                    return self.err_at(
                        span,
                        format!(
                            "ik_group '{name}': unknown method '{other}' (use \"pseudo_inverse\" or \"damped_least_squares\")"
                        ),
                    );
                }
            };
            let damping = g.damping.unwrap_or(0.1);
            if !(damping.is_finite() && damping >= 0.0) {
                return self.err_at(g.name.span(), format!("ik_group '{name}': damping must be >= 0"));
            }
            let max_iterations = g.max_iterations.unwrap_or(3);
            if !(1..=100_000).contains(&max_iterations) {
                return self.err_at(
                    g.name.span(),
                    format!("ik_group '{name}': max_iterations must be 1..100000"),
                );
            }
            if g.element.is_empty() {
                return self.err_at(
                    g.name.span(),
                    format!("ik_group '{name}': needs at least one [[ik_group.element]]"),
                );
            }
            let mut elements = Vec::with_capacity(g.element.len());
            for e in &g.element {
                let [tip, target] = [&e.tip, &e.target].map(|r| self.reference(r));
                let (tip, target) = (tip?, target?);
                for (i, r) in [(tip, &e.tip), (target, &e.target)] {
                    if !matches!(self.objects[i].kind, ObjectModelKind::Dummy) {
                        return self.err_at(r.span(), format!("ik_group '{name}': '{}' is not a dummy", r.get_ref()));
                    }
                }
                let base = e.base.as_ref().map(|b| self.reference(b)).transpose()?;
                let constraints = match &e.constraints {
                    None => 31,
                    Some(c) => match ik_constraints(c.get_ref()) {
                        Some(bits) => bits,
                        None => {
                            return self.err_at(
                                c.span(),
                                format!(
                                    "ik_group '{name}': constraints '{}' (use \"pose\", \"position\", \"orientation\", \
                                     or components joined by '+': x, y, z, alpha_beta, gamma)",
                                    c.get_ref()
                                ),
                            );
                        }
                    },
                };
                elements.push(IkElementModel {
                    tip,
                    target,
                    base,
                    constraints,
                });
            }
            out.push(IkGroupModel {
                name: name.clone(),
                elements,
                method,
                damping,
                max_iterations,
                explicit: g.explicit.unwrap_or(false),
            });
        }
        Ok(out)
    }

    /// The `[[collection]]` tables: unique names, items of a known scope, each naming an
    /// object except `all`.
    fn collections(&self, raw: &RawScene) -> Result<Vec<CollectionModel>, LoadError> {
        let mut out: Vec<CollectionModel> = Vec::with_capacity(raw.collection.len());
        for c in &raw.collection {
            let name = c.name.get_ref();
            if name.is_empty() || out.iter().any(|o| &o.name == name) {
                return self.err_at(
                    c.name.span(),
                    format!("collection: name '{name}' is empty or used twice"),
                );
            }
            let mut items = Vec::with_capacity(c.item.len());
            for i in &c.item {
                let scope = match i.scope.as_ref().map(|s| s.get_ref().as_str()) {
                    None | Some("object") => CollectionScope::Object,
                    Some("tree") => CollectionScope::Tree,
                    Some("chain") => CollectionScope::Chain,
                    Some("all") => CollectionScope::All,
                    Some(other) => {
                        let span = i.scope.as_ref().map_or(c.name.span(), Spanned::span);
                        return self.err_at(
                            span,
                            format!("collection '{name}': unknown scope '{other}' (use object, tree, chain or all)"),
                        );
                    }
                };
                let object = match (&i.object, scope) {
                    (None, CollectionScope::All) => None,
                    (Some(o), CollectionScope::All) => {
                        return self.err_at(o.span(), format!("collection '{name}': an 'all' item names no object"));
                    }
                    (Some(o), _) => Some(self.reference(o)?),
                    (None, _) => {
                        return self.err_at(c.name.span(), format!("collection '{name}': an item needs its object"));
                    }
                };
                items.push(CollectionItemModel {
                    scope,
                    object,
                    remove: i.remove.unwrap_or(false),
                    exclude_base: i.exclude_base.unwrap_or(false),
                });
            }
            out.push(CollectionModel {
                name: name.clone(),
                items,
            });
        }
        Ok(out)
    }

    /// The `[[dummy_link]]` pairs, each two distinct dummies, in file order: those that
    /// hold whole frames, then those with `free_rotation`.
    fn dummy_links(&self, raw: &RawScene) -> Result<(Vec<DummyPair>, Vec<DummyPair>), LoadError> {
        let mut out = Vec::with_capacity(raw.dummy_link.len());
        let mut balls = Vec::new();
        for link in &raw.dummy_link {
            let [a, b] = &link.dummies;
            let pair = [self.reference(a)?, self.reference(b)?];
            for (i, r) in pair.iter().zip([a, b]) {
                if !matches!(self.objects[*i].kind, ObjectModelKind::Dummy) {
                    return self.err_at(r.span(), format!("dummy_link: '{}' is not a dummy", r.get_ref()));
                }
            }
            if pair[0] == pair[1] {
                return self.err_at(a.span(), "dummy_link: a dummy cannot be linked to itself");
            }
            if link.free_rotation == Some(true) {
                balls.push(pair);
            } else {
                out.push(pair);
            }
        }
        Ok((out, balls))
    }

    fn camera(&self, o: &RawObject) -> Result<CameraModel, LoadError> {
        let fov = o.fov_deg.unwrap_or(60.0);
        if !(fov > 0.0 && fov < 180.0) {
            return self.err_at(
                o.name.span(),
                format!("camera '{}': need 0 < fov_deg < 180", o.name.get_ref()),
            );
        }
        Ok(CameraModel { fov: fov.to_radians() })
    }

    fn light(&self, o: &RawObject) -> Result<LightModel, LoadError> {
        let name = o.name.get_ref();
        let light_type = match o.light.as_ref().map(|t| (t.get_ref().as_str(), t.span())) {
            None | Some(("omnidirectional", _)) => LightType::Omnidirectional,
            Some(("spot", _)) => LightType::Spot,
            Some(("directional", _)) => LightType::Directional,
            Some((other, span)) => {
                return self.err_at(
                    span,
                    format!("light '{name}': unknown light '{other}'; use omnidirectional, spot or directional"),
                );
            }
        };
        let mut l = LightModel::new(light_type);
        let colour = |v: [f64; 3]| v.iter().all(|c| (0.0..=1.0).contains(c));
        for (key, v) in [("diffuse", o.diffuse), ("specular", o.specular)] {
            if v.is_some_and(|v| !colour(v)) {
                return self.err_at(
                    o.name.span(),
                    format!("light '{name}': {key} components must be from 0 to 1"),
                );
            }
        }
        l.on = o.on.unwrap_or(true);
        l.diffuse = o.diffuse.unwrap_or(l.diffuse);
        l.specular = o.specular.unwrap_or(l.specular);
        l.casts_shadows = o.casts_shadows.unwrap_or(false);
        if let Some(e) = o.spot_exponent {
            match i32::try_from(e) {
                Ok(e) if (0..=LightModel::MAX_SPOT_EXPONENT).contains(&e) => l.spot_exponent = e,
                _ => return self.err_at(o.name.span(), format!("light '{name}': spot_exponent must be 0 to 128")),
            }
        }
        if let Some(deg) = o.spot_cutoff_deg {
            // A cutoff written from a 4.1 file's single-precision pi/2 may exceed 90
            // degrees in its last digits; it is pi/2.
            if !(5.0..=90.0 + 1e-4).contains(&deg) {
                return self.err_at(
                    o.name.span(),
                    format!("light '{name}': spot_cutoff_deg must be 5 to 90"),
                );
            }
            l.spot_cutoff = deg.to_radians().min(LightModel::MAX_SPOT_CUTOFF);
        }
        if let Some(a) = o.attenuation {
            if !a.iter().all(|v| v.is_finite() && *v >= 0.0) {
                return self.err_at(
                    o.name.span(),
                    format!("light '{name}': attenuation factors must be finite and >= 0"),
                );
            }
            l.attenuation = a;
        }
        Ok(l)
    }

    fn path_object(&self, o: &RawObject) -> Result<PathModel, LoadError> {
        let name = o.name.get_ref();
        let ctrl_points = o.ctrl_points.clone().unwrap_or_default();
        if ctrl_points.iter().flatten().any(|v| !v.is_finite()) {
            return self.err_at(o.name.span(), format!("path '{name}': ctrl_points must be finite"));
        }
        let smoothness = o.smoothness.unwrap_or(0.0);
        if !(0.0..=1.0).contains(&smoothness) {
            return self.err_at(o.name.span(), format!("path '{name}': smoothness must be from 0 to 1"));
        }
        let subdiv = o.subdiv.unwrap_or(100) as usize;
        if !(2..=1_000_000).contains(&subdiv) {
            return self.err_at(o.name.span(), format!("path '{name}': subdiv must be 2 to 1000000"));
        }
        Ok(PathModel {
            ctrl_points,
            closed: o.closed.unwrap_or(false),
            smoothness,
            subdiv,
        })
    }

    fn robot(&mut self, r: &RawRobot, parent: Option<usize>, name: &str) -> Result<UrdfIndex, LoadError> {
        let path = self.relative(r.urdf.get_ref());
        if !self.files.is_file(&path) {
            return self.err_at(r.urdf.span(), format!("URDF '{}' not found", path.display()));
        }
        let mut initial = HashMap::new();
        if let Some(t) = &r.initial {
            for (k, v) in t {
                match v.as_float().or_else(|| v.as_integer().map(|i| i as f64)) {
                    Some(f) if f.is_finite() => {
                        initial.insert(k.clone(), f);
                    }
                    _ => {
                        return self.err_at(
                            r.urdf.span(),
                            format!("robot '{name}': initial.{k} must be a number (degrees or metres)"),
                        );
                    }
                }
            }
        }
        let mut joint_modes = HashMap::new();
        if let Some(t) = &r.joint_modes {
            for (k, v) in t {
                let mode = match v.as_str() {
                    Some("kinematic") => JointMode::Kinematic,
                    Some("position") => JointMode::Position,
                    Some("velocity") => JointMode::Velocity,
                    Some("free") => JointMode::Free,
                    Some("force") => JointMode::Force,
                    _ => {
                        return self.err_at(
                            r.urdf.span(),
                            format!("robot '{name}': joint_modes.{k} must be \"kinematic\", \"position\", \"velocity\", \"free\" or \"force\""),
                        );
                    }
                };
                joint_modes.insert(k.clone(), mode);
            }
        }
        let include = UrdfInclude {
            name: r.name.as_ref().map(|n| n.get_ref().clone()),
            joint_modes,
            self_collision: r.self_collision.unwrap_or(false),
            parent,
            pose: Self::pose(r.position, r.orientation_deg),
            fixed_base: r.fixed_base.unwrap_or(true),
            joint_mode: self.joint_mode(r.joint_mode.as_ref())?,
            max_force: r.max_force,
            kp: r.kp.unwrap_or(DEFAULT_KP),
            kd: r
                .kd
                .unwrap_or(if self.joint_mode(r.joint_mode.as_ref())? == JointMode::Velocity {
                    DEFAULT_VELOCITY_KD
                } else {
                    DEFAULT_KD
                }),
            initial,
        };
        let idx = import_urdf(
            self.files,
            &path,
            &include,
            &self.opts.package_paths,
            &mut self.objects,
            &mut self.warnings,
        )?;
        if let Some(k) = include.joint_modes.keys().find(|k| !idx.joints.contains_key(*k)) {
            return self.err_at(
                r.urdf.span(),
                format!("robot '{name}': joint_modes.{k} names no joint of the URDF"),
            );
        }
        for k in include.initial.keys() {
            if !idx.joints.contains_key(k) {
                self.warnings.push(format!(
                    "robot '{name}': initial.{k} names no joint of the URDF; ignored"
                ));
            }
        }
        if let Some(s) = &r.script {
            self.attach_script(idx.base, s)?;
        }
        self.urdf_robots.push(idx.robot_model());
        Ok(idx)
    }
}
