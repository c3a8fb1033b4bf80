//! `simIK.*` functions of CoppeliaSim 4.2 whose arguments differ from a 4.3+ function, and
//! the 4.3+ functions those names need that [`super::ik`] does not have yet.
//!
//! Pure renames (`createIkGroup` → `createGroup`, `setLinkedDummy` → `setTargetDummy`,
//! ...) are aliases of the simIK module in [`super::MODULES`], not functions here. The
//! functions on objects, the environment's own (`createDummy`, `createJoint`, ...) and
//! the scene's, are in [`super::ik_objects`].

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::ik::{self, Trees};
use crate::sim::Sim;
use crate::world::Handle;

/// The functions this file implements, in alphabetical order.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "getConfigForTipPose",
        call: ApiFn::Sim(get_config_for_tip_pose),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getElementBase",
        call: ApiFn::Sim(get_element_base),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "setElementBase",
        call: ApiFn::Sim(set_element_base),
        cost: Cost::Long,
    },
];

/// 4.2 names that only differ from a 4.3+ name by spelling: `(old, current)`.
pub(super) const ALIASES: &[(&str, &str)] = &[
    ("addIkElement", "addElement"),
    ("createIkGroup", "createGroup"),
    ("getIkGroupFlags", "getGroupFlags"),
    ("getIkGroupHandle", "getGroupHandle"),
    ("getLinkedDummy", "getTargetDummy"),
    ("setIkElementBase", "setElementBase"),
    ("setIkElementConstraints", "setElementConstraints"),
    ("setIkElementPrecision", "setElementPrecision"),
    ("setIkElementWeights", "setElementWeights"),
    ("setIkGroupCalculation", "setGroupCalculation"),
    ("setIkGroupFlags", "setGroupFlags"),
    ("setLinkedDummy", "setTargetDummy"),
];

/// `sim.handle_world` (also `simIK.handle_world`).
const HANDLE_WORLD: Handle = -1;

/// `simIK.setElementBase(env, group, element, base, constraintsBase=-1)` (4.2:
/// `setIkElementBase`): the chain now starts at `base` (-1: the world). Constraints are
/// expressed in the base's frame, so `constraintsBase` may only be -1 or `base`; another
/// frame is refused rather than ignored, because partial constraints (`constraint_x`, ...)
/// would silently mean other axes.
fn set_element_base(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (env, group, element) = (a.handle(0)?, a.handle(1)?, a.handle(2)?);
    let base = a.handle(3)?;
    let constraints_base = a.opt_int(4, HANDLE_WORLD)?;
    if constraints_base != HANDLE_WORLD && constraints_base != base {
        return Err(SimError::bad_argument(format!(
            "argument 5: constraints relative to object {constraints_base} are not supported \
             (gantry expresses them in the base's frame: pass -1)"
        )));
    }
    let tip = sim.ik.get_mut(env)?.group_mut(group)?.element_mut(element)?.tip;
    // The checks handleGroup relies on (base exists in the tip's tree, tip below it, a
    // joint between) run now, so a bad base fails here and not at the next solve.
    ik::check_chain(&Trees::new(&sim.world, &sim.ik.get(env)?.objects), base, tip)?;
    sim.ik.get_mut(env)?.group_mut(group)?.element_mut(element)?.base = base;
    Ok(Vec::new())
}

/// `simIK.getElementBase(env, group, element)` → base, constraintsBase. The constraint
/// frame is always the base, reported as -1 as CoppeliaSim does for "same as base".
fn get_element_base(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (env, group, element) = (a.handle(0)?, a.handle(1)?, a.handle(2)?);
    let base = sim.ik.get_mut(env)?.group_mut(group)?.element_mut(element)?.base;
    Ok(vec![Value::Int(base), Value::Int(HANDLE_WORLD)])
}

/// How `getConfigForTipPose` searches, in place of CoppeliaSim's time limit: random
/// configurations drawn at most, and solves run at most from those near enough.
pub(super) const CONFIG_SAMPLES: u32 = 10_000;
pub(super) const CONFIG_SOLVES: u32 = 1_000;
/// Iterations each of its solves gets at least (see [`ik::ConfigSearch::min_iterations`]).
pub(super) const CONFIG_MIN_ITERATIONS: u32 = 100;

/// `simIK.getConfigForTipPose(env, group, jointHandles, distanceThreshold=0.1,
/// maxTimeInMs=100, metric=nil, validationCallback=nil, auxData=nil, jointOptions=nil,
/// lowLimits=nil, ranges=nil)` → joint values in the order of `jointHandles`, or `nil`
/// (CoppeliaSim 4.2; 4.3 renamed it `findConfig`).
///
/// Searches for a configuration putting the group's tips on their targets without moving
/// any joint, as CoppeliaSim does: random configurations within the joints' limits, and
/// from those whose tips lie within `distanceThreshold` of their targets (in the
/// `metric`, default {1, 1, 1, 0.1}: metres, and radians counting a tenth), a solve with
/// the group's settings but at least 100 iterations (gantry's steps are shorter than
/// CoppeliaSim's; see [`ik::find_config`]). The script applies the result. gantry
/// draws a fixed number of configurations from a fixed seed instead of sampling for
/// `maxTimeInMs`, so the result does not depend on the machine's speed. The validation
/// callback must be a function name (or empty) and is not called; `auxData`, the joint
/// options and custom limits are ignored.
fn get_config_for_tip_pose(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (env, group) = (a.handle(0)?, a.handle(1)?);
    let Value::Array(items) = a.get(2) else {
        return Err(SimError::bad_argument(format!(
            "argument 3: expected array of joint handles, got {}",
            a.get(2).type_name()
        )));
    };
    let joints = items
        .iter()
        .map(|v| {
            v.as_i64()
                .ok_or_else(|| SimError::bad_argument("argument 3: joint handles must be integers"))
        })
        .collect::<Result<Vec<Handle>, _>>()?;
    let threshold = a.opt_f64(3, 0.1)?;
    a.opt_f64(4, 100.0)?;
    let metric = match a.get(5) {
        Value::Nil => ik::ConfigSearch::DEFAULT_METRIC,
        _ => a.floats::<4>(5)?,
    };
    match a.get(6) {
        Value::Nil | Value::Str(_) => {}
        other => {
            return Err(SimError::bad_argument(format!(
                "argument 7: expected the validation callback's name (a string), got {}",
                other.type_name()
            )));
        }
    }
    let search = ik::ConfigSearch {
        samples: CONFIG_SAMPLES,
        solves: CONFIG_SOLVES,
        threshold: Some(threshold),
        metric,
        min_iterations: CONFIG_MIN_ITERATIONS,
    };
    let Some(found) = ik::find_config(&sim.world, &sim.ik, env, group, &search)? else {
        return Ok(vec![Value::Nil]);
    };
    Ok(vec![super::ik::config_values(&found, &joints)?])
}
