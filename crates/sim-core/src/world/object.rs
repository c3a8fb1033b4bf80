//! Objects of the scene tree and their per-kind state.

use crate::math::{Pose, Vec3};
use crate::scene::{JointMode, JointType, ProximityModel, ShapeModel, VisionModel};

/// An object handle: CoppeliaSim's integer handle, stable for the scene's life.
pub type Handle = i64;

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
}

impl ObjectKind {
    /// CoppeliaSim's object type number (`sim.object_shape_type`, ...).
    pub fn type_code(&self) -> i64 {
        match self {
            ObjectKind::Shape(_) => 0,
            ObjectKind::Joint(_) => 1,
            ObjectKind::Graph => 2,
            ObjectKind::Dummy => 4,
            ObjectKind::ProximitySensor(_) => 5,
            ObjectKind::VisionSensor(_) => 9,
            ObjectKind::ForceSensor(_) => 12,
        }
    }

    /// A short name for messages.
    pub fn name(&self) -> &'static str {
        match self {
            ObjectKind::Shape(_) => "shape",
            ObjectKind::Joint(_) => "joint",
            ObjectKind::Graph => "graph",
            ObjectKind::Dummy => "dummy",
            ObjectKind::ProximitySensor(_) => "proximity sensor",
            ObjectKind::VisionSensor(_) => "vision sensor",
            ObjectKind::ForceSensor(_) => "force sensor",
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
    /// Maximum torque (N·m) or force (N).
    pub max_force: f64,
    /// Position stiffness.
    pub kp: f64,
    /// Damping.
    pub kd: f64,
    /// Torque/force the motor applied in the last step (estimated from its PD law).
    pub force: f64,
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

    /// Clamps to the limits, or wraps a cyclic joint, as CoppeliaSim's `setJointPosition`.
    pub fn constrain(&self, q: f64) -> f64 {
        if self.cyclic {
            crate::math::wrap_angle(q)
        } else if let Some((lo, hi)) = self.limits {
            q.clamp(lo, hi)
        } else {
            q
        }
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
