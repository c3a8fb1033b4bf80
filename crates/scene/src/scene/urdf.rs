//! URDF import: a robot becomes objects of the tree, as CoppeliaSim's importer builds it.
//!
//! - a model base (a dummy aliased by the robot name) at the include pose;
//! - each link a shape aliased by the link name, whose frame is the URDF link frame;
//! - each joint an object aliased by the joint name, between its parent and child link,
//!   oriented so that its local Z axis is the URDF axis (gantry joints move about/along Z).
//!
//! Honoured: `revolute`, `continuous`, `prismatic` and `fixed` joints with `<limit lower
//! upper effort velocity>` (effort is the motor's maximum force, velocity the largest speed
//! of the position and velocity controllers); `<dynamics damping friction>` (viscous
//! damping and Coulomb friction on the joint); `<mimic joint multiplier offset>` (the joint
//! follows its leader); `<inertial>`; `<visual>` and `<collision>` with box, cylinder,
//! sphere, capsule and STL/OBJ/DAE meshes (with scale; a multi-part OBJ is a convex
//! decomposition, see `world::physics`); robot-level and inline materials.
//!
//! Approximated or ignored, each said once per file in one warning that names every
//! element concerned: `floating` and `planar` joints (imported as fixed: gantry joints have
//! one degree of freedom), `<safety_controller>`, `<calibration>`, `<transmission>`,
//! `<gazebo>`, textures and any other top-level element. Nothing is dropped silently.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use nalgebra::{Translation3, UnitQuaternion, Vector3};

use super::error::LoadError;
use super::files::Files;
use super::mesh::{load_mesh, resolve_mesh_path};
use super::model::{
    GeomModel, Geometry, JointMode, JointModel, JointType, MAX_URDF_TEXT_BYTES, MassModel, MimicModel, ObjectModel,
    ObjectModelKind, ShapeModel, UrdfRobotModel, VisualModel,
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
    /// Modes of single joints by URDF joint name, overriding `joint_mode`.
    pub joint_modes: HashMap<String, JointMode>,
    /// Whether the robot's links collide with each other (parent-child pairs never do).
    pub self_collision: bool,
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
            joint_modes: HashMap::new(),
            self_collision: false,
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
    /// The file read.
    pub path: PathBuf,
    /// Its text as read, unchanged; `None` when over [`MAX_URDF_TEXT_BYTES`].
    pub text: Option<Arc<str>>,
}

impl UrdfIndex {
    /// The robot as the scene model keeps it, links and joints in object order.
    pub fn robot_model(&self) -> UrdfRobotModel {
        let sorted = |m: &HashMap<String, usize>| {
            let mut v: Vec<(usize, String)> = m.iter().map(|(name, &i)| (i, name.clone())).collect();
            v.sort_unstable();
            v
        };
        UrdfRobotModel {
            base: self.base,
            path: self.path.clone(),
            text: self.text.clone(),
            links: sorted(&self.links),
            joints: sorted(&self.joints),
        }
    }
}

/// Reads a URDF file and appends its objects to `objects`.
///
/// # Errors
/// Malformed XML ([`LoadError::Syntax`], with line and column), a joint cycle, a link
/// with two parents, two links or two joints with one name, an unknown link
/// ([`LoadError::Invalid`] at the element), a missing mesh, a `<mimic>` naming a missing
/// joint or forming a cycle.
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
    // Kept as read: ROS consumers of the description parse it themselves.
    let original: Option<Arc<str>> = (text.len() <= MAX_URDF_TEXT_BYTES).then(|| Arc::from(text.as_str()));
    if original.is_none() {
        warnings.push(format!(
            "{}: the file is larger than {} MiB, so its text is not kept (no ROS 2 /robot_description for it)",
            path.display(),
            MAX_URDF_TEXT_BYTES >> 20
        ));
    }
    let (text, repairs) = super::urdf_fixups::repair(&text);
    warnings.extend(repairs.into_iter().map(|r| format!("{}: {r}", path.display())));
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
    top_level_warnings(path, &text, warnings);
    // Elements that are read but not acted on, by element, with the joints carrying them,
    // so each is reported once per file rather than once per joint.
    let mut ignored: Vec<(&str, &str, Vec<&str>)> = vec![
        (
            "floating joints",
            "imported as fixed: gantry joints have one degree of freedom (use `fixed_base = false` for a free-floating base)",
            Vec::new(),
        ),
        (
            "planar joints",
            "imported as fixed: gantry joints have one degree of freedom",
            Vec::new(),
        ),
        (
            "<safety_controller>",
            "ignored: the <limit> range is enforced instead",
            Vec::new(),
        ),
        (
            "<calibration>",
            "ignored: joints start at `initial` (default 0)",
            Vec::new(),
        ),
    ];
    for j in &robot.joints {
        let mut note = |k: usize| ignored[k].2.push(j.name.as_str());
        match j.joint_type {
            urdf_rs::JointType::Floating => note(0),
            urdf_rs::JointType::Planar => note(1),
            _ => {}
        }
        if j.safety_controller.is_some() {
            note(2);
        }
        if j.calibration.is_some() {
            note(3);
        }
    }
    for (what, fate, joints) in &ignored {
        if !joints.is_empty() {
            warnings.push(format!("{}: {what} ({}): {fate}", path.display(), joints.join(", ")));
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
        self_collision: include.self_collision,
    };

    let base_alias = include.name.clone().unwrap_or_else(|| robot.name.clone());
    let base = objects.len();
    objects.push(ObjectModel {
        alias: base_alias,
        parent: include.parent,
        local: include.pose,
        model_base: true,
        extension: String::new(),
        layer: 1,
        kind: ObjectModelKind::Dummy,
    });
    let mut index = UrdfIndex {
        base,
        links: HashMap::new(),
        joints: HashMap::new(),
        path: path.to_owned(),
        text: original,
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
            extension: String::new(),
            layer: 1,
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
                // Floating, planar and urdf-rs's spherical: reported above, once per file.
                _ => (JointType::Fixed, None, false),
            };
            if let Some((lo, hi)) = limits
                && lo > hi
            {
                return Err(urdf_err(format!(
                    "joint '{}' has lower limit {lo} above upper limit {hi}",
                    j.name
                )));
            }
            let (damping, friction) = j.dynamics.as_ref().map_or((0.0, 0.0), |d| (d.damping, d.friction));
            if !(damping.is_finite() && damping >= 0.0 && friction.is_finite() && friction >= 0.0) {
                return Err(at(
                    "joint",
                    &j.name,
                    0,
                    format!(
                        "joint '{}': <dynamics damping=\"{damping}\" friction=\"{friction}\"> must both be finite and >= 0",
                        j.name
                    ),
                ));
            }
            let max_velocity =
                (joint_type != JointType::Fixed && j.limit.velocity.is_finite() && j.limit.velocity > 0.0)
                    .then_some(j.limit.velocity);
            let initial = match include.initial.get(&j.name) {
                Some(v) if joint_type == JointType::Revolute => v.to_radians(),
                Some(v) => *v,
                None => 0.0,
            };
            let mode = if joint_type == JointType::Fixed {
                JointMode::Kinematic
            } else {
                include.joint_modes.get(&j.name).copied().unwrap_or(include.joint_mode)
            };
            let effort = if j.limit.effort > 0.0 { j.limit.effort } else { 100.0 };
            let joint_obj = objects.len();
            objects.push(ObjectModel {
                alias: j.name.clone(),
                parent: Some(link_obj),
                local: origin * UnitQuaternion::from(align),
                model_base: false,
                extension: String::new(),
                layer: 1,
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
                    damping,
                    friction,
                    max_velocity,
                    // Resolved below, once every joint has its object.
                    mimic: None,
                }),
            });
            index.joints.insert(j.name.clone(), joint_obj);
            let child = link_ids[j.child.link.as_str()];
            // The child link frame equals the joint frame at q = 0, i.e. the joint object
            // frame without the axis alignment.
            let child_local = Pose::from_parts(Translation3::identity(), align.inverse());
            let child_dynamic = match mode {
                JointMode::Kinematic => joint_type == JointType::Fixed && dynamic,
                JointMode::Position | JointMode::Velocity | JointMode::Free | JointMode::Force => true,
            };
            stack.push((child, joint_obj, child_local, child_dynamic));
        }
    }
    resolve_mimics(path, &robot, &index, objects, &at, warnings)?;
    Ok(index)
}

/// Links each `<mimic>` follower to its leader's object. A follower starts where its
/// leader's initial position puts it.
fn resolve_mimics(
    path: &Path,
    robot: &urdf_rs::Robot,
    index: &UrdfIndex,
    objects: &mut [ObjectModel],
    at: &dyn Fn(&str, &str, usize, String) -> LoadError,
    warnings: &mut Vec<String>,
) -> Result<(), LoadError> {
    let moving = |o: &ObjectModel| matches!(&o.kind, ObjectModelKind::Joint(m) if m.joint_type != JointType::Fixed);
    // Vendor files (TALOS's grippers, for one) carry `<mimic>` on joints they later
    // declared `fixed`; there is nothing to couple, so the mimic is dropped, as PyBullet
    // and Pinocchio do, and said once per file.
    let mut inert: Vec<&str> = Vec::new();
    for j in &robot.joints {
        let Some(m) = &j.mimic else { continue };
        let bad = |why: String| {
            Err(at(
                "joint",
                &j.name,
                0,
                format!("joint '{}': <mimic joint=\"{}\">: {why}", j.name, m.joint),
            ))
        };
        let Some(&leader) = index.joints.get(&m.joint) else {
            return bad("no joint has that name".into());
        };
        let follower = index.joints[&j.name];
        if !moving(&objects[leader]) || !moving(&objects[follower]) {
            inert.push(&j.name);
            continue;
        }
        // A chain of mimics is fine (each follows its own leader), a loop is not.
        let mut cur = &m.joint;
        let mut hops = 0;
        while let Some(next) = robot
            .joints
            .iter()
            .find(|k| &k.name == cur)
            .and_then(|k| k.mimic.as_ref())
        {
            cur = &next.joint;
            hops += 1;
            if cur == &j.name || hops > robot.joints.len() {
                return bad("the mimic joints form a cycle".into());
            }
        }
        let multiplier = m.multiplier.unwrap_or(1.0);
        let offset = m.offset.unwrap_or(0.0);
        if !(multiplier.is_finite() && offset.is_finite()) {
            return bad("multiplier and offset must be finite".into());
        }
        let ObjectModelKind::Joint(lead) = &objects[leader].kind else {
            unreachable!("checked above that the leader is a joint")
        };
        let start = multiplier * lead.initial + offset;
        if let ObjectModelKind::Joint(f) = &mut objects[follower].kind {
            f.mimic = Some(MimicModel {
                leader,
                multiplier,
                offset,
            });
            f.initial = start;
            f.target_position = start;
        }
    }
    if !inert.is_empty() {
        warnings.push(format!(
            "{}: <mimic> on joints that cannot move or whose leader cannot ({}): ignored",
            path.display(),
            inert.join(", ")
        ));
    }
    Ok(())
}

/// One warning per kind of top-level element that gantry does not act on: transmissions,
/// Gazebo extensions and anything else that is not a link, joint or material.
fn top_level_warnings(path: &Path, text: &str, warnings: &mut Vec<String>) {
    let Ok(doc) = roxmltree::Document::parse_with_options(text, super::urdf_fixups::xml_options()) else {
        return;
    };
    let mut counts: Vec<(String, usize)> = Vec::new();
    for n in doc.root_element().children().filter(roxmltree::Node::is_element) {
        let name = n.tag_name().name();
        if matches!(name, "link" | "joint" | "material") {
            continue;
        }
        match counts.iter_mut().find(|(t, _)| t == name) {
            Some((_, c)) => *c += 1,
            None => counts.push((name.to_owned(), 1)),
        }
    }
    for (tag, count) in counts {
        let fate = match tag.as_str() {
            "transmission" => {
                "ignored: gantry drives joints with its own motors (`joint_mode`, `kp`, `kd`, `max_force`)"
            }
            "gazebo" => "ignored: Gazebo plugins, materials and physics settings do not apply to gantry",
            _ => "ignored: not part of the URDF elements gantry reads (link, joint, material)",
        };
        warnings.push(format!("{}: {count} <{tag}> element(s) {fate}", path.display()));
    }
}

/// The error for a file urdf-rs cannot read. urdf-rs does not say where the problem is,
/// so a well-formedness error is located with roxmltree (line and column); a well-formed
/// file with a wrong structure (a missing attribute, a bad number) keeps urdf-rs's text.
fn malformed(path: &Path, text: &str, reason: &str) -> LoadError {
    match roxmltree::Document::parse_with_options(text, super::urdf_fixups::xml_options()) {
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
/// Line and column (1-based) of the `occurrence`-th (0-based) `<tag name="name">` element
/// below `<robot>`, for errors about one link or joint. Only used on error paths, so the
/// file is parsed again here rather than carrying positions through urdf-rs.
fn element_position(text: &str, tag: &str, name: &str, occurrence: usize) -> Option<(usize, usize)> {
    let doc = roxmltree::Document::parse_with_options(text, super::urdf_fixups::xml_options()).ok()?;
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
    self_collision: bool,
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
                texture: None,
            });
        }
        let i = &link.inertial;
        // Upper triangle, row by row: ixx, ixy, ixz, iyy, iyz, izz (kg·m²).
        let tensor = [
            i.inertia.ixx,
            i.inertia.ixy,
            i.inertia.ixz,
            i.inertia.iyy,
            i.inertia.iyz,
            i.inertia.izz,
        ];
        if !(i.mass.value.is_finite() && i.mass.value >= 0.0 && tensor.iter().all(|v| v.is_finite())) {
            return Err(LoadError::Urdf {
                path: self.path.to_owned(),
                message: format!(
                    "link '{}': <inertial> mass must be finite and >= 0 and its inertia finite",
                    link.name
                ),
            });
        }
        // A massless link with a rotational inertia (Franka's flange in pybullet_data) is
        // kept as written, as PyBullet and Pinocchio do: only a link with neither is given
        // a mass from its geometry.
        let mass = if i.mass.value > 0.0 || tensor.iter().any(|v| *v != 0.0) {
            let o = urdf_pose(&i.origin);
            let t = o.translation.vector;
            let r = o.rotation;
            MassModel::Inertial {
                mass: i.mass.value,
                com: [t.x, t.y, t.z],
                frame: [r.i, r.j, r.k, r.w],
                inertia: tensor,
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
            collidable: true,
            self_collision: self.self_collision,
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

    /// Imports the URDF at `p` with default options: its index, objects and warnings.
    fn import(p: &Path) -> Result<(UrdfIndex, Vec<ObjectModel>, Vec<String>), LoadError> {
        let (mut objects, mut warnings) = (Vec::new(), Vec::new());
        let idx = import_urdf(&DiskFiles, p, &UrdfInclude::default(), &[], &mut objects, &mut warnings)?;
        Ok((idx, objects, warnings))
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
        let (idx, objects, warnings) = import(&p).expect("loads");
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
        let ObjectModelKind::Joint(j) = &objects[2].kind else {
            panic!("joint expected")
        };
        assert_eq!((j.damping, j.friction, j.max_velocity), (0.1, 0.0, Some(1.0)));
        assert!(warnings.is_empty(), "{warnings:?}");
    }

    #[test]
    fn keeps_the_text_as_read_up_to_the_limit() {
        let text = r#"<robot name="r"><link name="a"/><link name="b"/>
              <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint></robot>"#;
        let p = write("text", text);
        let (idx, _, _) = import(&p).expect("loads");
        let robot = idx.robot_model();
        assert_eq!(robot.text.as_deref(), Some(text));
        assert_eq!(robot.links, [(1, "a".to_owned()), (3, "b".to_owned())]);
        assert_eq!(robot.joints, [(2, "j".to_owned())]);
        // A file past the limit still loads; only its text is not kept, and it is said.
        let padding = "x".repeat(MAX_URDF_TEXT_BYTES);
        let p = write(
            "big",
            &text.replace("<link name=\"b\"/>", &format!("<link name=\"b\"/><!--{padding}-->")),
        );
        let (idx, _, warnings) = import(&p).expect("loads");
        let _ = std::fs::remove_file(&p);
        assert_eq!(idx.text, None);
        assert!(warnings.iter().any(|w| w.contains("not kept")), "{warnings:?}");
    }

    #[test]
    fn rejects_cycles_and_two_parents() {
        let p = write(
            "cycle",
            r#"<robot name="r"><link name="a"/><link name="b"/>
              <joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>
              <joint name="j2" type="fixed"><parent link="b"/><child link="a"/></joint></robot>"#,
        );
        let err = import(&p).map(|_| ()).expect_err("cycle");
        assert!(err.to_string().contains("cycle"), "{err}");
    }

    #[test]
    fn missing_mesh_is_an_error_naming_the_link() {
        let p = write(
            "mesh",
            r#"<robot name="r"><link name="a"><collision><geometry><mesh filename="package://nope/m.stl"/></geometry></collision></link></robot>"#,
        );
        let err = import(&p).map(|_| ()).expect_err("missing mesh");
        let msg = err.to_string();
        assert!(msg.contains("link 'a'") && msg.contains("--package-path"), "{msg}");
    }
}
