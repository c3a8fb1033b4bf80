//! Joints: type, limits, position, mode and the dynamic motor settings.
//!
//! Angles are radians for revolute joints, lengths metres for prismatic ones. Files
//! before 4.4 have no `Dcm`: their dynamic control mode comes from `Va9` bits (4 motor,
//! 5 control loop, 7 spring), the way CoppeliaSim converts them.

use crate::chunk::{At, Chunk};
use crate::error::ReadError;
use crate::field::{Fields, is_double};
use crate::pose::Pose;

/// What kind of joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointType {
    /// Rotation about the joint's z axis.
    Revolute,
    /// Translation along the joint's z axis.
    Prismatic,
    /// Free rotation about a point (3 DOF).
    Spherical,
    /// A value this reader does not know.
    Other(i32),
}

/// How the joint is driven (`Jmd`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointMode {
    /// Passive or kinematic: the position is set, not simulated.
    Passive,
    /// Deprecated motion mode.
    Motion,
    /// Deprecated inverse-kinematics mode.
    InverseKinematics,
    /// Follows a master joint (see [`Joint::dependency`]).
    Dependent,
    /// Simulated by the physics engine (see [`Joint::dynamic_control`]).
    Dynamic,
    /// Deprecated hybrid mode (IK-driven, dynamically enacted).
    Hybrid,
    /// A value this reader does not know.
    Other(i32),
}

/// The motor of a dynamic joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DynamicControl {
    /// No motor.
    Free,
    /// Constant force or torque.
    Force,
    /// Velocity target under a force limit.
    Velocity,
    /// Position target through the engine's PID, under velocity and force limits.
    Position,
    /// Spring-damper towards the target position.
    Spring,
    /// A script callback computes the command.
    Callback,
    /// A value this reader does not know.
    Other(i32),
}

/// A dependent joint's relation: `position = master * multiplier + offset`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointDependency {
    /// Handle of the master joint.
    pub master: i32,
    /// Multiplier.
    pub multiplier: f64,
    /// Offset, rad or m.
    pub offset: f64,
}

/// A joint object's own part.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Revolute, prismatic or spherical.
    pub joint_type: JointType,
    /// Lower limit, rad or m.
    pub min: f64,
    /// Range from the lower limit, rad or m.
    pub range: f64,
    /// Position, rad or m.
    pub position: f64,
    /// A revolute joint without limits.
    pub cyclic: bool,
    /// How the joint is driven.
    pub mode: JointMode,
    /// The motor, meaningful for dynamic joints.
    pub dynamic_control: DynamicControl,
    /// Target velocity, rad/s or m/s.
    pub target_velocity: f64,
    /// Maximum force (N) or torque (N·m).
    pub max_force: f64,
    /// Target position, rad or m.
    pub target_position: f64,
    /// The master joint relation, when one is set (used in dependent mode).
    pub dependency: Option<JointDependency>,
    /// Maximum velocity of the motion profile, rad/s or m/s, when stored.
    pub max_velocity: Option<f64>,
    /// A spherical joint's rotation (`Jst`/`_st`, `[w, x, y, z]`).
    pub spherical_rotation: [f64; 4],
}

impl Joint {
    /// The joint's own motion at its current position: what lies between the joint's
    /// frame and the frame its children hang from. A rotation of [`Joint::position`]
    /// about z (revolute), a translation of it along z (prismatic), or the stored
    /// rotation (spherical). Compose it after the joint's pose to place its children.
    pub fn intrinsic_pose(&self) -> Pose {
        match self.joint_type {
            JointType::Revolute => {
                let h = self.position / 2.0;
                Pose::new([h.cos(), 0.0, 0.0, h.sin()], [0.0; 3])
            }
            JointType::Prismatic => Pose::new([1.0, 0.0, 0.0, 0.0], [0.0, 0.0, self.position]),
            JointType::Spherical => Pose::new(self.spherical_rotation, [0.0; 3]),
            JointType::Other(_) => Pose::IDENTITY,
        }
    }
}

/// Reads a joint's type-specific chunks.
pub fn read(chunks: &[Chunk], at: &At) -> Result<Joint, ReadError> {
    let mut j = Joint {
        joint_type: JointType::Revolute,
        min: 0.0,
        range: 0.0,
        position: 0.0,
        cyclic: false,
        mode: JointMode::Passive,
        dynamic_control: DynamicControl::Free,
        target_velocity: 0.0,
        max_force: 0.0,
        target_position: 0.0,
        dependency: None,
        max_velocity: None,
        spherical_rotation: [1.0, 0.0, 0.0, 0.0],
    };
    let mut dcm = None;
    let mut va9 = 0u8;
    for c in chunks {
        let mut f = Fields::new(c, at);
        let double = is_double(c.tag);
        match &c.tag {
            b"Jtt" => {
                j.joint_type = match f.i32()? {
                    10 => JointType::Revolute,
                    11 => JointType::Prismatic,
                    12 => JointType::Spherical,
                    other => JointType::Other(other),
                }
            }
            b"Pmr" | b"_mr" => [j.min, j.range] = f.reals(double)?,
            b"Prt" | b"_rt" => [j.position] = f.reals(double)?,
            b"Va9" => {
                va9 = f.u8()?;
                j.cyclic = va9 & 0x01 != 0;
            }
            b"Jmd" => {
                j.mode = match f.i32()? {
                    0 => JointMode::Passive,
                    1 => JointMode::Motion,
                    2 => JointMode::InverseKinematics,
                    3 | 4 => JointMode::Dependent,
                    5 => JointMode::Dynamic,
                    32 => JointMode::Hybrid,
                    other => JointMode::Other(other),
                }
            }
            b"Dcm" => dcm = Some(f.i32()?),
            b"Dmp" | b"_mp" => {
                [j.target_velocity, j.max_force] = f.reals(double)?;
                // The f32 variant could store the pair with opposite signs; CoppeliaSim
                // keeps the force's sign with the velocity's.
                if !double && j.target_velocity * j.max_force < 0.0 {
                    j.max_force = -j.max_force;
                }
            }
            b"Dtp" | b"_tp" => [j.target_position] = f.reals(double)?,
            b"Jdt" | b"_dt" => {
                let master = f.i32()?;
                let [multiplier, offset] = f.reals(double)?;
                j.dependency = (master >= 0).then_some(JointDependency {
                    master,
                    multiplier,
                    offset,
                });
            }
            b"Jst" | b"_st" => j.spherical_rotation = f.reals(double)?,
            b"_uc" => j.max_velocity = Some(f.f64()?),
            // Before 4.4: the maximum velocity of dynamic joints.
            b"Ulv" if j.max_velocity.is_none() => j.max_velocity = Some(f.f32()?),
            _ => {}
        }
    }
    j.dynamic_control = match dcm {
        Some(0) => DynamicControl::Free,
        Some(1) => DynamicControl::Force,
        Some(4) => DynamicControl::Velocity,
        // 9 and 13 are the older position and spring modes that also allowed a callback.
        Some(8 | 9) => DynamicControl::Position,
        Some(12 | 13) => DynamicControl::Spring,
        Some(16) => DynamicControl::Callback,
        Some(other) => DynamicControl::Other(other),
        None => {
            let (motor, control, spring) = (va9 & 0x10 != 0, va9 & 0x20 != 0, va9 & 0x80 != 0);
            match (motor, control, spring) {
                (false, _, _) => DynamicControl::Free,
                (true, false, _) => DynamicControl::Velocity,
                (true, true, false) => DynamicControl::Position,
                (true, true, true) => DynamicControl::Spring,
            }
        }
    };
    Ok(j)
}
