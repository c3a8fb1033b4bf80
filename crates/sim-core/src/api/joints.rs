//! Joint state and targets. Positions in rad (revolute) or m (prismatic).

use super::{Args, CallContext, Ret};
use crate::Value;
use crate::error::SimError;
use crate::scene::JointType;
use crate::world::World;

/// `sim.getJointPosition(h)` → position.
pub(super) fn get_joint_position(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Float(w.joint(a.handle(0)?)?.position)])
}

/// `sim.setJointPosition(h, q)`: clamped to the limits, cyclic joints wrapped into
/// (-pi, pi]; descendants move at once.
pub(super) fn set_joint_position(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    w.set_joint_position(h, a.finite(1)?)?;
    Ok(Vec::new())
}

/// `sim.getJointVelocity(h)` → rad/s or m/s.
pub(super) fn get_joint_velocity(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Float(w.joint(a.handle(0)?)?.velocity)])
}

/// `sim.getJointTargetPosition(h)`.
pub(super) fn get_joint_target_position(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Float(w.joint(a.handle(0)?)?.target_position)])
}

/// `sim.setJointTargetPosition(h, q, motionParams={})`: dynamic joints servo to it with
/// their controller; kinematic ones move there over the next steps (see
/// `Joint::kinematic_step`). Motion parameters are accepted and ignored.
pub(super) fn set_joint_target_position(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    w.set_joint_target_position(h, a.finite(1)?)?;
    Ok(Vec::new())
}

/// `sim.getJointTargetVelocity(h)`.
pub(super) fn get_joint_target_velocity(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Float(w.joint(a.handle(0)?)?.target_velocity)])
}

/// `sim.setJointTargetVelocity(h, v, motionParams={})`.
pub(super) fn set_joint_target_velocity(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    w.set_joint_target_velocity(h, a.finite(1)?)?;
    Ok(Vec::new())
}

/// `sim.setJointTargetForce(h, f, signedValue=true)`: in force/torque mode
/// (`sim.jointdynctrl_force`) the torque (N·m) or force (N) the joint applies, signed
/// unless `signedValue` is false; in the velocity and position modes, `|f|` is the
/// controller's largest torque or force.
pub(super) fn set_joint_target_force(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let signed = a.opt_bool(2, true)?;
    w.set_joint_target_force(h, a.finite(1)?, signed)?;
    Ok(Vec::new())
}

/// `sim.getJointForce(h)` → the torque/force the motor applied in the last step.
pub(super) fn get_joint_force(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Float(w.joint(a.handle(0)?)?.force)])
}

/// `sim.getJointInterval(h)` → `cyclic, [min, range]` (CoppeliaSim gives min and range,
/// not min and max).
pub(super) fn get_joint_interval(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let j = w.joint(a.handle(0)?)?;
    let (min, range) = match (j.cyclic, j.limits) {
        (true, _) => (-std::f64::consts::PI, 2.0 * std::f64::consts::PI),
        (false, Some((lo, hi))) => (lo, hi - lo),
        // Unlimited non-cyclic joints: CoppeliaSim reports a huge interval.
        (false, None) => (-1e5, 2e5),
    };
    Ok(vec![Value::Bool(j.cyclic), Value::floats(&[min, range])])
}

/// `sim.getJointType(h)` → `sim.joint_revolute_subtype` (10), prismatic (11), or
/// gantry's `sim.joint_fixed_subtype` (13).
pub(super) fn get_joint_type(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let code = match w.joint(a.handle(0)?)?.joint_type {
        JointType::Revolute => 10,
        JointType::Prismatic => 11,
        JointType::Fixed => 13,
    };
    Ok(vec![Value::Int(code)])
}

/// `sim.setJointInterval(h, cyclic, {min, range})`: a revolute joint made cyclic loses
/// its limits and wraps its position; otherwise its limits become `min ..= min + range`
/// (rad or m; a prismatic joint is never cyclic). The position is clamped into the new
/// interval at once.
pub(super) fn set_joint_interval(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let cyclic = a.bool(1)?;
    let [min, range] = a.floats::<2>(2)?;
    w.set_joint_interval(h, cyclic, min, range)?;
    Ok(Vec::new())
}
