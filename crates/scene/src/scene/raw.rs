//! Stage 1 of scene loading: serde structs that mirror the TOML file exactly.
//!
//! Nothing here resolves names, units or files; it only checks the file's syntax and
//! types. `docs/scene-format.md` documents every key. Keys this module does not know are
//! collected by [`unknown_keys`] and reported as warnings, never silently dropped.

use serde::Deserialize;
use toml::Spanned;

/// A whole scene file.
#[derive(Debug, Deserialize, Default)]
pub struct RawScene {
    /// `[simulation]`: time step, substeps, gravity.
    pub simulation: Option<RawSimulation>,
    /// `[floor]`: the ground box; absent means no floor.
    pub floor: Option<RawFloor>,
    /// `[server]`: default listener ports for this scene.
    pub server: Option<RawServer>,
    /// `[[object]]`: shapes, joints, dummies, sensors and graphs, in any order (parents
    /// are resolved by name).
    #[serde(default)]
    pub object: Vec<RawObject>,
    /// `[[robot]]`: URDF includes.
    #[serde(default)]
    pub robot: Vec<RawRobot>,
    /// `[[script]]`: scripts attached to objects by path (e.g. inside a URDF robot).
    #[serde(default)]
    pub script: Vec<RawScript>,
    /// `[[dummy_link]]`: pairs of dummies the physics holds together (loop closures).
    #[serde(default)]
    pub dummy_link: Vec<RawDummyLink>,
    /// `[[reference]]`: referenced handles (`sim.getReferencedHandles`) an object holds.
    #[serde(default)]
    pub reference: Vec<RawReference>,
    /// `[[user_parameter]]`: an object's user parameters (`sim.getScriptSimulationParameter`).
    #[serde(default)]
    pub user_parameter: Vec<RawUserParameter>,
    /// `[[ik_group]]`: IK groups (V-REP 3's built-in kinematics).
    #[serde(default)]
    pub ik_group: Vec<RawIkGroup>,
    /// `[[collection]]`: named collections (`sim.getCollectionHandle`).
    #[serde(default)]
    pub collection: Vec<RawCollection>,
}

/// `[simulation]`.
#[derive(Debug, Deserialize, Default)]
pub struct RawSimulation {
    /// Simulation time step in seconds (CoppeliaSim's default 0.05).
    pub dt: Option<f64>,
    /// Physics substeps per simulation step (CoppeliaSim's default 10).
    pub substeps: Option<u32>,
    /// Collision detection at every substep instead of once per step (default false).
    pub collisions_every_substep: Option<bool>,
    /// Solver velocity iterations per substep (default 1).
    pub solver_iterations: Option<u32>,
    /// Gravity in m/s², world frame (default `[0, 0, -9.81]`, Z up).
    pub gravity: Option<[f64; 3]>,
    /// The seed of the scripts' and the simulator's pseudo-random numbers (default 0).
    pub seed: Option<i64>,
    /// RGB colour (0..1) vision sensors show where they see nothing (default black).
    pub background: Option<[f64; 3]>,
}

/// `[floor]`.
#[derive(Debug, Deserialize, Default)]
pub struct RawFloor {
    /// Extent along X and Y in metres (default 5 x 5).
    pub size: Option<[f64; 2]>,
    /// Coulomb friction coefficient (default 1).
    pub friction: Option<f64>,
    /// RGB colour, each 0..1.
    pub color: Option<[f32; 3]>,
}

/// `[server]`.
#[derive(Debug, Deserialize, Default)]
pub struct RawServer {
    /// Address the listeners bind (default 127.0.0.1).
    pub bind: Option<String>,
    /// Text command channel port (default 6000).
    pub text_port: Option<u16>,
    /// ZMQ remote API port (default 23000).
    pub zmq_port: Option<u16>,
    /// HTTP viewer port (default 8080).
    pub http_port: Option<u16>,
}

/// One `[[object]]`. Which keys apply depends on `kind`; keys of other kinds are ignored.
#[derive(Debug, Deserialize)]
pub struct RawObject {
    /// Unique name within the file; other entries refer to the object by it. Also the
    /// default alias.
    pub name: Spanned<String>,
    /// `shape`, `joint`, `dummy`, `proximity_sensor`, `vision_sensor`, `force_sensor` or `graph`.
    pub kind: Spanned<String>,
    /// Alias shown to scripts (`sim.getObject` paths); defaults to `name`.
    pub alias: Option<String>,
    /// Name of the parent object (or `robot-name/link-name` inside a URDF robot).
    pub parent: Option<Spanned<String>>,
    /// Position relative to the parent, metres.
    pub position: Option<[f64; 3]>,
    /// Orientation relative to the parent, CoppeliaSim Euler angles in **degrees**.
    pub orientation_deg: Option<[f64; 3]>,
    /// Orientation relative to the parent as a unit quaternion `[x, y, z, w]`, instead
    /// of `orientation_deg` (exact where Euler angles are not, as at gimbal lock).
    pub quaternion: Option<[f64; 4]>,
    /// Marks the object as a model base (for `:` in paths).
    pub model_base: Option<bool>,
    /// Extension string (`sim.getExtensionString`); none by default.
    pub extension_string: Option<String>,
    /// Visibility layer bits (default 1: layer 1, shown).
    pub layer: Option<Spanned<i64>>,
    /// Lua script file attached to this object, relative to the scene file.
    pub script: Option<Spanned<String>>,

    /// Shape: `box`, `sphere`, `cylinder`, `capsule` or `mesh`.
    pub shape: Option<Spanned<String>>,
    /// Box: full extents in metres.
    pub size: Option<[f64; 3]>,
    /// Sphere, cylinder, capsule: radius in metres.
    pub radius: Option<f64>,
    /// Cylinder, capsule: length along the local Z axis in metres.
    pub length: Option<f64>,
    /// Mesh: file (STL, OBJ or DAE) relative to the scene file.
    pub mesh: Option<Spanned<String>>,
    /// Mesh: scale per axis.
    pub scale: Option<[f64; 3]>,
    /// Shape: simulated by the physics engine (default false: static).
    pub dynamic: Option<bool>,
    /// Shape: mass in kg (exclusive with density).
    pub mass: Option<f64>,
    /// Shape: density in kg/m³ (default 1000 when neither mass nor density is given).
    pub density: Option<f64>,
    /// Shape: Coulomb friction coefficient (default 0.5). Joint: Coulomb joint friction,
    /// the largest torque (N·m) or force (N) it opposes motion with (default 0).
    pub friction: Option<f64>,
    /// Shape: restitution 0..1 (default 0).
    pub restitution: Option<f64>,
    /// Shape: RGB colour, each 0..1.
    pub color: Option<[f32; 3]>,
    /// Shape: the texture its one part wears.
    pub texture: Option<RawTexture>,
    /// Shape: collision group bits (default all).
    pub collision_group: Option<u32>,
    /// Shape: collision mask bits, which groups this shape collides with (default all).
    pub collision_mask: Option<u32>,
    /// Shape: takes part in contacts (default true).
    pub respondable: Option<bool>,
    /// Shape: seen by proximity sensors (default true).
    pub detectable: Option<bool>,
    /// Shape: seen by `sim.checkDistance` (default true).
    pub measurable: Option<bool>,
    /// Shape: seen by collision checks against everything or a collection (default
    /// true).
    pub collidable: Option<bool>,
    /// Shape: collides with the other links of its own mechanism (default true).
    pub self_collision: Option<bool>,
    /// Shape: centre of mass in the shape frame, metres (with `mass` and `inertia`).
    pub center_of_mass: Option<[f64; 3]>,
    /// Shape: inertia tensor `[ixx, ixy, ixz, iyy, iyz, izz]`, kg·m² (with `mass`).
    pub inertia: Option<[f64; 6]>,
    /// Shape: frame of `inertia` in the shape frame, quaternion `[x, y, z, w]`.
    pub inertia_frame: Option<[f64; 4]>,
    /// Shape: several collision and visual parts instead of one `shape`.
    pub part: Option<Vec<RawPart>>,

    /// Joint: `revolute`, `prismatic` or `fixed`. The joint moves about/along its local Z axis.
    pub joint: Option<Spanned<String>>,
    /// Joint: `kinematic`, `position` or `velocity`.
    pub mode: Option<Spanned<String>>,
    /// Joint limits `[min, max]` in degrees (revolute) or metres (prismatic).
    pub limits: Option<[f64; 2]>,
    /// Joint: revolute joint without limits, wrapped into (-180°, 180°].
    pub cyclic: Option<bool>,
    /// Joint: initial position, degrees or metres.
    pub initial: Option<f64>,
    /// Joint: initial position target (mode `position`), degrees or metres.
    pub target_position: Option<f64>,
    /// Joint: initial velocity target (mode `velocity`), deg/s or m/s.
    pub target_velocity: Option<f64>,
    /// Joint: maximum motor torque (N·m) or force (N).
    pub max_force: Option<f64>,
    /// Joint: position-control stiffness (N·m/rad or N/m).
    pub kp: Option<f64>,
    /// Joint: position/velocity-control damping (N·m·s/rad or N·s/m).
    pub kd: Option<f64>,
    /// Joint: viscous damping in the joint itself (N·m·s/rad or N·s/m).
    pub damping: Option<f64>,
    /// Joint: largest speed of the controllers, deg/s or m/s.
    pub max_velocity: Option<f64>,
    /// Joint: the joint this one follows.
    pub mimic: Option<RawMimic>,

    /// Proximity sensor: `ray`, `cone`, `pyramid`, `cylinder` or `disc`. It looks along its
    /// local +Z axis.
    pub sensor: Option<Spanned<String>>,
    /// Proximity sensor: detection range in metres.
    pub range: Option<f64>,
    /// Proximity sensor: full cone or disc angle in degrees.
    pub angle_deg: Option<f64>,
    /// Proximity sensor: distance from the origin where the volume starts, metres.
    pub offset: Option<f64>,
    /// Pyramid proximity sensor: full widths `[x, y]` of the near face, metres.
    pub size_near: Option<[f64; 2]>,
    /// Pyramid proximity sensor: full widths `[x, y]` of the far face, metres.
    pub size_far: Option<[f64; 2]>,
    /// Cylinder proximity sensor: radius of the far face, metres (default `radius`).
    pub radius_far: Option<f64>,
    /// Disc proximity sensor: thickness along local Y, metres.
    pub thickness: Option<f64>,
    /// Vision sensor: resolution `[width, height]` in pixels.
    pub resolution: Option<[u32; 2]>,
    /// Vision sensor, camera: perspective field of view in degrees.
    pub fov_deg: Option<f64>,
    /// Vision sensor: `perspective` (default) or `orthographic`.
    pub projection: Option<Spanned<String>>,
    /// Vision sensor: extent of an orthographic view along the larger image side, m.
    pub ortho_size: Option<f64>,
    /// Vision sensor: near clipping distance in metres.
    pub near: Option<f64>,
    /// Vision sensor: far clipping distance in metres.
    pub far: Option<f64>,
    /// Vision sensor: `visible` (default) or `color_coded` (handles as colours).
    pub render_mode: Option<Spanned<String>>,
    /// Vision sensor: render no colour (default false).
    pub ignore_rgb: Option<bool>,
    /// Vision sensor: write no depth image (default false).
    pub ignore_depth: Option<bool>,
    /// Vision sensor: images per simulated second on the ROS 2 graph (default: the run's).
    pub ros2_rate: Option<f64>,
    /// Vision sensor: RGB colour (0..1) where it sees nothing (default: the scene's).
    pub background: Option<[f64; 3]>,

    /// Light: `omnidirectional`, `spot` or `directional`. It shines along its local +Z
    /// axis (spot, directional).
    pub light: Option<Spanned<String>>,
    /// Light: lit (default true).
    pub on: Option<bool>,
    /// Light: diffuse RGB, each 0..1 (default 0.5 grey).
    pub diffuse: Option<[f64; 3]>,
    /// Light: specular RGB, each 0..1 (default 0.5 grey).
    pub specular: Option<[f64; 3]>,
    /// Light: spot exponent, 0 to 128 (default 5).
    pub spot_exponent: Option<i64>,
    /// Light: spot cutoff, half the cone's opening, degrees, 5 to 90 (default 90).
    pub spot_cutoff_deg: Option<f64>,
    /// Light: constant, linear and quadratic attenuation factors (default `[1, 0, 0]`).
    pub attenuation: Option<[f64; 3]>,
    /// Light: casts shadows in POV-Ray renderings (default false).
    pub casts_shadows: Option<bool>,

    /// Path: control points `[x, y, z, qx, qy, qz, qw]` in the path's frame (metres).
    pub ctrl_points: Option<Vec<[f64; 7]>>,
    /// Path: the last control point links back to the first (default false).
    pub closed: Option<bool>,
    /// Path: 0 (default) for the polyline through the control points, up to 1 for the
    /// roundest corners.
    pub smoothness: Option<f64>,
    /// Path: points of a rounded curve (default 100).
    pub subdiv: Option<u32>,
}

/// One `[[object.part]]` of a shape: a primitive or mesh placed in the shape frame.
#[derive(Debug, Deserialize)]
pub struct RawPart {
    /// `both` (default), `collision` or `visual`.
    pub role: Option<Spanned<String>>,
    /// `box`, `sphere`, `cylinder`, `capsule` or `mesh`.
    pub shape: Option<Spanned<String>>,
    /// Box: full extents in metres.
    pub size: Option<[f64; 3]>,
    /// Sphere, cylinder, capsule: radius in metres.
    pub radius: Option<f64>,
    /// Cylinder, capsule: length along the local Z axis in metres.
    pub length: Option<f64>,
    /// Mesh: file (STL, OBJ or DAE) relative to the scene file.
    pub mesh: Option<Spanned<String>>,
    /// Mesh: scale per axis.
    pub scale: Option<[f64; 3]>,
    /// Position in the shape frame, metres.
    pub position: Option<[f64; 3]>,
    /// Orientation in the shape frame, CoppeliaSim Euler angles in degrees.
    pub orientation_deg: Option<[f64; 3]>,
    /// Orientation in the shape frame as a quaternion `[x, y, z, w]`.
    pub quaternion: Option<[f64; 4]>,
    /// RGB colour, each 0..1 (visual parts).
    pub color: Option<[f32; 3]>,
    /// The texture the part wears (visual parts).
    pub texture: Option<RawTexture>,
}

/// A part's `texture = { image = "textures/x.png", ... }`.
#[derive(Debug, Deserialize)]
pub struct RawTexture {
    /// PNG file relative to the scene file; parts naming the same file share one texture.
    pub image: Spanned<String>,
    /// The texture's name (`sim.getTextureId`); default the file's stem.
    pub name: Option<String>,
    /// `plane` (default), `cylinder`, `sphere` or `cube`.
    pub mapping: Option<Spanned<String>>,
    /// `sim.setShapeTexture` option bits (default 0).
    pub options: Option<i64>,
    /// The texture's size on the part along u and v, m (default 1, 1).
    pub scaling: Option<[f64; 2]>,
    /// The texture frame's position in the shape frame, m.
    pub position: Option<[f64; 3]>,
    /// The texture frame's orientation in the shape frame, `[x, y, z, w]`.
    pub quaternion: Option<[f64; 4]>,
    /// Fixed coordinates: a text file of `u v` lines, one per triangle corner.
    pub coordinates: Option<Spanned<String>>,
}

/// A joint's `mimic = { leader = "...", multiplier = 1, offset = 0 }`.
#[derive(Debug, Deserialize)]
pub struct RawMimic {
    /// Name of the leading joint.
    pub leader: Spanned<String>,
    /// `q = multiplier · q_leader + offset`, in rad and m (default 1).
    pub multiplier: Option<f64>,
    /// Follower position when the leader is at zero, degrees or metres (default 0).
    pub offset: Option<f64>,
}

/// One `[[dummy_link]]`.
#[derive(Debug, Deserialize)]
pub struct RawDummyLink {
    /// The two dummies, by name.
    pub dummies: [Spanned<String>; 2],
    /// Hold only the dummies' origins together, their rotation free (a loop closed
    /// through a ball joint); default false: their whole frames.
    pub free_rotation: Option<bool>,
}

/// One `[[reference]]`.
#[derive(Debug, Deserialize)]
pub struct RawReference {
    /// The object holding the references, by name.
    pub object: Spanned<String>,
    /// The tag (default empty, as in CoppeliaSim).
    pub tag: Option<String>,
    /// The objects referenced, by name, in order.
    pub objects: Vec<Spanned<String>>,
}

/// One `[[user_parameter]]`.
#[derive(Debug, Deserialize)]
pub struct RawUserParameter {
    /// The object holding it, by name.
    pub object: Spanned<String>,
    /// The name scripts ask for.
    pub name: Spanned<String>,
    /// Free text (default empty).
    pub unit: Option<String>,
    /// The value, as text.
    pub value: String,
}

/// One `[[ik_group]]`.
#[derive(Debug, Deserialize)]
pub struct RawIkGroup {
    /// The name `sim.getIkGroupHandle` finds it by.
    pub name: Spanned<String>,
    /// `pseudo_inverse` (default) or `damped_least_squares`.
    pub method: Option<Spanned<String>>,
    /// Damping factor of damped least squares (default 0.1).
    pub damping: Option<f64>,
    /// Solver iterations per handling (default 3).
    pub max_iterations: Option<u32>,
    /// Handled only by `sim.handleIkGroup` on it (default false: every step).
    pub explicit: Option<bool>,
    /// `[[ik_group.element]]`: the elements, in order.
    #[serde(default)]
    pub element: Vec<RawIkElement>,
}

/// One `[[ik_group.element]]`.
#[derive(Debug, Deserialize)]
pub struct RawIkElement {
    /// The tip dummy, by name.
    pub tip: Spanned<String>,
    /// The target dummy, by name.
    pub target: Spanned<String>,
    /// The chain's base, by name (default: the world).
    pub base: Option<Spanned<String>>,
    /// `pose` (default), `position`, `orientation`, or components joined by `+`.
    pub constraints: Option<Spanned<String>>,
}

/// One `[[collection]]`.
#[derive(Debug, Deserialize)]
pub struct RawCollection {
    /// The name `sim.getCollectionHandle` finds it by.
    pub name: Spanned<String>,
    /// `[[collection.item]]`: the items, applied in order.
    #[serde(default)]
    pub item: Vec<RawCollectionItem>,
}

/// One `[[collection.item]]`.
#[derive(Debug, Deserialize)]
pub struct RawCollectionItem {
    /// `object` (default), `tree`, `chain` or `all`.
    pub scope: Option<Spanned<String>>,
    /// The object it starts from, by name (not with `all`).
    pub object: Option<Spanned<String>>,
    /// Removes the objects instead of adding them (default false).
    pub remove: Option<bool>,
    /// Leaves out the object itself, a tree's base or a chain's tip (default false).
    pub exclude_base: Option<bool>,
}

/// One `[[robot]]`: a URDF include.
#[derive(Debug, Deserialize)]
pub struct RawRobot {
    /// URDF file, relative to the scene file.
    pub urdf: Spanned<String>,
    /// Alias of the robot's model base (default: the URDF robot name).
    pub name: Option<Spanned<String>>,
    /// Name of the parent object (default: the world).
    pub parent: Option<Spanned<String>>,
    /// Position of the robot base, metres.
    pub position: Option<[f64; 3]>,
    /// Orientation of the robot base, CoppeliaSim Euler angles in **degrees**.
    pub orientation_deg: Option<[f64; 3]>,
    /// Whether the base link is fixed to the world (default true, like PyBullet's `useFixedBase`).
    pub fixed_base: Option<bool>,
    /// Mode of every joint: `kinematic` (default), `position`, `velocity` or `free`.
    pub joint_mode: Option<Spanned<String>>,
    /// Modes of single joints by URDF joint name, overriding `joint_mode`.
    pub joint_modes: Option<toml::Table>,
    /// Whether the robot's links collide with each other (default false, as PyBullet).
    pub self_collision: Option<bool>,
    /// Maximum joint torque/force; default: the URDF `effort` limit, else 100.
    pub max_force: Option<f64>,
    /// Position-control stiffness for every joint.
    pub kp: Option<f64>,
    /// Position/velocity-control damping for every joint.
    pub kd: Option<f64>,
    /// Lua script attached to the robot's model base.
    pub script: Option<Spanned<String>>,
    /// Initial joint positions by joint name, degrees or metres.
    pub initial: Option<toml::Table>,
}

/// One `[[script]]`.
#[derive(Debug, Deserialize)]
pub struct RawScript {
    /// Object to attach to: an object's `name`, or `robot/link` for a URDF link or joint.
    pub object: Spanned<String>,
    /// Lua file, relative to the scene file.
    pub file: Spanned<String>,
}

const SCENE_KEYS: &[&str] = &[
    "simulation",
    "floor",
    "server",
    "object",
    "robot",
    "script",
    "dummy_link",
    "reference",
    "user_parameter",
    "ik_group",
    "collection",
];
const SIMULATION_KEYS: &[&str] = &[
    "dt",
    "substeps",
    "collisions_every_substep",
    "solver_iterations",
    "gravity",
    "seed",
    "background",
];
const FLOOR_KEYS: &[&str] = &["size", "friction", "color"];
const SERVER_KEYS: &[&str] = &["bind", "text_port", "zmq_port", "http_port"];
const OBJECT_KEYS: &[&str] = &[
    "name",
    "kind",
    "alias",
    "parent",
    "position",
    "orientation_deg",
    "quaternion",
    "model_base",
    "extension_string",
    "layer",
    "script",
    "shape",
    "size",
    "radius",
    "length",
    "mesh",
    "scale",
    "dynamic",
    "mass",
    "density",
    "friction",
    "restitution",
    "color",
    "texture",
    "collision_group",
    "collision_mask",
    "respondable",
    "detectable",
    "measurable",
    "collidable",
    "self_collision",
    "center_of_mass",
    "inertia",
    "inertia_frame",
    "part",
    "joint",
    "mode",
    "limits",
    "cyclic",
    "initial",
    "target_position",
    "target_velocity",
    "max_force",
    "kp",
    "kd",
    "damping",
    "max_velocity",
    "mimic",
    "sensor",
    "range",
    "angle_deg",
    "offset",
    "size_near",
    "size_far",
    "radius_far",
    "thickness",
    "resolution",
    "fov_deg",
    "projection",
    "ortho_size",
    "near",
    "far",
    "render_mode",
    "ignore_rgb",
    "ignore_depth",
    "ros2_rate",
    "background",
    "light",
    "on",
    "diffuse",
    "specular",
    "spot_exponent",
    "spot_cutoff_deg",
    "attenuation",
    "casts_shadows",
    "ctrl_points",
    "closed",
    "smoothness",
    "subdiv",
];
const ROBOT_KEYS: &[&str] = &[
    "urdf",
    "name",
    "parent",
    "position",
    "orientation_deg",
    "fixed_base",
    "joint_mode",
    "joint_modes",
    "self_collision",
    "max_force",
    "kp",
    "kd",
    "script",
    "initial",
];
const SCRIPT_KEYS: &[&str] = &["object", "file"];
const PART_KEYS: &[&str] = &[
    "role",
    "shape",
    "size",
    "radius",
    "length",
    "mesh",
    "scale",
    "position",
    "orientation_deg",
    "quaternion",
    "color",
    "texture",
];
const TEXTURE_KEYS: &[&str] = &[
    "image",
    "name",
    "mapping",
    "options",
    "scaling",
    "position",
    "quaternion",
    "coordinates",
];
const MIMIC_KEYS: &[&str] = &["leader", "multiplier", "offset"];
const DUMMY_LINK_KEYS: &[&str] = &["dummies", "free_rotation"];
const REFERENCE_KEYS: &[&str] = &["object", "tag", "objects"];
const USER_PARAMETER_KEYS: &[&str] = &["object", "name", "unit", "value"];
const IK_GROUP_KEYS: &[&str] = &["name", "method", "damping", "max_iterations", "explicit", "element"];
const IK_ELEMENT_KEYS: &[&str] = &["tip", "target", "base", "constraints"];
const COLLECTION_KEYS: &[&str] = &["name", "item"];
const COLLECTION_ITEM_KEYS: &[&str] = &["scope", "object", "remove", "exclude_base"];

/// Lists keys of the document that the scene format does not define, as
/// `"table.key"` paths with a suggestion when a known key is close.
pub fn unknown_keys(doc: &toml::Table) -> Vec<String> {
    let mut out = Vec::new();
    check_table(doc, "", SCENE_KEYS, &mut out);
    let tables: [(&str, &[&str]); 3] = [
        ("simulation", SIMULATION_KEYS),
        ("floor", FLOOR_KEYS),
        ("server", SERVER_KEYS),
    ];
    for (name, keys) in tables {
        if let Some(toml::Value::Table(t)) = doc.get(name) {
            check_table(t, name, keys, &mut out);
        }
    }
    let arrays: [(&str, &[&str]); 8] = [
        ("object", OBJECT_KEYS),
        ("robot", ROBOT_KEYS),
        ("script", SCRIPT_KEYS),
        ("dummy_link", DUMMY_LINK_KEYS),
        ("reference", REFERENCE_KEYS),
        ("user_parameter", USER_PARAMETER_KEYS),
        ("ik_group", IK_GROUP_KEYS),
        ("collection", COLLECTION_KEYS),
    ];
    for (name, keys) in arrays {
        if let Some(toml::Value::Array(items)) = doc.get(name) {
            for (i, item) in items.iter().enumerate() {
                if let toml::Value::Table(t) = item {
                    let label = match t.get("name").and_then(|v| v.as_str()) {
                        Some(n) => format!("{name}[{i}] ('{n}')"),
                        None => format!("{name}[{i}]"),
                    };
                    check_table(t, &label, keys, &mut out);
                    if let Some(toml::Value::Table(m)) = t.get("mimic") {
                        check_table(m, &format!("{label}.mimic"), MIMIC_KEYS, &mut out);
                    }
                    if let Some(toml::Value::Array(elements)) = t.get("element") {
                        for (j, e) in elements.iter().enumerate() {
                            if let toml::Value::Table(e) = e {
                                check_table(e, &format!("{label}.element[{j}]"), IK_ELEMENT_KEYS, &mut out);
                            }
                        }
                    }
                    if let Some(toml::Value::Array(items)) = t.get("item") {
                        for (j, e) in items.iter().enumerate() {
                            if let toml::Value::Table(e) = e {
                                check_table(e, &format!("{label}.item[{j}]"), COLLECTION_ITEM_KEYS, &mut out);
                            }
                        }
                    }
                    if let Some(toml::Value::Table(x)) = t.get("texture") {
                        check_table(x, &format!("{label}.texture"), TEXTURE_KEYS, &mut out);
                    }
                    if let Some(toml::Value::Array(parts)) = t.get("part") {
                        for (j, p) in parts.iter().enumerate() {
                            if let toml::Value::Table(p) = p {
                                check_table(p, &format!("{label}.part[{j}]"), PART_KEYS, &mut out);
                                if let Some(toml::Value::Table(x)) = p.get("texture") {
                                    check_table(x, &format!("{label}.part[{j}].texture"), TEXTURE_KEYS, &mut out);
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    out
}

fn check_table(t: &toml::Table, label: &str, known: &[&str], out: &mut Vec<String>) {
    for key in t.keys() {
        if known.contains(&key.as_str()) {
            continue;
        }
        let place = if label.is_empty() {
            key.clone()
        } else {
            format!("{label}.{key}")
        };
        let closest = known
            .iter()
            .filter(|k| key.len() >= 3 && k.starts_with(key.as_str()))
            .map(|k| (0, *k))
            .chain(known.iter().map(|k| (edit_distance(k, key), *k)))
            .filter(|(d, _)| *d <= 2)
            .min_by_key(|(d, _)| *d)
            .map(|(_, k)| k);
        match closest {
            Some(k) => out.push(format!("unknown key '{place}' (did you mean '{k}'?)")),
            None => out.push(format!("unknown key '{place}'")),
        }
    }
}

/// Levenshtein distance, for "did you mean" hints on short keys.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, &cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_keys_are_reported_with_hints() {
        let doc: toml::Table = toml::from_str(
            "[simulation]\ndt = 0.05\nsubstep = 3\n[[object]]\nname = 'a'\nkind = 'dummy'\ncolour = [1,0,0]\nwhatever = 1\n",
        )
        .expect("valid toml");
        let w = unknown_keys(&doc);
        assert_eq!(
            w,
            vec![
                "unknown key 'simulation.substep' (did you mean 'substeps'?)".to_string(),
                "unknown key 'object[0] ('a').colour' (did you mean 'color'?)".to_string(),
                "unknown key 'object[0] ('a').whatever'".to_string(),
            ]
        );
    }
}
