//! Stage 2 of scene loading: the resolved scene, with no rapier types.
//!
//! Every name reference is an index, every angle is in radians, every file has been
//! read, and every default has been applied. This is what the world is built from, and
//! what tests inspect without a physics engine.

use std::path::PathBuf;
use std::sync::Arc;

use crate::math::Pose;

/// A resolved scene, ready to be inserted into a world.
#[derive(Debug, Clone)]
pub struct SceneModel {
    /// A short name for logs: the file stem, or `showroom` for the embedded scene.
    pub name: String,
    /// Folder scripts may write into and relative paths are resolved against.
    pub base_dir: PathBuf,
    /// The file the scene was read from (`sim.stringparam_scene_path_and_name`); empty
    /// for a scene built in memory.
    pub path: PathBuf,
    /// Time step, substeps and gravity.
    pub settings: SimSettings,
    /// Listener defaults from the scene's `[server]` section.
    pub server: ServerSettings,
    /// Objects in hierarchy order: a parent always comes before its children. The index
    /// of an object becomes its handle.
    pub objects: Vec<ObjectModel>,
    /// Scripts attached to objects.
    pub scripts: Vec<ScriptModel>,
    /// Dynamic loop closures: pairs of dummies (object indices) the physics holds
    /// together, as `sim.setLinkDummy` does; CoppeliaSim's grippers close their linkages
    /// this way.
    pub dummy_links: Vec<[usize; 2]>,
    /// Loop closures that hold only the two dummies' origins together, leaving their
    /// rotation free: a CoppeliaSim loop closed through a free spherical joint, which
    /// gantry imports as fixed (its 1-DoF joints have no ball joint) and frees here.
    pub ball_links: Vec<[usize; 2]>,
    /// Referenced handles (CoppeliaSim 4.7+'s `sim.setReferencedHandles`): for an object,
    /// a tag and the objects it names, all as object indices. A model's scripts find their
    /// parts this way (`sim.getReferencedHandle(self, 'ik.tip')`).
    pub referenced_handles: Vec<ReferencedHandles>,
    /// Objects' user parameters (CoppeliaSim up to 4.2's "script simulation
    /// parameters", `sim.getScriptSimulationParameter`), in file order.
    pub user_parameters: Vec<UserParameter>,
    /// The scene's IK groups (V-REP 3 / CoppeliaSim 4.0-4.2 built-in kinematics, reached
    /// with `sim.getIkGroupHandle`), in file order.
    pub ik_groups: Vec<IkGroupModel>,
    /// Named collections (`sim.getCollectionHandle`), in file order; names are unique.
    pub collections: Vec<CollectionModel>,
    /// The robots loaded from URDF files, in load order: which objects each file's links
    /// and joints became, and the file's text (ROS 2's `/robot_description`).
    pub urdf_robots: Vec<UrdfRobotModel>,
    /// Texture images, which visuals name by index ([`VisualTexture::texture`]).
    pub textures: Vec<TextureModel>,
    /// Soft problems found while loading (unknown keys, unsupported URDF elements).
    pub warnings: Vec<String>,
}

impl SceneModel {
    /// Moves every object index by `by`, as when `by` objects are put in front of this
    /// model's: parents, mimic leaders, the objects scripts are attached to and the
    /// dummies of the loop closures.
    pub fn offset_indices(&mut self, by: usize) {
        for o in &mut self.objects {
            o.parent = o.parent.map(|p| p + by);
            if let ObjectModelKind::Joint(j) = &mut o.kind
                && let Some(m) = &mut j.mimic
            {
                m.leader += by;
            }
        }
        for s in &mut self.scripts {
            s.object += by;
        }
        for i in self.dummy_links.iter_mut().chain(&mut self.ball_links).flatten() {
            *i += by;
        }
        for p in &mut self.user_parameters {
            p.object += by;
        }
        for r in &mut self.referenced_handles {
            r.object += by;
            for t in &mut r.targets {
                *t += by;
            }
        }
        for g in &mut self.ik_groups {
            for e in &mut g.elements {
                e.tip += by;
                e.target += by;
                e.base = e.base.map(|b| b + by);
            }
        }
        for c in &mut self.collections {
            for i in &mut c.items {
                i.object = i.object.map(|o| o + by);
            }
        }
        for r in &mut self.urdf_robots {
            r.base += by;
            for (i, _) in r.links.iter_mut().chain(&mut r.joints) {
                *i += by;
            }
        }
    }
}

/// The longest URDF text a scene keeps for its robot description, bytes. The whole file
/// is read and parsed anyway; this bounds what is held for the run (and sent as one
/// ROS message to every subscriber). The largest public robots (a humanoid with every
/// `<gazebo>` block) stay well under a megabyte.
pub const MAX_URDF_TEXT_BYTES: usize = 8 << 20;

/// A robot loaded from a URDF file: where its parts landed in the object list, and the
/// file itself, for consumers that want the robot as ROS describes it (the ROS 2
/// graph's `/robot_description` and link-named TF frames).
#[derive(Debug, Clone, PartialEq)]
pub struct UrdfRobotModel {
    /// Index of the model base (the dummy aliased by the robot name).
    pub base: usize,
    /// The file it was read from.
    pub path: PathBuf,
    /// The file's text as read, unchanged (before gantry's repairs of common mistakes);
    /// `None` when longer than [`MAX_URDF_TEXT_BYTES`] (a loading warning says so).
    pub text: Option<Arc<str>>,
    /// Index of each link's object and the URDF link name, by index.
    pub links: Vec<(usize, String)>,
    /// Index of each joint's object and the URDF joint name, by index.
    pub joints: Vec<(usize, String)>,
}

/// One IK group of the scene (`[[ik_group]]`): elements solved together each step
/// unless handled explicitly.
#[derive(Debug, Clone, PartialEq)]
pub struct IkGroupModel {
    /// The name `sim.getIkGroupHandle` looks up.
    pub name: String,
    /// The base/tip/target triples, in order.
    pub elements: Vec<IkElementModel>,
    /// How the Jacobian is inverted.
    pub method: IkMethodModel,
    /// Damping factor of damped least squares.
    pub damping: f64,
    /// Solver iterations per handling.
    pub max_iterations: u32,
    /// Whether only `sim.handleIkGroup` on this group solves it (else the main script does,
    /// every step).
    pub explicit: bool,
}

/// How an IK group inverts its Jacobian (`sim.ik_*_method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IkMethodModel {
    /// Pseudo-inverse (CoppeliaSim's default).
    PseudoInverse,
    /// Damped least squares.
    DampedLeastSquares,
}

/// One element of an IK group: a chain from `base` to the tip dummy, driven onto the
/// target dummy.
#[derive(Debug, Clone, PartialEq)]
pub struct IkElementModel {
    /// Index of the tip dummy.
    pub tip: usize,
    /// Index of the target dummy.
    pub target: usize,
    /// Index of the chain's base; `None`: the world.
    pub base: Option<usize>,
    /// What is constrained, as `sim.ik_*_constraint` bits: x 1, y 2, z 4, alpha-beta 8,
    /// gamma 16 (position 7, orientation 24, pose 31).
    pub constraints: u8,
}

/// A named collection (`[[collection]]`): a set of objects built from items applied in
/// order, evaluated against the tree when queried, as CoppeliaSim's collections are.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CollectionModel {
    /// The name `sim.getCollectionHandle` finds it by.
    pub name: String,
    /// The items, in order.
    pub items: Vec<CollectionItemModel>,
}

/// One item of a collection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CollectionItemModel {
    /// What the item covers.
    pub scope: CollectionScope,
    /// Index of the object it starts from; `None` only for [`CollectionScope::All`].
    pub object: Option<usize>,
    /// The item removes its objects instead of adding them.
    pub remove: bool,
    /// Leave out the object itself (a tree's base, a chain's tip).
    pub exclude_base: bool,
}

/// What a collection item covers (`sim.handle_single`, `_tree`, `_chain`, `_all`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CollectionScope {
    /// The object alone.
    Object,
    /// The object and everything below it.
    Tree,
    /// The object and its ancestors.
    Chain,
    /// Every object.
    All,
}

/// One user parameter of an object: what a model's script reads with
/// `sim.getScriptSimulationParameter(sim.handle_self, name)`. The value is text, as
/// CoppeliaSim keeps it; the function returns a number when the text is one.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UserParameter {
    /// Index of the object that holds it.
    pub object: usize,
    /// The name scripts ask for.
    pub name: String,
    /// The unit the model's dialog showed (free text, e.g. `degrees (5-360)`).
    pub unit: String,
    /// The value, as text.
    pub value: String,
}

/// One tag of an object's referenced handles.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReferencedHandles {
    /// Index of the object that holds them.
    pub object: usize,
    /// The tag, e.g. `ik.tip`.
    pub tag: String,
    /// Indices of the objects referenced, in order.
    pub targets: Vec<usize>,
}

/// Simulation settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimSettings {
    /// Simulation time step, seconds.
    pub dt: f64,
    /// Physics substeps per simulation step.
    pub substeps: u32,
    /// Run collision detection at every substep (separate rapier steps) rather than once
    /// per step with the substeps inside rapier's solver. See docs/performance.md.
    pub collisions_every_substep: bool,
    /// Velocity iterations of rapier's solver in each substep (its
    /// `num_internal_pgs_iterations`, 1 by default). An arm's motors are coupled through
    /// its mass matrix, and one pass leaves a sag under gravity that more passes remove:
    /// CoppeliaSim imports use [`COPPELIA_SOLVER_ITERATIONS`](crate::scene::COPPELIA_SOLVER_ITERATIONS).
    pub solver_iterations: u32,
    /// Gravity in the world frame, m/s².
    pub gravity: [f64; 3],
    /// The seed of the run's pseudo-random numbers: Lua's `math.random` in every
    /// script and `sim.getFloatParam(sim.floatparam_rand)`. One seed gives one
    /// sequence, so that runs repeat (Lua would otherwise seed from the clock).
    pub seed: i64,
    /// RGB colour (0..1) a vision sensor's image shows where the sensor sees nothing
    /// (CoppeliaSim's environment colour its vision sensors clear to, the "fog
    /// background"; a sensor may ask for its own, [`VisionModel::background`]). `None`
    /// shows black, as a scene that sets none always did.
    pub background: Option<[f64; 3]>,
}

impl Default for SimSettings {
    fn default() -> Self {
        // CoppeliaSim's defaults: a 50 ms simulation step with 10 physics substeps.
        Self {
            dt: 0.05,
            substeps: 10,
            collisions_every_substep: false,
            solver_iterations: 1,
            gravity: [0.0, 0.0, -9.81],
            seed: 0,
            background: None,
        }
    }
}

/// Listener defaults a scene may set (the command line overrides them).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ServerSettings {
    /// Bind address.
    pub bind: Option<String>,
    /// Text command channel port.
    pub text_port: Option<u16>,
    /// ZMQ remote API port.
    pub zmq_port: Option<u16>,
    /// HTTP viewer port.
    pub http_port: Option<u16>,
}

/// One object of the tree.
#[derive(Debug, Clone)]
pub struct ObjectModel {
    /// Alias used by `sim.getObject` paths.
    pub alias: String,
    /// Index of the parent object, `None` for a root.
    pub parent: Option<usize>,
    /// Pose relative to the parent (for a joint parent: relative to its moving frame).
    pub local: Pose,
    /// Whether `:` in paths stops at this object.
    pub model_base: bool,
    /// Extension string (`sim.getExtensionString`), empty when none: free text that
    /// plugins and task code read, such as RLBench's waypoint commands
    /// (`open_gripper()`, `ignore_collisions;linear`).
    pub extension: String,
    /// Visibility layer bits (`sim.objintparam_visibility_layer`; bit k is layer k + 1).
    /// Vision sensors and the viewer show objects on the active layers,
    /// [`VISIBLE_LAYERS`]; CoppeliaSim files keep respondable shapes and joints on
    /// hidden ones.
    pub layer: u16,
    /// What the object is.
    pub kind: ObjectModelKind,
}

/// CoppeliaSim's active layers, 1 to 8 (bits 0-7): what vision sensors and the viewer
/// show. An object on none of them is hidden.
pub const VISIBLE_LAYERS: u16 = 0x00ff;

/// The kinds of object, as in CoppeliaSim.
#[derive(Debug, Clone)]
pub enum ObjectModelKind {
    /// A collidable/visible body part.
    Shape(ShapeModel),
    /// A revolute, prismatic or fixed joint.
    Joint(JointModel),
    /// A reference frame.
    Dummy,
    /// A ray or cone proximity sensor.
    ProximitySensor(ProximityModel),
    /// A perspective or orthographic camera that renders RGB and depth images.
    VisionSensor(VisionModel),
    /// A rigid link that measures the force and torque it transmits.
    ForceSensor,
    /// A graph (time series owner).
    Graph,
    /// A viewpoint for the viewer (CoppeliaSim's camera object).
    Camera(CameraModel),
    /// A light: a frame with lighting parameters, no physics. Gantry's renderers keep
    /// their own lighting; the parameters are what `sim.getLightParameters` and the
    /// light object parameters read and write.
    Light(LightModel),
    /// An old path object (V-REP 3 to CoppeliaSim 4.2, `sim.object_path_type`): a frame
    /// and a curve through control points in it, for `sim.getPositionOnPath` and the
    /// other old-path functions.
    Path(PathModel),
}

/// A shape: collision geometry, visual geometry and physical properties.
#[derive(Debug, Clone)]
pub struct ShapeModel {
    /// Collision geometry, each part with its pose in the shape frame.
    pub geoms: Vec<GeomModel>,
    /// Visual geometry, for the viewer and vision sensors.
    pub visuals: Vec<VisualModel>,
    /// Simulated by the physics engine (otherwise static or kinematic).
    pub dynamic: bool,
    /// How mass is given.
    pub mass: MassModel,
    /// Coulomb friction coefficient.
    pub friction: f64,
    /// Restitution 0..1.
    pub restitution: f64,
    /// Collision group bits.
    pub collision_group: u32,
    /// Collision mask bits.
    pub collision_mask: u32,
    /// Takes part in contacts.
    pub respondable: bool,
    /// Seen by proximity sensors.
    pub detectable: bool,
    /// Seen by distance queries.
    pub measurable: bool,
    /// Seen by collision checks against `sim.handle_all` or a collection
    /// (`sim.objectspecialproperty_collidable`).
    pub collidable: bool,
    /// Whether this shape, as a link of a simulated mechanism (a rapier multibody),
    /// collides with the other links of that mechanism. `false` for URDF robots unless
    /// their `self_collision` is set; pairs joined directly by a joint never collide.
    pub self_collision: bool,
}

impl ShapeModel {
    /// One primitive (or mesh) both collided with and drawn in `color`, in the object's
    /// frame, with the scene format's defaults: static, respondable, 1000 kg/m³,
    /// friction 0.5, no restitution, colliding with everything.
    pub fn single(geometry: Geometry, color: [f32; 3]) -> Self {
        ShapeModel {
            geoms: vec![GeomModel {
                geometry: geometry.clone(),
                local: Pose::identity(),
            }],
            visuals: vec![VisualModel {
                geometry,
                local: Pose::identity(),
                color,
                texture: None,
            }],
            dynamic: false,
            mass: MassModel::Density(1000.0),
            friction: 0.5,
            restitution: 0.0,
            collision_group: u32::MAX,
            collision_mask: u32::MAX,
            respondable: true,
            detectable: true,
            measurable: true,
            collidable: true,
            self_collision: true,
        }
    }
}

/// One collision part of a shape.
#[derive(Debug, Clone)]
pub struct GeomModel {
    /// The primitive or mesh.
    pub geometry: Geometry,
    /// Pose of the part in the shape frame.
    pub local: Pose,
}

/// One visual part of a shape.
#[derive(Debug, Clone)]
pub struct VisualModel {
    /// The primitive or mesh.
    pub geometry: Geometry,
    /// Pose of the part in the shape frame.
    pub local: Pose,
    /// RGB, each 0..1.
    pub color: [f32; 3],
    /// The texture the part wears, if any (for the API, vision sensors and the viewer).
    pub texture: Option<VisualTexture>,
}

/// A texture image (a CoppeliaSim texture object).
#[derive(Debug, Clone, PartialEq)]
pub struct TextureModel {
    /// Its name (`sim.getTextureId` finds it by that).
    pub name: String,
    /// Width and height, pixels.
    pub resolution: [u32; 2],
    /// 4 bytes a pixel, rows from the top of the picture.
    pub rgba: Arc<Vec<u8>>,
}

/// How a visual part wears a texture.
#[derive(Debug, Clone, PartialEq)]
pub struct VisualTexture {
    /// Index into [`SceneModel::textures`].
    pub texture: usize,
    /// `sim.texturemap_*`: 0 plane, 1 cylinder, 2 sphere, 3 cube; it projects the
    /// coordinates when [`VisualTexture::coordinates`] is `None`.
    pub mapping: i64,
    /// `sim.setShapeTexture`'s option bits: 1 no interpolation, 2 decal, 4 repeat along
    /// u, 8 repeat along v.
    pub options: i64,
    /// The texture's size on the part along u and v, m (projections).
    pub scaling: [f64; 2],
    /// The texture frame in the shape frame (as CoppeliaSim keeps it).
    pub frame: Pose,
    /// Fixed coordinates: u, v per triangle corner of the part's mesh, 6 a triangle.
    pub coordinates: Option<Arc<Vec<f32>>>,
}

/// Geometry, in metres. Cylinders and capsules lie along their local Z axis.
#[derive(Debug, Clone)]
pub enum Geometry {
    /// A box given by its half extents.
    Box {
        /// Half extents along X, Y, Z.
        half_extents: [f64; 3],
    },
    /// A sphere.
    Sphere {
        /// Radius.
        radius: f64,
    },
    /// A cylinder along local Z, centred on the origin.
    Cylinder {
        /// Radius.
        radius: f64,
        /// Full length.
        length: f64,
    },
    /// A capsule along local Z; `length` is the distance between the cap centres.
    Capsule {
        /// Radius.
        radius: f64,
        /// Length of the cylindrical part.
        length: f64,
    },
    /// A triangle mesh, already scaled.
    Mesh(Arc<MeshData>),
}

/// Triangle mesh data shared between colliders, visuals and the viewer.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshData {
    /// The file it came from, for messages.
    pub source: PathBuf,
    /// Vertex positions in metres.
    pub vertices: Vec<[f32; 3]>,
    /// Triangles as vertex indices.
    pub indices: Vec<[u32; 3]>,
    /// The convex parts a dynamic body collides with, as point sets in metres (scaled like
    /// `vertices`): one per `o`/`g` section of a multi-part OBJ (a convex decomposition),
    /// as PyBullet reads it. Empty when the mesh is one part: then the hull of `vertices`.
    pub parts: Vec<Vec<[f32; 3]>>,
}

/// How a shape's mass is specified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MassModel {
    /// Uniform density in kg/m³ over the collision geometry.
    Density(f64),
    /// Total mass in kg, spread uniformly over the collision geometry.
    Mass(f64),
    /// Explicit inertial properties (from URDF).
    Inertial {
        /// Mass in kg.
        mass: f64,
        /// Centre of mass in the shape frame, metres.
        com: [f64; 3],
        /// Frame of the inertia tensor relative to the shape frame (rotation only).
        frame: [f64; 4],
        /// Inertia tensor `[ixx, ixy, ixz, iyy, iyz, izz]`, kg·m², in `frame`.
        inertia: [f64; 6],
    },
}

/// Joint types.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointType {
    /// Rotation about the local Z axis.
    Revolute,
    /// Translation along the local Z axis.
    Prismatic,
    /// No motion (a rigid link that still appears in the tree).
    Fixed,
}

/// How a joint is driven.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointMode {
    /// The position is set directly (CoppeliaSim's kinematic/passive mode).
    Kinematic,
    /// Dynamic, with a PD position controller limited by `max_force`.
    Position,
    /// Dynamic, with a velocity controller limited by `max_force`.
    Velocity,
    /// Dynamic, with no motor at all (CoppeliaSim's "motor disabled", PyBullet's velocity
    /// control with zero force): only gravity, contacts, damping, friction and limits act.
    Free,
    /// Dynamic, applying a set torque (N·m) or force (N), signed, whatever the motion:
    /// CoppeliaSim's force/torque control (`sim.jointdynctrl_force`), PyBullet's
    /// `TORQUE_CONTROL`. The value is `sim.setJointTargetForce`'s.
    Force,
}

impl JointMode {
    /// Whether the physics engine simulates the joint (every mode but kinematic).
    pub fn is_dynamic(self) -> bool {
        self != JointMode::Kinematic
    }

    /// The scene file's name of the mode.
    pub fn name(self) -> &'static str {
        match self {
            JointMode::Kinematic => "kinematic",
            JointMode::Position => "position",
            JointMode::Velocity => "velocity",
            JointMode::Free => "free",
            JointMode::Force => "force",
        }
    }
}

/// A joint that follows another (URDF `<mimic>`): `q = multiplier · q_leader + offset`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MimicModel {
    /// Index of the leading joint object.
    pub leader: usize,
    /// Ratio of the follower's motion to the leader's.
    pub multiplier: f64,
    /// Follower position when the leader is at zero, rad or m.
    pub offset: f64,
}

/// A joint.
#[derive(Debug, Clone, PartialEq)]
pub struct JointModel {
    /// Revolute, prismatic or fixed.
    pub joint_type: JointType,
    /// How it is driven.
    pub mode: JointMode,
    /// Limits `(min, max)` in rad or m; `None` for unlimited.
    pub limits: Option<(f64, f64)>,
    /// Revolute without limits, wrapped into (-pi, pi].
    pub cyclic: bool,
    /// Initial position, rad or m.
    pub initial: f64,
    /// Initial position target, rad or m.
    pub target_position: f64,
    /// Initial velocity target, rad/s or m/s.
    pub target_velocity: f64,
    /// Maximum torque (N·m) or force (N).
    pub max_force: f64,
    /// Position stiffness.
    pub kp: f64,
    /// Damping.
    pub kd: f64,
    /// Viscous joint damping (URDF `<dynamics damping>`), N·m·s/rad or N·s/m. It acts in
    /// every dynamic mode, on top of the motor, and is not limited by `max_force`.
    pub damping: f64,
    /// Coulomb joint friction (URDF `<dynamics friction>`): the largest torque (N·m) or
    /// force (N) friction can oppose motion with, in every dynamic mode.
    pub friction: f64,
    /// Largest speed of the position and velocity controllers (URDF `<limit velocity>`),
    /// rad/s or m/s; `None` for no limit.
    pub max_velocity: Option<f64>,
    /// The joint this one follows, if any.
    pub mimic: Option<MimicModel>,
}

/// Proximity sensor volumes. The sensor looks along its local +Z axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ProximityModel {
    /// A segment from `offset` to `offset + range` along +Z.
    Ray {
        /// Start of the segment, m.
        offset: f64,
        /// Length of the segment, m.
        range: f64,
    },
    /// A cone of half angle `half_angle` between the spheres of radius `offset` and
    /// `offset + range`.
    Cone {
        /// Near radius, m.
        offset: f64,
        /// Depth, m.
        range: f64,
        /// Half of the full cone angle, rad.
        half_angle: f64,
    },
    /// A rectangular pyramid frustum between `z = offset` and `z = offset + range`.
    Pyramid {
        /// Distance of the near face, m.
        offset: f64,
        /// Depth, m.
        range: f64,
        /// Full widths along X and Y of the near face, m.
        near_size: [f64; 2],
        /// Full widths along X and Y of the far face, m.
        far_size: [f64; 2],
    },
    /// A cone frustum around +Z between `z = offset` and `z = offset + range`.
    Cylinder {
        /// Distance of the near face, m.
        offset: f64,
        /// Depth, m.
        range: f64,
        /// Radius of the near face, m.
        radius: f64,
        /// Radius of the far face, m.
        radius_far: f64,
    },
    /// A fan in the XZ plane around +Z, between the radii `offset` and `offset + range`.
    Disc {
        /// Inner radius, m.
        offset: f64,
        /// Radial depth, m.
        range: f64,
        /// Half of the full opening angle, rad (up to π, a whole ring).
        half_angle: f64,
        /// Thickness along Y, m.
        thickness: f64,
    },
}

/// Largest vision-sensor image side, in pixels: the loader, `sim.setObjectInt32Param`
/// and the renderer all hold images to it. 2048 covers every camera a robot carries
/// (and CoppeliaSim's own sensors, which its GUI limits to 2048 by default too).
pub const MAX_VISION_RESOLUTION: u32 = 2048;

/// Bytes a vision sensor keeps per pixel: its RGB image (3) and its depth image (one
/// `f32`, 4).
pub const VISION_BYTES_PER_PIXEL: u64 = 7;

/// Most memory all the vision sensors of a scene may hold in RGB and depth images
/// together, bytes (1 GiB: 36 sensors of 2048 x 2048, or 500 of 640 x 480). A scene
/// or a run-time resolution change beyond it is refused with the total, rather than
/// left to fail on allocation, or to swap, at the first render. The renderer's own
/// buffers (up to three words per pixel: depth, colour and, for masks, handles) come
/// on top, for the largest sensor once per core and once per sensor drawn in bands
/// (fewer than the cores), as do simVision work images and buffers.
pub const MAX_VISION_IMAGE_BYTES: u64 = 1 << 30;

/// Image memory of one sensor of `resolution`, bytes (RGB and depth).
pub fn vision_image_bytes(resolution: [u32; 2]) -> u64 {
    u64::from(resolution[0]) * u64::from(resolution[1]) * VISION_BYTES_PER_PIXEL
}

/// How a vision sensor projects the scene onto its image (CoppeliaSim's
/// `sim.visionintparam_perspective_operation`: 1 perspective, 0 orthographic).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Projection {
    /// A pinhole camera: the view angle spans the larger image side.
    #[default]
    Perspective,
    /// Parallel rays along +Z: the ortho size spans the larger image side, and
    /// objects keep their size whatever their distance.
    Orthographic,
}

/// What a vision sensor's RGB image shows (CoppeliaSim's
/// `sim.visionintparam_render_mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RenderMode {
    /// The shapes' colours, lit (`sim.rendermode_opengl`, 0).
    #[default]
    Visible,
    /// Each pixel's colour is the handle of the shape it sees, `r + 256 g + 65536 b`
    /// (bytes), white where nothing is seen (`sim.rendermode_colorcoded`, 2): the
    /// segmentation masks PyRep and RLBench read.
    ColorCoded,
}

/// A vision sensor. It looks along its local +Z axis, image X along local -X, image
/// up along local +Y. As in CoppeliaSim, it holds both a view angle and an ortho size
/// whatever its projection, so switching the projection at run time keeps both.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VisionModel {
    /// Width and height in pixels.
    pub resolution: [u32; 2],
    /// Perspective or orthographic.
    pub projection: Projection,
    /// Field of view of a perspective sensor, rad (of the larger image side, as in
    /// CoppeliaSim).
    pub fov: f64,
    /// Extent of an orthographic sensor's view along the larger image side, m
    /// (CoppeliaSim's `sim.visionfloatparam_ortho_size`); the other side follows from
    /// the aspect ratio.
    pub ortho_size: f64,
    /// Near clipping distance along +Z, m.
    pub near: f64,
    /// Far clipping distance along +Z, m.
    pub far: f64,
    /// What the RGB image shows.
    pub render_mode: RenderMode,
    /// Skip the colour work: the RGB image stays black (CoppeliaSim's "ignore RGB
    /// info", `sim.visionintparam_rgbignored`), for depth-only sensors such as laser
    /// scanners.
    pub ignore_rgb: bool,
    /// Skip the depth image: it stays as it was (1, nothing seen, before any render)
    /// (CoppeliaSim's "ignore depth info", `sim.visionintparam_depthignored`). The
    /// z-buffer that decides what is seen is still drawn.
    pub ignore_depth: bool,
    /// Images per simulated second on the ROS 2 graph (`gantry run --ros2`): `None`
    /// takes the run's default (`--ros2-camera-rate`), 0 publishes none.
    pub ros2_rate: Option<f64>,
    /// RGB colour (0..1) the image shows where the sensor sees nothing: CoppeliaSim's
    /// null-pixel colour (`sim.createVisionSensor` option bit 7). `None` takes the
    /// scene's, [`SimSettings::background`]. The colour-coded render mode keeps white.
    pub background: Option<[f64; 3]>,
}

/// A CoppeliaSim camera: a viewpoint the viewer can look through. It looks along its
/// local +Z axis with local +Y up, as a vision sensor does; it renders nothing itself.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraModel {
    /// Perspective view angle, rad (CoppeliaSim's, of the larger side of the view).
    pub fov: f64,
}

/// The kind of a light, as CoppeliaSim's light subtypes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LightType {
    /// From a point in every direction (`sim.light_omnidirectional_subtype`, 1).
    Omnidirectional,
    /// A cone along the light's +Z axis (`sim.light_spot_subtype`, 2).
    Spot,
    /// Parallel rays along the light's +Z axis (`sim.light_directional_subtype`, 3).
    Directional,
}

impl LightType {
    /// CoppeliaSim's subtype number.
    pub fn code(self) -> i64 {
        match self {
            LightType::Omnidirectional => 1,
            LightType::Spot => 2,
            LightType::Directional => 3,
        }
    }
}

/// A light's parameters, CoppeliaSim's (colours 0..1, angles in rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightModel {
    /// Omnidirectional, spot or directional.
    pub light_type: LightType,
    /// Lit.
    pub on: bool,
    /// Diffuse RGB.
    pub diffuse: [f64; 3],
    /// Specular RGB.
    pub specular: [f64; 3],
    /// Spot exponent, 0 to 128: how fast a spot's light falls off towards its edge.
    pub spot_exponent: i32,
    /// Spot cutoff, rad: half the cone's opening, up to pi/2.
    pub spot_cutoff: f64,
    /// Constant, linear and quadratic attenuation factors.
    pub attenuation: [f64; 3],
    /// Casts shadows in POV-Ray renderings (`sim.lightintparam_pov_casts_shadows`).
    pub casts_shadows: bool,
}

impl LightModel {
    /// Most spot exponent (OpenGL's limit, which CoppeliaSim keeps).
    pub const MAX_SPOT_EXPONENT: i32 = 128;
    /// Largest spot cutoff: pi/2 as CoppeliaSim 4.1 stores it, in single precision, so
    /// that a cutoff read from a 4.1 file is kept as it is.
    pub const MAX_SPOT_CUTOFF: f64 = std::f32::consts::FRAC_PI_2 as f64;
    /// Smallest spot cutoff (CoppeliaSim's, 5 degrees).
    pub const MIN_SPOT_CUTOFF: f64 = 5.0 * std::f64::consts::PI / 180.0;

    /// A new light of this type as CoppeliaSim makes one: on, grey diffuse and
    /// specular, a 90-degree cutoff and exponent 5, constant attenuation only.
    pub fn new(light_type: LightType) -> Self {
        Self {
            light_type,
            on: true,
            diffuse: [0.5; 3],
            specular: [0.5; 3],
            spot_exponent: 5,
            spot_cutoff: Self::MAX_SPOT_CUTOFF,
            attenuation: [1.0, 0.0, 0.0],
            casts_shadows: false,
        }
    }
}

/// An old path object's curve: control points in the path's frame, each
/// `x, y, z, qx, qy, qz, qw`, and how the curve goes through them.
#[derive(Debug, Clone, PartialEq)]
pub struct PathModel {
    /// The control points, in order.
    pub ctrl_points: Vec<[f64; 7]>,
    /// The last control point links back to the first.
    pub closed: bool,
    /// 0 for the polyline through the control points, up to 1 for corners rounded by
    /// quadratic Bézier curves of that strength.
    pub smoothness: f64,
    /// Points of a rounded curve (at least 2; unused for a polyline).
    pub subdiv: usize,
}

/// A script attached to an object.
#[derive(Debug, Clone)]
pub struct ScriptModel {
    /// Index of the object the script is attached to.
    pub object: usize,
    /// The file, for messages and hot reload.
    pub path: PathBuf,
    /// Its text.
    pub source: String,
}
