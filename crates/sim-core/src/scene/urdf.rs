//! URDF import: a robot becomes objects of the tree, as CoppeliaSim's importer builds it.
//!
//! - a model base (a dummy aliased by the robot name) at the include pose;
//! - each link a shape aliased by the link name, whose frame is the URDF link frame;
//! - each joint an object aliased by the joint name, between its parent and child link,
//!   oriented so that its local Z axis is the URDF axis (gantry joints move about/along Z).
//!
//! Supported: `revolute`, `continuous`, `prismatic` and `fixed` joints with limits and
//! effort; `<inertial>`; `<visual>` and `<collision>` with box, cylinder, sphere, capsule
//! and STL/OBJ/DAE meshes (with scale); robot-level and inline materials.
//! Documented, not warned (every real URDF has it): `<limit velocity>` is not enforced;
//! joints respect `effort` through their motor's maximum force.
//! Reported as warnings and otherwise ignored: `floating` and `planar` joints (imported as
//! fixed), `<dynamics>`, `<mimic>`, `<safety_controller>`, `<calibration>`,
//! `<transmission>`, `<gazebo>` and textures. Nothing is dropped without a warning.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use nalgebra::{Translation3, UnitQuaternion, Vector3};

use super::error::LoadError;
use super::files::Files;
use super::mesh::{load_mesh, resolve_mesh_path};
use super::model::{
    GeomModel, Geometry, JointMode, JointModel, JointType, MassModel, ObjectModel, ObjectModelKind, ShapeModel,
    VisualModel,
};
use crate::math::{Pose, rotation_z_to};

/// How a URDF is placed and driven.
#[derive(Debug, Clone)]
pub struct UrdfInclude {
    /// Alias of the model base; defaults to the URDF robot name.
    pub name: Option<String>,
    /// Parent object index, `None` for the world.
    pub parent: Option<usize>,
    /// Pose of the robot base relative to the parent.
    pub pose: Pose,
    /// Whether the base link is fixed to the world.
    pub fixed_base: bool,
    /// Mode of every movable joint.
    pub joint_mode: JointMode,
    /// Maximum torque/force override; default: the URDF effort, else 100.
    pub max_force: Option<f64>,
    /// Position stiffness for every joint.
    pub kp: f64,
    /// Damping for every joint.
    pub kd: f64,
    /// Initial positions by joint name, **in degrees for revolute joints** and metres for
    /// prismatic ones (the scene file's units).
    pub initial: HashMap<String, f64>,
}

impl Default for UrdfInclude {
    fn default() -> Self {
        Self {
            name: None,
            parent: None,
            pose: Pose::identity(),
            fixed_base: true,
            joint_mode: JointMode::Kinematic,
            max_force: None,
            kp: DEFAULT_KP,
            kd: DEFAULT_KD,
            initial: HashMap::new(),
        }
    }
}

/// Default position stiffness of dynamic joints, N·m/rad.
pub const DEFAULT_KP: f64 = 2000.0;
/// Default damping of dynamic joints, N·m·s/rad.
pub const DEFAULT_KD: f64 = 100.0;

/// Where a robot's parts landed in the object list.
#[derive(Debug, Clone)]
pub struct UrdfIndex {
    /// The model base.
    pub base: usize,
    /// Link objects by URDF link name.
    pub links: HashMap<String, usize>,
    /// Joint objects by URDF joint name.
    pub joints: HashMap<String, usize>,
}

/// Reads a URDF file and appends its objects to `objects`.
///
/// # Errors
/// Malformed XML ([`LoadError::Syntax`], with line and column), a joint cycle, a link
/// with two parents, two links or two joints with one name, an unknown link
/// ([`LoadError::Invalid`] at the element), a missing mesh.
pub fn import_urdf(
    files: &dyn Files,
    path: &Path,
    include: &UrdfInclude,
    package_paths: &[PathBuf],
    objects: &mut Vec<ObjectModel>,
    warnings: &mut Vec<String>,
) -> Result<UrdfIndex, LoadError> {
    let bytes = files.read(path).map_err(|e| LoadError::Io {
        path: path.to_owned(),
        source: e,
        hint: String::new(),
    })?;
    let text = String::from_utf8(bytes).map_err(|_| LoadError::Urdf {
        path: path.to_owned(),
        message: "the file is not UTF-8 text".into(),
    })?;
    let robot = urdf_rs::read_from_string(&text).map_err(|e| malformed(path, &text, &e.to_string()))?;
    let urdf_err = |message: String| LoadError::Urdf {
        path: path.to_owned(),
        message,
    };
    // An error about one `<link>` or `<joint>` element, at its line and column.
    let at = |tag: &str, name: &str, occurrence: usize, message: String| match element_position(
        &text, tag, name, occurrence,
    ) {
        Some((line, column)) => LoadError::Invalid {
            path: path.to_owned(),
            line,
            column,
            message,
        },
        None => urdf_err(message),
    };
    for tag in ["transmission", "gazebo"] {
        if text.contains(&format!("<{tag}")) {
            warnings.push(format!(
                "{}: <{tag}> elements are not supported and were ignored",
                path.display()
            ));
        }
    }

    // Build the link tree and check it is one tree. Duplicate names are refused rather
    // than letting the later element shadow the earlier one in `robot/part` references.
    let mut link_ids: HashMap<&str, usize> = HashMap::new();
    for (i, l) in robot.links.iter().enumerate() {
        if link_ids.insert(l.name.as_str(), i).is_some() {
            return Err(at(
                "link",
                &l.name,
                1,
                format!("two links are named '{}'; link names must be unique", l.name),
            ));
        }
    }
    let mut joint_names = HashSet::new();
    for j in &robot.joints {
        if !joint_names.insert(j.name.as_str()) {
            return Err(at(
                "joint",
                &j.name,
                1,
                format!("two joints are named '{}'; joint names must be unique", j.name),
            ));
        }
    }
    let mut parent_joint: Vec<Option<usize>> = vec![None; robot.links.len()];
    let mut child_joints: Vec<Vec<usize>> = vec![Vec::new(); robot.links.len()];
    // The parent and child link of each joint, by joint index.
    let mut joint_parent: Vec<usize> = Vec::with_capacity(robot.joints.len());
    let mut joint_child: Vec<usize> = Vec::with_capacity(robot.joints.len());
    for (ji, j) in robot.joints.iter().enumerate() {
        let p = *link_ids.get(j.parent.link.as_str()).ok_or_else(|| {
            at(
                "joint",
                &j.name,
                0,
                format!(
                    "joint '{}' names parent link '{}', which does not exist",
                    j.name, j.parent.link
                ),
            )
        })?;
        let c = *link_ids.get(j.child.link.as_str()).ok_or_else(|| {
            at(
                "joint",
                &j.name,
                0,
                format!(
                    "joint '{}' names child link '{}', which does not exist",
                    j.name, j.child.link
                ),
            )
        })?;
        if let Some(other) = parent_joint[c] {
            return Err(at(
                "joint",
                &j.name,
                0,
                format!(
                    "link '{}' is the child of two joints ('{}' and '{}'); a URDF must be a tree",
                    j.child.link, robot.joints[other].name, j.name
                ),
            ));
        }
        parent_joint[c] = Some(ji);
        child_joints[p].push(ji);
        joint_parent.push(p);
        joint_child.push(c);
    }
    let roots: Vec<usize> = (0..robot.links.len()).filter(|&i| parent_joint[i].is_none()).collect();
    if roots.len() > 1 {
        let names: Vec<&str> = roots.iter().map(|&i| robot.links[i].name.as_str()).collect();
        return Err(urdf_err(format!(
            "several root links ({}); connect them with joints so the robot is one tree",
            names.join(", ")
        )));
    }
    // Every link has at most one parent, so a link the root does not reach (every link,
    // when no link is a root) hangs below a cycle of joints. Without this check such
    // links would silently be left out of the robot.
    let mut reachable = vec![false; robot.links.len()];
    let mut todo = roots.clone();
    while let Some(l) = todo.pop() {
        if !std::mem::replace(&mut reachable[l], true) {
            todo.extend(child_joints[l].iter().map(|&ji| joint_child[ji]));
        }
    }
    if let Some(stray) = reachable.iter().position(|r| !r) {
        let cycle = joint_cycle(stray, &parent_joint, &joint_parent);
        let names: Vec<String> = cycle.iter().map(|&ji| format!("'{}'", robot.joints[ji].name)).collect();
        let first = cycle.first().map_or("", |&ji| robot.joints[ji].name.as_str());
        return Err(at(
            "joint",
            first,
            0,
            format!(
                "the joints {} form a cycle, so link '{}' is not connected to the root; a URDF must be a tree",
                names.join(" -> "),
                robot.links[stray].name
            ),
        ));
    }
    let Some(&root) = roots.first() else {
        return Err(urdf_err("the robot has no <link>; a URDF needs at least one".into()));
    };

    let materials: HashMap<&str, [f32; 3]> = robot
        .materials
        .iter()
        .filter_map(|m| m.color.as_ref().map(|c| (m.name.as_str(), rgb(&c.rgba.0))))
        .collect();
    let urdf_dir = path.parent().unwrap_or(Path::new("."));
    let ctx = Ctx {
        files,
        path,
        urdf_dir,
        package_paths,
        materials,
    };

    let base_alias = include.name.clone().unwrap_or_else(|| robot.name.clone());
    let base = objects.len();
    objects.push(ObjectModel {
        alias: base_alias,
        parent: include.parent,
        local: include.pose,
        model_base: true,
        kind: ObjectModelKind::Dummy,
    });
    let mut index = UrdfIndex {
        base,
        links: HashMap::new(),
        joints: HashMap::new(),
    };

    // Depth-first from the root; an explicit stack keeps deep chains off the call stack.
    // Each entry: (link, parent object, pose of the link frame relative to that parent,
    // whether the link is driven by a dynamic joint).
    let mut stack = vec![(root, base, Pose::identity(), !include.fixed_base)];
    let mut visited = vec![false; robot.links.len()];
    while let Some((li, parent_obj, local, dynamic)) = stack.pop() {
        if std::mem::replace(&mut visited[li], true) {
            return Err(urdf_err("the joints form a cycle".into()));
        }
        let link = &robot.links[li];
        let shape = ctx.link_shape(link, dynamic, warnings)?;
        let link_obj = objects.len();
        objects.push(ObjectModel {
            alias: link.name.clone(),
            parent: Some(parent_obj),
            local,
            model_base: false,
            kind: ObjectModelKind::Shape(shape),
        });
        index.links.insert(link.name.clone(), link_obj);

        // Reverse so that popping visits children in file order.
        for &ji in child_joints[li].iter().rev() {
            let j = &robot.joints[ji];
            let origin = urdf_pose(&j.origin);
            let axis = Vector3::from(j.axis.xyz.0);
            let axis = if axis.norm() > 1e-9 {
                axis.normalize()
            } else {
                Vector3::x()
            };
            let align = rotation_z_to(&axis);
            // urdf-rs reads a missing <limit> as [0, 0], which would freeze the joint.
            let missing_limit = j.limit.lower == 0.0 && j.limit.upper == 0.0;
            if missing_limit
                && matches!(
                    j.joint_type,
                    urdf_rs::JointType::Revolute | urdf_rs::JointType::Prismatic
                )
            {
                warnings.push(format!(
                    "{}: joint '{}' has no <limit lower upper>; imported without limits",
                    path.display(),
                    j.name
                ));
            }
            let limit = (!missing_limit).then_some((j.limit.lower, j.limit.upper));
            let (joint_type, limits, cyclic) = match j.joint_type {
                urdf_rs::JointType::Revolute => (JointType::Revolute, limit, false),
                urdf_rs::JointType::Continuous => (JointType::Revolute, None, true),
                urdf_rs::JointType::Prismatic => (JointType::Prismatic, limit, false),
                urdf_rs::JointType::Fixed => (JointType::Fixed, None, false),
                ref other => {
                    warnings.push(format!(
                        "{}: joint '{}' of type {other:?} is not supported; imported as fixed",
                        path.display(),
                        j.name
                    ));
                    (JointType::Fixed, None, false)
                }
            };
            if let Some((lo, hi)) = limits
                && lo > hi
            {
                return Err(urdf_err(format!(
                    "joint '{}' has lower limit {lo} above upper limit {hi}",
                    j.name
                )));
            }
            for (present, what) in [
                (j.dynamics.is_some(), "<dynamics>"),
                (j.mimic.is_some(), "<mimic>"),
                (j.safety_controller.is_some(), "<safety_controller>"),
                (j.calibration.is_some(), "<calibration>"),
            ] {
                if present {
                    warnings.push(format!(
                        "{}: joint '{}': {what} is not supported and was ignored",
                        path.display(),
                        j.name
                    ));
                }
            }
            let initial = match include.initial.get(&j.name) {
                Some(v) if joint_type == JointType::Revolute => v.to_radians(),
                Some(v) => *v,
                None => 0.0,
            };
            let mode = if joint_type == JointType::Fixed {
                JointMode::Kinematic
            } else {
                include.joint_mode
            };
            let effort = if j.limit.effort > 0.0 { j.limit.effort } else { 100.0 };
            let joint_obj = objects.len();
            objects.push(ObjectModel {
                alias: j.name.clone(),
                parent: Some(link_obj),
                local: origin * UnitQuaternion::from(align),
                model_base: false,
                kind: ObjectModelKind::Joint(JointModel {
                    joint_type,
                    mode,
                    limits,
                    cyclic,
                    initial,
                    target_position: initial,
                    target_velocity: 0.0,
                    max_force: include.max_force.unwrap_or(effort),
                    kp: include.kp,
                    kd: include.kd,
                }),
            });
            index.joints.insert(j.name.clone(), joint_obj);
            let child = link_ids[j.child.link.as_str()];
            // The child link frame equals the joint frame at q = 0, i.e. the joint object
            // frame without the axis alignment.
            let child_local = Pose::from_parts(Translation3::identity(), align.inverse());
            let child_dynamic = match mode {
                JointMode::Kinematic => joint_type == JointType::Fixed && dynamic,
                JointMode::Position | JointMode::Velocity => true,
            };
            stack.push((child, joint_obj, child_local, child_dynamic));
        }
    }
    Ok(index)
}

/// The error for a file urdf-rs cannot read. urdf-rs does not say where the problem is,
/// so a well-formedness error is located with roxmltree (line and column); a well-formed
/// file with a wrong structure (a missing attribute, a bad number) keeps urdf-rs's text.
fn malformed(path: &Path, text: &str, reason: &str) -> LoadError {
    match roxmltree::Document::parse_with_options(text, xml_options()) {
        Err(e) => {
            let pos = e.pos();
            let message = e.to_string();
            // roxmltree appends " at ROW:COL", which the error already leads with.
            let message = message.strip_suffix(&format!(" at {pos}")).unwrap_or(&message);
            LoadError::Syntax {
                path: path.to_owned(),
                line: pos.row as usize,
                column: pos.col as usize,
                message: format!("malformed URDF XML: {message}"),
            }
        }
        Ok(_) => LoadError::Urdf {
            path: path.to_owned(),
            message: format!("malformed URDF: {reason}"),
        },
    }
}

/// URDFs may carry a DOCTYPE (roxmltree refuses one by default).
fn xml_options() -> roxmltree::ParsingOptions {
    roxmltree::ParsingOptions {
        allow_dtd: true,
        ..roxmltree::ParsingOptions::default()
    }
}

/// Line and column (1-based) of the `occurrence`-th (0-based) `<tag name="name">` element
/// below `<robot>`, for errors about one link or joint. Only used on error paths, so the
/// file is parsed again here rather than carrying positions through urdf-rs.
fn element_position(text: &str, tag: &str, name: &str, occurrence: usize) -> Option<(usize, usize)> {
    let doc = roxmltree::Document::parse_with_options(text, xml_options()).ok()?;
    let node = doc
        .root_element()
        .children()
        .filter(|n| n.has_tag_name(tag) && n.attribute("name") == Some(name))
        .nth(occurrence)?;
    let pos = doc.text_pos_at(node.range().start);
    Some((pos.row as usize, pos.col as usize))
}

/// The joints of the cycle reached by walking from link `start` towards its ancestors,
/// in parent-to-child order starting with the joint that comes first in the file.
/// `start` must not be reachable from a root link, so the walk never ends at a root.
fn joint_cycle(start: usize, parent_joint: &[Option<usize>], joint_parent: &[usize]) -> Vec<usize> {
    // Walk up until a link repeats: that link is on the cycle.
    let mut seen = vec![false; parent_joint.len()];
    let mut link = start;
    while !std::mem::replace(&mut seen[link], true) {
        match parent_joint[link] {
            Some(j) => link = joint_parent[j],
            None => return Vec::new(),
        }
    }
    // Collect the cycle child-to-parent, then reverse it and rotate it to a stable start.
    let mut cycle = Vec::new();
    let first = link;
    while let Some(j) = parent_joint[link] {
        cycle.push(j);
        link = joint_parent[j];
        if link == first {
            break;
        }
    }
    cycle.reverse();
    if let Some(k) = cycle.iter().enumerate().min_by_key(|(_, j)| **j).map(|(k, _)| k) {
        cycle.rotate_left(k);
    }
    cycle
}

struct Ctx<'a> {
    files: &'a dyn Files,
    path: &'a Path,
    urdf_dir: &'a Path,
    package_paths: &'a [PathBuf],
    materials: HashMap<&'a str, [f32; 3]>,
}

impl Ctx<'_> {
    fn link_shape(
        &self,
        link: &urdf_rs::Link,
        dynamic: bool,
        warnings: &mut Vec<String>,
    ) -> Result<ShapeModel, LoadError> {
        let mut geoms = Vec::new();
        for c in &link.collision {
            geoms.push(GeomModel {
                geometry: self.geometry(&c.geometry, &link.name)?,
                local: urdf_pose(&c.origin),
            });
        }
        let mut visuals = Vec::new();
        for v in &link.visual {
            let color = match &v.material {
                Some(m) => match (&m.color, self.materials.get(m.name.as_str())) {
                    (Some(c), _) => rgb(&c.rgba.0),
                    (None, Some(c)) => *c,
                    (None, None) => DEFAULT_COLOR,
                },
                None => DEFAULT_COLOR,
            };
            if v.material.as_ref().is_some_and(|m| m.texture.is_some()) {
                warnings.push(format!(
                    "{}: link '{}': textures are not supported; the visual uses a plain colour",
                    self.path.display(),
                    link.name
                ));
            }
            visuals.push(VisualModel {
                geometry: self.geometry(&v.geometry, &link.name)?,
                local: urdf_pose(&v.origin),
                color,
            });
        }
        let i = &link.inertial;
        let mass = if i.mass.value > 0.0 {
            let o = urdf_pose(&i.origin);
            let t = o.translation.vector;
            let r = o.rotation;
            MassModel::Inertial {
                mass: i.mass.value,
                com: [t.x, t.y, t.z],
                frame: [r.i, r.j, r.k, r.w],
                inertia: [
                    i.inertia.ixx,
                    i.inertia.ixy,
                    i.inertia.ixz,
                    i.inertia.iyy,
                    i.inertia.iyz,
                    i.inertia.izz,
                ],
            }
        } else {
            if dynamic {
                warnings.push(format!(
                    "{}: link '{}' has no <inertial>; its mass is computed from its collision geometry at 1000 kg/m³",
                    self.path.display(),
                    link.name
                ));
            }
            MassModel::Density(1000.0)
        };
        Ok(ShapeModel {
            geoms,
            visuals,
            dynamic,
            mass,
            friction: 0.5,
            restitution: 0.0,
            collision_group: u32::MAX,
            collision_mask: u32::MAX,
            respondable: true,
            detectable: true,
            measurable: true,
        })
    }

    fn geometry(&self, g: &urdf_rs::Geometry, link: &str) -> Result<Geometry, LoadError> {
        Ok(match g {
            urdf_rs::Geometry::Box { size } => Geometry::Box {
                half_extents: [size.0[0] / 2.0, size.0[1] / 2.0, size.0[2] / 2.0],
            },
            urdf_rs::Geometry::Cylinder { radius, length } => Geometry::Cylinder {
                radius: *radius,
                length: *length,
            },
            urdf_rs::Geometry::Capsule { radius, length } => Geometry::Capsule {
                radius: *radius,
                length: *length,
            },
            urdf_rs::Geometry::Sphere { radius } => Geometry::Sphere { radius: *radius },
            urdf_rs::Geometry::Mesh { filename, scale } => {
                let file = resolve_mesh_path(self.files, filename, self.urdf_dir, self.package_paths).map_err(|tried| {
                    let list: Vec<String> = tried.iter().map(|p| p.display().to_string()).collect();
                    LoadError::Mesh {
                        path: self.path.to_owned(),
                        message: format!(
                            "link '{link}': mesh '{filename}' not found (tried: {}); for package:// meshes pass --package-path DIR",
                            list.join(", ")
                        ),
                    }
                })?;
                Geometry::Mesh(load_mesh(self.files, &file, scale.map_or([1.0; 3], |s| s.0))?)
            }
        })
    }
}

/// The colour of a visual without a material.
const DEFAULT_COLOR: [f32; 3] = [0.7, 0.7, 0.72];

fn rgb(rgba: &[f64; 4]) -> [f32; 3] {
    [rgba[0] as f32, rgba[1] as f32, rgba[2] as f32]
}

/// A URDF `<origin xyz rpy>`: rpy are fixed-axis roll, pitch, yaw, i.e. R = Rz(y) Ry(p) Rx(r).
fn urdf_pose(p: &urdf_rs::Pose) -> Pose {
    let [x, y, z] = p.xyz.0;
    let [r, pi, ya] = p.rpy.0;
    Pose::from_parts(Translation3::new(x, y, z), UnitQuaternion::from_euler_angles(r, pi, ya))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::files::DiskFiles;

    fn write(name: &str, text: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("gantry-urdf-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("tmp dir");
        let p = dir.join("r.urdf");
        std::fs::write(&p, text).expect("write");
        p
    }

    #[test]
    fn builds_link_joint_link_tree_with_z_axis_joints() {
        let p = write(
            "tree",
            r#"<robot name="r">
              <link name="a"><collision><geometry><box size="1 1 1"/></geometry></collision></link>
              <link name="b"/>
              <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
                <origin xyz="0 0 1" rpy="0 0 0"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="5" velocity="1"/>
                <dynamics damping="0.1"/></joint>
            </robot>"#,
        );
        let mut objects = Vec::new();
        let mut warnings = Vec::new();
        let idx = import_urdf(
            &DiskFiles,
            &p,
            &UrdfInclude::default(),
            &[],
            &mut objects,
            &mut warnings,
        )
        .expect("loads");
        let aliases: Vec<&str> = objects.iter().map(|o| o.alias.as_str()).collect();
        assert_eq!(aliases, ["r", "a", "j", "b"]);
        assert_eq!(objects[2].parent, Some(idx.links["a"]));
        assert_eq!(objects[3].parent, Some(idx.joints["j"]));
        // The joint's Z axis is the URDF axis (world +Y here).
        let z = objects[2].local.rotation * Vector3::z();
        assert!((z - Vector3::y()).norm() < 1e-12);
        // The child link frame at q = 0 is the URDF joint origin: identity rotation.
        let child_world = objects[2].local * objects[3].local;
        assert!(child_world.rotation.angle() < 1e-12);
        assert!(warnings.iter().any(|w| w.contains("<dynamics>")), "{warnings:?}");
    }

    #[test]
    fn rejects_cycles_and_two_parents() {
        let p = write(
            "cycle",
            r#"<robot name="r"><link name="a"/><link name="b"/>
              <joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>
              <joint name="j2" type="fixed"><parent link="b"/><child link="a"/></joint></robot>"#,
        );
        let err = import_urdf(
            &DiskFiles,
            &p,
            &UrdfInclude::default(),
            &[],
            &mut Vec::new(),
            &mut Vec::new(),
        )
        .expect_err("cycle");
        assert!(err.to_string().contains("cycle"), "{err}");
    }

    #[test]
    fn missing_mesh_is_an_error_naming_the_link() {
        let p = write(
            "mesh",
            r#"<robot name="r"><link name="a"><collision><geometry><mesh filename="package://nope/m.stl"/></geometry></collision></link></robot>"#,
        );
        let err = import_urdf(
            &DiskFiles,
            &p,
            &UrdfInclude::default(),
            &[],
            &mut Vec::new(),
            &mut Vec::new(),
        )
        .expect_err("missing mesh");
        let msg = err.to_string();
        assert!(msg.contains("link 'a'") && msg.contains("--package-path"), "{msg}");
    }
}
