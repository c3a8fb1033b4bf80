//! Objects of the scene tree and their per-kind state.

use super::octree::Octree;
use super::point_cloud::PointCloud;
use crate::math::{Pose, Vec3};
use crate::scene::{
    CameraModel, JointMode, JointModel, JointType, LightModel, ProximityModel, ShapeModel, VisionModel,
};

pub use crate::handle::Handle;

/// One object of the tree.
#[derive(Debug, Clone)]
pub struct Object {
    /// Alias used by `sim.getObject` paths.
    pub alias: String,
    /// Parent object, `None` for a root.
    pub parent: Option<Handle>,
    /// Children in hierarchy order.
    pub children: Vec<Handle>,
    /// Pose relative to the parent's frame; for a joint parent, relative to the joint's
    /// moving frame (after its rotation/translation), as in CoppeliaSim.
    pub local: Pose,
    /// Pose in the world frame, kept up to date by the world after every change.
    pub world: Pose,
    /// Whether `:` in paths stops at this object.
    pub model_base: bool,
    /// Extension string (`sim.getExtensionString`), empty when none.
    pub extension: String,
    /// What the object is, with its state.
    pub kind: ObjectKind,
}

/// The kinds of object and their state.
#[derive(Debug, Clone)]
pub enum ObjectKind {
    /// Geometry and physical properties.
    Shape(Box<ShapeModel>),
    /// A joint and its state.
    Joint(Joint),
    /// A reference frame.
    Dummy,
    /// A proximity sensor and its last result.
    ProximitySensor(ProximitySensor),
    /// A vision sensor.
    VisionSensor(VisionModel),
    /// A force sensor and its last reading.
    ForceSensor(ForceReading),
    /// A graph.
    Graph,
    /// A point cloud and its points (boxed: a cloud is much larger than the other kinds).
    PointCloud(Box<PointCloud>),
    /// An OC tree and its voxels (boxed, like point clouds).
    Octree(Box<Octree>),
    /// A camera: a viewpoint for the viewer.
    Camera(CameraModel),
    /// A light: a frame with lighting parameters and no physics (gantry's renderers
    /// keep their own lighting).
    Light(LightModel),
    /// An old path object (V-REP 3 to 4.2): a frame whose curve is kept in
    /// [`crate::sim::Sim::paths`] by its handle.
    Path,
}

impl ObjectKind {
    /// CoppeliaSim's object type number (`sim.object_shape_type`, ...).
    pub fn type_code(&self) -> i64 {
        match self {
            ObjectKind::Shape(_) => 0,
            ObjectKind::Joint(_) => 1,
            ObjectKind::Graph => 2,
            ObjectKind::Camera(_) => 3,
            ObjectKind::Dummy => 4,
            ObjectKind::ProximitySensor(_) => 5,
            ObjectKind::Path => 8,
            ObjectKind::Light(_) => 13,
            ObjectKind::VisionSensor(_) => 9,
            ObjectKind::ForceSensor(_) => 12,
            ObjectKind::Octree(_) => 15,
            ObjectKind::PointCloud(_) => 16,
        }
    }

    /// A short name for messages.
    pub fn name(&self) -> &'static str {
        match self {
            ObjectKind::Shape(_) => "shape",
            ObjectKind::Joint(_) => "joint",
            ObjectKind::Graph => "graph",
            ObjectKind::Camera(_) => "camera",
            ObjectKind::Dummy => "dummy",
            ObjectKind::ProximitySensor(_) => "proximity sensor",
            ObjectKind::VisionSensor(_) => "vision sensor",
            ObjectKind::ForceSensor(_) => "force sensor",
            ObjectKind::PointCloud(_) => "point cloud",
            ObjectKind::Octree(_) => "octree",
            ObjectKind::Light(_) => "light",
            ObjectKind::Path => "path",
        }
    }
}

/// A joint's configuration and state. Positions in rad (revolute) or m (prismatic).
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Revolute, prismatic or fixed.
    pub joint_type: JointType,
    /// How it is driven.
    pub mode: JointMode,
    /// Limits `(min, max)`; `None` when unlimited.
    pub limits: Option<(f64, f64)>,
    /// Whether the position wraps into (-pi, pi].
    pub cyclic: bool,
    /// Current position.
    pub position: f64,
    /// Current velocity (rad/s or m/s).
    pub velocity: f64,
    /// Position target (position mode).
    pub target_position: f64,
    /// Velocity target (velocity mode).
    pub target_velocity: f64,
    /// Maximum torque (N·m) or force (N) of the position and velocity controllers.
    pub max_force: f64,
    /// `sim.setJointTargetForce`'s value, signed: what a joint in force mode applies.
    /// Its magnitude is `max_force`.
    pub target_force: f64,
    /// Position stiffness.
    pub kp: f64,
    /// Damping.
    pub kd: f64,
    /// Torque/force the motor applied in the last step (estimated from its PD law).
    pub force: f64,
    /// Viscous damping, N·m·s/rad or N·s/m (URDF `<dynamics damping>`).
    pub damping: f64,
    /// Coulomb friction, N·m or N (URDF `<dynamics friction>`).
    pub friction: f64,
    /// Largest speed of the position and velocity controllers, rad/s or m/s.
    pub max_velocity: Option<f64>,
    /// The joint this one follows, if any (URDF `<mimic>`).
    pub mimic: Option<Mimic>,
    /// Position mode: where the controller servos to this step. It is the target itself
    /// unless `max_velocity` is set; then it moves towards the target at that speed at
    /// most (CoppeliaSim's motion profile in its simplest form), so a far target does not
    /// make the joint jump, and its speed is fed forward to the motor.
    pub reference: f64,
    /// Speed of `reference` over the last step, rad/s or m/s.
    pub reference_velocity: f64,
    /// A kinematic joint's motion from step to step (CoppeliaSim's motion profile for
    /// kinematic joints, `sim.setJointTargetPosition`/`setJointTargetVelocity`).
    pub motion: KinematicMotion,
    /// CoppeliaSim 4.1's IK mode (`sim.jointmode_ik`, 2): a kinematic joint that IK
    /// groups move. gantry's IK moves kinematic joints alike; the flag is kept so that
    /// `sim.getJointMode` reports the mode a 4.1 client set.
    pub ik_mode: bool,
    /// A velocity-controlled joint whose target velocity is zero holds its position with
    /// an unbounded force (`sim.jointintparam_velocity_lock`, Bullet's locked motor).
    pub velocity_lock: bool,
}

impl Joint {
    /// The joint a scene model describes, at its initial position; `leader` gives the
    /// handle of a mimic leader's object index.
    pub(crate) fn from_model(j: &JointModel, leader: impl Fn(usize) -> Handle) -> Joint {
        let mut joint = Joint {
            joint_type: j.joint_type,
            mode: j.mode,
            limits: j.limits,
            cyclic: j.cyclic,
            position: 0.0,
            velocity: 0.0,
            target_position: j.target_position,
            target_velocity: j.target_velocity,
            max_force: j.max_force,
            target_force: j.max_force,
            kp: j.kp,
            kd: j.kd,
            force: 0.0,
            damping: j.damping,
            friction: j.friction,
            max_velocity: j.max_velocity,
            mimic: j.mimic.map(|m| Mimic {
                leader: leader(m.leader),
                multiplier: m.multiplier,
                offset: m.offset,
            }),
            reference: 0.0,
            reference_velocity: 0.0,
            motion: KinematicMotion::Still,
            ik_mode: false,
            velocity_lock: false,
        };
        joint.position = joint.constrain(j.initial);
        // A speed-limited controller starts where the joint is and moves towards the
        // target from there; an unlimited one servos to it.
        joint.reference = if joint.max_velocity.is_some() {
            joint.position
        } else {
            joint.target_position
        };
        joint
    }
}

/// How a kinematic joint moves from step to step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum KinematicMotion {
    /// It stays where it was placed.
    #[default]
    Still,
    /// Towards `target_position` at `max_velocity` (else [`Joint::kinematic_speed`]),
    /// then still.
    ToTarget,
    /// At `target_velocity` (within `max_velocity`) until a limit stops it.
    AtVelocity,
}

/// A joint that follows another: `q = multiplier · q_leader + offset`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mimic {
    /// The leading joint.
    pub leader: Handle,
    /// Ratio of the follower's motion to the leader's.
    pub multiplier: f64,
    /// Follower position when the leader is at zero, rad or m.
    pub offset: f64,
}

impl Joint {
    /// The motion of the joint's moving frame relative to its fixed frame: a rotation
    /// about, or translation along, local Z by the current position.
    pub fn motion(&self) -> Pose {
        match self.joint_type {
            JointType::Revolute => Pose::rotation(Vec3::z() * self.position),
            JointType::Prismatic => Pose::translation(0.0, 0.0, self.position),
            JointType::Fixed => Pose::identity(),
        }
    }

    /// Moves the position controller's reference one step of `dt` seconds towards the
    /// target, at `max_velocity` at most. Returns whether the reference changed.
    pub fn advance_reference(&mut self, dt: f64) -> bool {
        let before = (self.reference, self.reference_velocity);
        match self.max_velocity {
            Some(v) if dt > 0.0 => {
                let step = (self.target_position - self.reference).clamp(-v * dt, v * dt);
                self.reference += step;
                self.reference_velocity = step / dt;
            }
            // Without a limit the controller servos straight to the target, with no speed
            // fed forward (a jump of the target would otherwise be an unbounded kick).
            _ => {
                self.reference = self.target_position;
                self.reference_velocity = 0.0;
            }
        }
        before != (self.reference, self.reference_velocity)
    }

    /// Largest speed of a kinematic joint's motion towards a target: its `max_velocity`,
    /// else gantry's default of 180 deg/s (rad/s) or 0.5 m/s (prismatic).
    pub fn kinematic_speed(&self) -> f64 {
        self.max_velocity.unwrap_or(match self.joint_type {
            JointType::Prismatic => 0.5,
            _ => std::f64::consts::PI,
        })
    }

    /// One step of a kinematic joint's motion: the position to place it at, or `None`
    /// when it is still. Ends the motion when the target or a limit is reached.
    pub fn kinematic_step(&mut self, dt: f64) -> Option<f64> {
        match self.motion {
            KinematicMotion::Still => None,
            KinematicMotion::ToTarget => {
                let v = self.kinematic_speed() * dt;
                let delta = if self.cyclic {
                    crate::math::wrap_angle(self.target_position - self.position)
                } else {
                    self.target_position - self.position
                };
                let step = delta.clamp(-v, v);
                if (delta - step).abs() <= 1e-12 {
                    self.motion = KinematicMotion::Still;
                    return Some(self.target_position);
                }
                Some(self.constrain(self.position + step))
            }
            KinematicMotion::AtVelocity => {
                let q = self.position + self.commanded_velocity() * dt;
                let placed = self.constrain(q);
                if !self.cyclic && placed != q {
                    // A limit stops it, as it stops CoppeliaSim's.
                    self.motion = KinematicMotion::Still;
                }
                Some(placed)
            }
        }
    }

    /// The velocity target the velocity controller uses: the set one, within the limit.
    pub fn commanded_velocity(&self) -> f64 {
        match self.max_velocity {
            Some(v) => self.target_velocity.clamp(-v, v),
            None => self.target_velocity,
        }
    }

    /// Clamps to the limits, or wraps a cyclic joint, as CoppeliaSim's `setJointPosition`.
    pub fn constrain(&self, q: f64) -> f64 {
        crate::math::constrain_joint(q, self.cyclic, self.limits)
    }
}

/// A proximity sensor's volume and last result.
#[derive(Debug, Clone, PartialEq)]
pub struct ProximitySensor {
    /// The detection volume.
    pub volume: ProximityModel,
    /// Result of the last handling; `None` until first handled (reads return -1).
    pub last: Option<Option<Detection>>,
}

/// What a proximity sensor detected. Point and normal are in the sensor frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Detection {
    /// Distance from the sensor origin to the point, m.
    pub distance: f64,
    /// Detected point, sensor frame, m.
    pub point: Vec3,
    /// Handle of the detected object.
    pub object: Handle,
    /// Unit surface normal at the point, sensor frame.
    pub normal: Vec3,
}

/// A force sensor's last reading, in the sensor frame: the force and torque that the
/// child side exerts on the parent side.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ForceReading {
    /// Whether a reading exists (the sensor joins two dynamic bodies and a step ran).
    pub valid: bool,
    /// Force, N.
    pub force: Vec3,
    /// Torque, N·m.
    pub torque: Vec3,
}
