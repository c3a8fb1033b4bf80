//! `sim.createJoint`: a revolute or prismatic joint made at run time, with CoppeliaSim's
//! argument list, at the world origin as a root. The scene-building calls an editor, a
//! Lua script or a remote client make to put a robot together: the joint's children
//! are attached with `sim.setObjectParent`.
//!
//! What CoppeliaSim leaves to the joint's dialog gets CoppeliaSim's defaults for a new
//! joint: a revolute joint is cyclic (bit 0 of `options`) or limited to -180..+180
//! degrees, a prismatic one to -0.05..+0.05 m; the motor's largest torque is 2.5 N·m
//! (force, 50 N); a dynamic joint is velocity-controlled with a target velocity of 0,
//! which is what a wheel's script then sets. Every value can be changed afterwards
//! (`sim.setJointInterval`, `sim.setJointTargetForce`, `sim.setObjectInt32Param`, ...).

use std::f64::consts::PI;

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::math::Pose;
use crate::scene::{DEFAULT_KD, DEFAULT_KP, DEFAULT_VELOCITY_KD, JointMode, JointModel, JointType};
use crate::world::World;

/// The joint creation function.
pub const FUNCTIONS: &[ApiFunction] = &[ApiFunction {
    name: "createJoint",
    call: ApiFn::World(create_joint),
    cost: Cost::Quick,
}];

/// `sim.joint_revolute_subtype`, `prismatic`, `spherical`.
const REVOLUTE: i64 = 10;
const PRISMATIC: i64 = 11;
const SPHERICAL: i64 = 12;

/// A new revolute joint's largest motor torque, N·m, and a prismatic one's force, N.
const NEW_JOINT_TORQUE: f64 = 2.5;
const NEW_JOINT_FORCE: f64 = 50.0;
/// A new prismatic joint's half travel, m.
const NEW_PRISMATIC_HALF_RANGE: f64 = 0.05;

/// `sim.createJoint(jointType, jointMode, options=0, sizes=nil)` → handle.
///
/// `jointType`: `sim.joint_revolute_subtype` (10) or `sim.joint_prismatic_subtype`
/// (11); spherical joints (12) are refused, gantry has none. `jointMode`:
/// `sim.jointmode_kinematic` (0), CoppeliaSim 4.1's `sim.jointmode_ik` (2, kinematic
/// and moved by IK groups) or `sim.jointmode_dynamic` (5); a dependent joint (4) is
/// refused (gantry's are URDF `<mimic>` followers). `options` bit 0: cyclic (revolute
/// only). `sizes`: the length and diameter CoppeliaSim draws the joint with (m), checked
/// and otherwise unused.
fn create_joint(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let joint_type = match a.int(0)? {
        REVOLUTE => JointType::Revolute,
        PRISMATIC => JointType::Prismatic,
        SPHERICAL => {
            return Err(SimError::refused(
                "spherical joints are not supported: gantry's joints are revolute or prismatic (chain two or three revolute joints instead)",
            ));
        }
        other => {
            return Err(SimError::bad_argument(format!(
                "argument 1: invalid joint type {other} (sim.joint_revolute_subtype or sim.joint_prismatic_subtype)"
            )));
        }
    };
    let (mode, ik_mode) = match a.int(1)? {
        0 => (JointMode::Kinematic, false),
        2 => (JointMode::Kinematic, true),
        5 => (JointMode::Velocity, false),
        4 => {
            return Err(SimError::bad_argument(
                "argument 2: gantry has dependent joints only as URDF <mimic> followers",
            ));
        }
        other => {
            return Err(SimError::bad_argument(format!(
                "argument 2: invalid joint mode {other} (sim.jointmode_kinematic, sim.jointmode_ik or sim.jointmode_dynamic)"
            )));
        }
    };
    let options = a.opt_int(2, 0)?;
    let cyclic = options & 1 != 0;
    if cyclic && joint_type == JointType::Prismatic {
        return Err(SimError::bad_argument(
            "argument 3: only a revolute joint can be cyclic (options bit 0)",
        ));
    }
    match a.get(3) {
        Value::Nil => {}
        Value::Array(_) => {
            let sizes = a.numbers(3)?;
            if sizes.len() < 2 || sizes[..2].iter().any(|s| !(s.is_finite() && *s > 0.0)) {
                return Err(SimError::bad_argument(format!(
                    "argument 4: sizes {sizes:?} must be a length and a diameter, finite and > 0 (m)"
                )));
            }
        }
        other => {
            return Err(SimError::bad_argument(format!(
                "argument 4: expected the sizes {{length, diameter}} or nil, got {}",
                other.type_name()
            )));
        }
    }
    let (limits, max_force, alias) = match joint_type {
        JointType::Revolute => ((!cyclic).then_some((-PI, PI)), NEW_JOINT_TORQUE, "Revolute_joint"),
        _ => (
            Some((-NEW_PRISMATIC_HALF_RANGE, NEW_PRISMATIC_HALF_RANGE)),
            NEW_JOINT_FORCE,
            "Prismatic_joint",
        ),
    };
    let model = JointModel {
        joint_type,
        mode,
        limits,
        cyclic,
        initial: 0.0,
        target_position: 0.0,
        target_velocity: 0.0,
        max_force,
        kp: DEFAULT_KP,
        kd: if mode == JointMode::Velocity {
            DEFAULT_VELOCITY_KD
        } else {
            DEFAULT_KD
        },
        damping: 0.0,
        friction: 0.0,
        max_velocity: None,
        mimic: None,
    };
    let h = w.add_joint(alias, &model, None, Pose::identity())?;
    if ik_mode {
        w.set_joint_ik_mode(h, true)?;
    }
    Ok(vec![Value::Int(h)])
}
