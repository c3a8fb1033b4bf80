//! `simIK.*` functions of CoppeliaSim 4.2 whose arguments differ from a 4.3+ function, and
//! the 4.3+ functions those names need that [`super::ik`] does not have yet.
//!
//! Pure renames (`createIkGroup` → `createGroup`, ...) are aliases of the simIK module in
//! [`super::MODULES`], not functions here. gantry's IK objects *are* the scene objects (see
//! [`crate::ik`]), so the functions that address IK objects (`setObjectMatrix`,
//! `setJointPosition`, ...) read and write the scene. The 4.2 functions that build a
//! separate IK world object by object (`createDummy`, `createJoint`, `setObjectParent`,
//! `setJointMode`, `setJointInterval`, `setLinkedDummy`, `addIkElement`) are deliberately
//! absent: they would edit the scene's tree or create an element without a target, so a
//! script using them fails with "No such function" instead of solving something else.

use super::{ApiError, ApiFn, ApiFunction, Args, CallContext, Ret, joints, objects};
use crate::Value;
use crate::ik::{IkElement, KinematicModel};
use crate::sim::Sim;
use crate::world::{Handle, ObjectKind};

/// The functions this file implements, in alphabetical order.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "getElementBase",
        call: ApiFn::Sim(get_element_base),
    },
    ApiFunction {
        name: "getObjectMatrix",
        call: ApiFn::Sim(get_object_matrix),
    },
    ApiFunction {
        name: "setElementBase",
        call: ApiFn::Sim(set_element_base),
    },
    ApiFunction {
        name: "setJointPosition",
        call: ApiFn::Sim(set_joint_position),
    },
    ApiFunction {
        name: "setObjectMatrix",
        call: ApiFn::Sim(set_object_matrix),
    },
];

/// 4.2 names that only differ from a 4.3+ name by spelling: `(old, current)`.
pub(super) const ALIASES: &[(&str, &str)] = &[
    ("createIkGroup", "createGroup"),
    ("getIkGroupHandle", "getGroupHandle"),
    ("setIkElementBase", "setElementBase"),
    ("setIkElementConstraints", "setElementConstraints"),
    ("setIkElementPrecision", "setElementPrecision"),
    ("setIkElementWeights", "setElementWeights"),
    ("setIkGroupCalculation", "setGroupCalculation"),
];

/// `sim.handle_world` (also `simIK.handle_world`).
const HANDLE_WORLD: Handle = -1;

/// Checks that argument 0 names a live environment, so that a call with a stale
/// environment fails as every other `simIK` call does even though the object functions
/// below only touch the scene.
fn check_environment(sim: &Sim, a: &Args<'_>) -> Result<(), ApiError> {
    sim.ik.get(a.handle(0)?)?;
    Ok(())
}

/// The arguments after the environment handle, for the `sim.*` function of the same shape.
fn without_environment<'a>(a: &Args<'a>) -> Vec<Value> {
    (1..a.len()).map(|i| a.get(i).clone()).collect()
}

/// `simIK.setElementBase(env, group, element, base, constraintsBase=-1)` (4.2:
/// `setIkElementBase`): the chain now starts at `base` (-1: the world). Constraints are
/// expressed in the base's frame, so `constraintsBase` may only be -1 or `base`; another
/// frame is refused rather than ignored, because partial constraints (`constraint_x`, ...)
/// would silently mean other axes.
fn set_element_base(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, ApiError> {
    let (env, group, element) = (a.handle(0)?, a.handle(1)?, a.handle(2)?);
    let base = a.handle(3)?;
    let constraints_base = a.opt_int(4, HANDLE_WORLD)?;
    if constraints_base != HANDLE_WORLD && constraints_base != base {
        return Err(ApiError::new(format!(
            "argument 5: constraints relative to object {constraints_base} are not supported \
             (gantry expresses them in the base's frame: pass -1)"
        )));
    }
    let mut probe: IkElement = sim.ik.get_mut(env)?.group_mut(group)?.element_mut(element)?.clone();
    probe.base = base;
    // The checks handleGroup relies on (base exists, tip below it, a joint between) run
    // now, so a bad base fails here and not at the next solve.
    KinematicModel::from_world(&sim.world, std::slice::from_ref(&probe))?;
    sim.ik.get_mut(env)?.group_mut(group)?.element_mut(element)?.base = base;
    Ok(Vec::new())
}

/// `simIK.getElementBase(env, group, element)` → base, constraintsBase. The constraint
/// frame is always the base, reported as -1 as CoppeliaSim does for "same as base".
fn get_element_base(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, ApiError> {
    let (env, group, element) = (a.handle(0)?, a.handle(1)?, a.handle(2)?);
    let base = sim.ik.get_mut(env)?.group_mut(group)?.element_mut(element)?.base;
    Ok(vec![Value::Int(base), Value::Int(HANDLE_WORLD)])
}

/// `simIK.getObjectMatrix(env, object, relativeTo=-1)` → 12 numbers, row-major 3x4 (m):
/// the scene object's pose, as `sim.getObjectMatrix`. A solution held back by
/// `handleGroup{syncWorlds=false}` is not reflected (it lives only as joint values).
fn get_object_matrix(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, ApiError> {
    check_environment(sim, a)?;
    let rest = without_environment(a);
    objects::get_object_matrix(&mut sim.world, ctx, &Args::new(&rest))
}

/// `simIK.setObjectMatrix(env, object, relativeTo, matrix)` (4.2-4.4 order) or
/// `(env, object, matrix, relativeTo=-1)` (4.5+): moves the scene object. Scripts use it
/// to copy a target's pose into the IK world, which here is the scene itself. Joints are
/// refused: moving one would reshape the robot in the scene, not just in an IK copy.
fn set_object_matrix(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, ApiError> {
    check_environment(sim, a)?;
    let h = a.handle(1)?;
    if matches!(sim.world.object(h)?.kind, ObjectKind::Joint(_)) {
        return Err(ApiError::new(format!(
            "object {h} is a joint: gantry's IK objects are the scene's, so set its value with \
             simIK.setJointPosition instead of moving it"
        )));
    }
    let rest = without_environment(a);
    objects::set_object_matrix(&mut sim.world, ctx, &Args::new(&rest))
}

/// `simIK.setJointPosition(env, joint, position)`: sets the scene joint (rad or m, clamped
/// to its limits as `sim.setJointPosition`) and forgets any solution pending for it, so
/// `simIK.getJointPosition` returns the new value.
fn set_joint_position(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, ApiError> {
    let (env, joint) = (a.handle(0)?, a.handle(1)?);
    sim.ik.get(env)?;
    let rest = without_environment(a);
    let out = joints::set_joint_position(&mut sim.world, ctx, &Args::new(&rest))?;
    sim.ik.get_mut(env)?.pending.remove(&joint);
    Ok(out)
}
