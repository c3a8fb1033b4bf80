//! `simIK.*`: CoppeliaSim 4.x's kinematics plugin API: environments, groups, elements and
//! solving (see [`crate::ik`] for the model). The functions on objects are in
//! [`super::ik_objects`].
//!
//! Handles: environments are numbered from 1; groups and elements share one counter per
//! environment; an environment's own objects are numbered from [`ik::FIRST_OBJECT`]. An
//! element made from the scene has no copy of its objects (the scene is its IK world),
//! so `addElementFromScene`'s `simToIkMap`/`ikToSimMap` are identity maps over the
//! chain's objects.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::ik::{self, Apply, Constraints, GroupFlags, GroupsOutcome, IkMethod};
use crate::sim::Sim;
use crate::world::Handle;

/// The functions this file implements, in alphabetical order.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "addElement",
        call: ApiFn::Sim(add_element_to_group),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "addElementFromScene",
        call: ApiFn::Sim(add_element_from_scene),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "addIkElementFromScene",
        call: ApiFn::Sim(add_ik_element_from_scene),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "applyIkEnvironmentToScene",
        call: ApiFn::Sim(apply_ik_environment_to_scene),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "applySceneToIkEnvironment",
        call: ApiFn::Sim(apply_scene_to_ik_environment),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "createEnvironment",
        call: ApiFn::Sim(create_environment),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "createGroup",
        call: ApiFn::Sim(create_group),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "eraseEnvironment",
        call: ApiFn::Sim(erase_environment),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "findConfig",
        call: ApiFn::Sim(find_config),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getElementConstraints",
        call: ApiFn::Sim(get_element_constraints),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getElementPrecision",
        call: ApiFn::Sim(get_element_precision),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getElementWeights",
        call: ApiFn::Sim(get_element_weights),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getGroupCalculation",
        call: ApiFn::Sim(get_group_calculation),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getGroupFlags",
        call: ApiFn::Sim(get_group_flags),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getGroupHandle",
        call: ApiFn::Sim(get_group_handle),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getGroupJoints",
        call: ApiFn::Sim(get_group_joints),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "handleGroup",
        call: ApiFn::Sim(handle_group),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "handleGroups",
        call: ApiFn::Sim(handle_groups),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "handleIkGroup",
        call: ApiFn::Sim(handle_ik_group),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "setElementConstraints",
        call: ApiFn::Sim(set_element_constraints),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "setElementPrecision",
        call: ApiFn::Sim(set_element_precision),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "setElementWeights",
        call: ApiFn::Sim(set_element_weights),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "setGroupCalculation",
        call: ApiFn::Sim(set_group_calculation),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "setGroupFlags",
        call: ApiFn::Sim(set_group_flags),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "syncFromSim",
        call: ApiFn::Sim(sync_from_sim),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "syncToSim",
        call: ApiFn::Sim(sync_to_sim),
        cost: Cost::Long,
    },
];

/// The `simIK.*` constants, with CoppeliaSim's values.
pub(super) const CONSTANTS: &[(&str, i64)] = &[
    ("method_pseudo_inverse", 0),
    ("method_damped_least_squares", 1),
    ("method_jacobian_transpose", 2),
    ("method_undamped_pseudo_inverse", 3),
    ("constraint_x", 1),
    ("constraint_y", 2),
    ("constraint_z", 4),
    ("constraint_alpha_beta", 8),
    ("constraint_gamma", 16),
    ("constraint_position", 7),
    ("constraint_orientation", 24),
    ("constraint_pose", 31),
    ("result_not_performed", 0),
    ("result_success", 1),
    ("result_fail", 2),
    // The 4.1 names of the same results, used by the paper's script.
    ("ikresult_not_performed", 0),
    ("ikresult_success", 1),
    ("ikresult_fail", 2),
    ("calc_notperformed", ik::CALC_NOT_PERFORMED),
    ("calc_cannotinvert", ik::CALC_CANNOT_INVERT),
    ("calc_notwithintolerance", ik::CALC_NOT_WITHIN_TOLERANCE),
    ("calc_stepstoobig", 8),
    ("calc_limithit", ik::CALC_LIMIT_HIT),
    ("handle_world", -1),
    ("group_enabled", 1),
    ("group_ignoremaxsteps", 2),
    ("group_restoreonbadlintol", 4),
    ("group_restoreonbadangtol", 8),
];

/// `simIK.createEnvironment(flags=0)` → environment handle. Flags are accepted and ignored.
fn create_environment(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    a.opt_int(0, 0)?;
    Ok(vec![Value::Int(sim.ik.create())])
}

/// `simIK.eraseEnvironment(env)`: drops its groups and elements; the scene is untouched.
fn erase_environment(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    sim.ik.erase(a.handle(0)?)?;
    Ok(Vec::new())
}

/// `simIK.createGroup(env, name='')` → group handle. New groups use CoppeliaSim's
/// defaults: pseudo-inverse, damping 0.1, 3 iterations.
fn create_group(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let env = a.handle(0)?;
    let name = match a.get(1) {
        Value::Nil => "",
        _ => a.str(1)?,
    };
    let environment = sim.ik.get_mut(env)?;
    if environment.group_by_name(name).is_some() {
        return Err(SimError::refused(format!("an IK group named '{name}' already exists")));
    }
    Ok(vec![Value::Int(environment.create_group(name))])
}

/// `simIK.getGroupHandle(env, name)` → group handle.
fn get_group_handle(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let env = a.handle(0)?;
    let name = a.str(1)?;
    sim.ik
        .get(env)?
        .group_by_name(name)
        .map(|h| vec![Value::Int(h)])
        .ok_or_else(|| SimError::no_such_item(format!("no IK group named '{name}'")))
}

/// `simIK.setGroupCalculation(env, group, method, damping, maxIterations)`.
/// Damping must be finite and >= 0; iterations between 1 and 100000 (a bound on the time
/// one call may take on the sim thread).
fn set_group_calculation(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (env, group) = (a.handle(0)?, a.handle(1)?);
    let code = a.int(2)?;
    let method = IkMethod::from_code(code).ok_or_else(|| {
        SimError::bad_argument(format!(
            "argument 3: unknown method {code} (use simIK.method_pseudo_inverse, \
             method_damped_least_squares, method_jacobian_transpose or method_undamped_pseudo_inverse)"
        ))
    })?;
    let damping = a.finite(3)?;
    if damping < 0.0 {
        return Err(SimError::bad_argument(format!(
            "argument 4: damping must be >= 0, got {damping}"
        )));
    }
    let iterations = a.int(4)?;
    let max_iterations = u32::try_from(iterations)
        .ok()
        .filter(|n| (1..=100_000).contains(n))
        .ok_or_else(|| {
            SimError::bad_argument(format!("argument 5: maxIterations must be 1..100000, got {iterations}"))
        })?;
    let g = sim.ik.get_mut(env)?.group_mut(group)?;
    g.method = method;
    g.damping = damping;
    g.max_iterations = max_iterations;
    Ok(Vec::new())
}

/// `simIK.setGroupFlags(env, group, flags)` (4.2: `setIkGroupFlags`): `simIK.group_enabled`
/// (1; a disabled group is skipped), `group_ignoremaxsteps` (2; accepted, gantry has no
/// maximum steps), `group_restoreonbadlintol` (4) and `group_restoreonbadangtol` (8; the
/// joints keep their values when the position or orientation ends outside its precision).
/// Other bits (stop on limit hit, avoid limits, ...) are refused.
fn set_group_flags(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (env, group) = (a.handle(0)?, a.handle(1)?);
    let code = a.int(2)?;
    let flags = GroupFlags::from_code(code).ok_or_else(|| {
        SimError::bad_argument(format!(
            "argument 3: unsupported group flags {code} (combine simIK.group_enabled, group_ignoremaxsteps, \
             group_restoreonbadlintol and group_restoreonbadangtol, 0..15)"
        ))
    })?;
    sim.ik.get_mut(env)?.group_mut(group)?.flags = flags;
    Ok(Vec::new())
}

/// `simIK.getGroupFlags(env, group)` → flags (default 3: enabled, ignoring maximum steps).
fn get_group_flags(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let g = sim.ik.get(a.handle(0)?)?.group(a.handle(1)?)?;
    Ok(vec![Value::Int(i64::from(g.flags.0))])
}

/// `simIK.getGroupJoints(env, group)` → the joints of the group's chains, base to tip.
fn get_group_joints(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let joints = ik::chain_joints(&sim.world, &sim.ik, a.handle(0)?, a.handle(1)?)?;
    Ok(vec![Value::Array(joints.into_iter().map(Value::Int).collect())])
}

/// `simIK.getGroupCalculation(env, group)` → method, damping, maxIterations.
fn get_group_calculation(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let g = sim.ik.get(a.handle(0)?)?.group(a.handle(1)?)?;
    Ok(vec![
        Value::Int(g.method.code()),
        Value::Float(g.damping),
        Value::Int(i64::from(g.max_iterations)),
    ])
}

/// Argument `i` as a constraint combination.
fn constraints_arg(a: &Args<'_>, i: usize) -> Result<Constraints, SimError> {
    let code = a.int(i)?;
    Constraints::from_code(code).ok_or_else(|| {
        SimError::bad_argument(format!(
            "argument {}: invalid constraints {code} (combine simIK.constraint_x/y/z/alpha_beta/gamma, 1..31)",
            i + 1
        ))
    })
}

/// The shared part of the two `addElementFromScene` spellings: element handle and the
/// identity map over the chain's objects.
fn add_element(sim: &mut Sim, a: &Args<'_>) -> Result<(Value, Value), SimError> {
    let (env, group) = (a.handle(0)?, a.handle(1)?);
    let ends = [a.handle(2)?, a.handle(3)?, a.handle(4)?];
    let constraints = constraints_arg(a, 5)?;
    let (element, objects) = ik::add_element_from_scene(&sim.world, &mut sim.ik, env, group, ends, constraints)?;
    let map = Value::Map(objects.iter().map(|&h| (Value::Int(h), Value::Int(h))).collect());
    Ok((Value::Int(element), map))
}

/// `simIK.addElementFromScene(env, group, base, tip, target, constraints)` → element,
/// simToIkMap, ikToSimMap. `base` may be -1 (world). The chain is every revolute and
/// prismatic joint on the tree path from `tip` up to `base`. Both maps are identity maps
/// (scene handle → the same handle) over base, the path objects and the target, because
/// gantry's IK objects are the scene objects.
fn add_element_from_scene(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (element, map) = add_element(sim, a)?;
    Ok(vec![element, map.clone(), map])
}

/// `simIK.addIkElementFromScene(...)`: the 4.2 name; returns element, simToIkMap.
fn add_ik_element_from_scene(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (element, map) = add_element(sim, a)?;
    Ok(vec![element, map])
}

/// `simIK.addElement(env, group, tipDummy)` (4.2: `addIkElement`) → element. The tip is a
/// dummy, usually one of the environment's own; its target is whatever dummy it is linked
/// to when the group is solved (`simIK.setLinkedDummy`; `sim.setLinkDummy` for a scene
/// dummy). The element's base is the world until `setElementBase`, and it constrains the
/// full pose until `setElementConstraints`, as in CoppeliaSim.
fn add_element_to_group(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (env, group, tip) = (a.handle(0)?, a.handle(1)?, a.handle(2)?);
    Ok(vec![Value::Int(ik::add_element(
        &sim.world,
        &mut sim.ik,
        env,
        group,
        tip,
    )?)])
}

/// Resolves (env, group, element) from arguments 0..3 and runs `f` on the element.
fn with_element<T>(sim: &mut Sim, a: &Args<'_>, f: impl FnOnce(&mut ik::IkElement) -> T) -> Result<T, SimError> {
    let (env, group, element) = (a.handle(0)?, a.handle(1)?, a.handle(2)?);
    let e = sim.ik.get_mut(env)?.group_mut(group)?.element_mut(element)?;
    Ok(f(e))
}

/// `simIK.setElementConstraints(env, group, element, constraints)`.
fn set_element_constraints(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let c = constraints_arg(a, 3)?;
    with_element(sim, a, |e| e.constraints = c)?;
    Ok(Vec::new())
}

/// `simIK.getElementConstraints(env, group, element)` → constraints.
fn get_element_constraints(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let c = with_element(sim, a, |e| e.constraints)?;
    Ok(vec![Value::Int(i64::from(c.0))])
}

/// Argument `i` as two non-negative finite numbers.
fn pair_arg(a: &Args<'_>, i: usize, what: &str) -> Result<[f64; 2], SimError> {
    let v = a.floats::<2>(i)?;
    if v.iter().any(|x| *x < 0.0) {
        return Err(SimError::bad_argument(format!(
            "argument {}: {what} must be >= 0",
            i + 1
        )));
    }
    Ok(v)
}

/// `simIK.setElementPrecision(env, group, element, {linear (m), angular (rad)})`: the
/// distances below which the element counts as solved.
fn set_element_precision(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p = pair_arg(a, 3, "precisions")?;
    with_element(sim, a, |e| e.precision = p)?;
    Ok(Vec::new())
}

/// `simIK.getElementPrecision(env, group, element)` → {linear (m), angular (rad)}.
fn get_element_precision(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p = with_element(sim, a, |e| e.precision)?;
    Ok(vec![Value::floats(&p)])
}

/// `simIK.setElementWeights(env, group, element, {linear, angular[, element]})`: factors on
/// the error rows (CoppeliaSim weights the error, not the Jacobian).
fn set_element_weights(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let [lin, ang] = pair_arg(a, 3, "weights")?;
    let whole = match a.get(3) {
        Value::Array(v) if v.len() >= 3 => match v[2].as_f64() {
            Some(x) if x.is_finite() && x >= 0.0 => x,
            _ => {
                return Err(SimError::bad_argument(
                    "argument 4: element 3 must be a finite number >= 0",
                ));
            }
        },
        _ => 1.0,
    };
    with_element(sim, a, |e| e.weights = [lin, ang, whole])?;
    Ok(Vec::new())
}

/// `simIK.getElementWeights(env, group, element)` → {linear, angular, element}.
fn get_element_weights(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let wts = with_element(sim, a, |e| e.weights)?;
    Ok(vec![Value::floats(&wts)])
}

/// The options table of `handleGroup(s)`: `syncWorlds` (gantry default **true**: there is
/// no separate IK world a script could read the result from otherwise, short of
/// `simIK.getJointPosition`) and `allowError` (default false). Unknown keys are ignored,
/// as CoppeliaSim ignores `debug`, `callback` and the like that gantry does not support.
fn apply_policy(a: &Args<'_>, i: usize) -> Result<Apply, SimError> {
    let opts = a.get(i);
    let flag = |key: &str, default: bool| match opts.get(key) {
        None | Some(Value::Nil) => Ok(default),
        Some(Value::Bool(b)) => Ok(*b),
        Some(other) => Err(SimError::bad_argument(format!(
            "argument {}: options.{key} must be a boolean, got {}",
            i + 1,
            other.type_name()
        ))),
    };
    match opts {
        // An empty Lua table may arrive as an empty array.
        Value::Nil | Value::Map(_) => {}
        Value::Array(v) if v.is_empty() => {}
        other => {
            return Err(SimError::bad_argument(format!(
                "argument {}: expected options table, got {}",
                i + 1,
                other.type_name()
            )));
        }
    }
    Ok(match (flag("syncWorlds", true)?, flag("allowError", false)?) {
        (false, _) => Apply::Never,
        (true, false) => Apply::OnSuccess,
        (true, true) => Apply::Always,
    })
}

/// `result, flags, {linear, angular}` as CoppeliaSim returns them.
fn outcome_values(o: &GroupsOutcome) -> Ret {
    vec![
        Value::Int(o.result.code()),
        Value::Int(o.flags),
        Value::floats(&o.precision),
    ]
}

/// `simIK.handleGroup(env, group, options={})` → result, flags, {linear (m), angular (rad)}.
///
/// Solves from the current joint values. The environment's own joints take the solution
/// (unless the group's flags restore them). For a chain made from the scene, with
/// `syncWorlds` (default true) the solution is written to the scene joints only if every
/// element ended within its precision (or `allowError=true`), as CoppeliaSim's
/// `handleGroup`; otherwise the scene is unchanged and the solution waits for
/// `simIK.syncToSim`.
fn handle_group(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (env, group) = (a.handle(0)?, a.handle(1)?);
    let apply = apply_policy(a, 2)?;
    Ok(outcome_values(&ik::handle_groups(
        &mut sim.world,
        &mut sim.ik,
        env,
        &[group],
        apply,
    )?))
}

/// Argument `i` as a non-empty array of group handles.
fn groups_arg(a: &Args<'_>, i: usize) -> Result<Vec<Handle>, SimError> {
    let Value::Array(items) = a.get(i) else {
        return Err(SimError::bad_argument(format!(
            "argument {}: expected array of group handles, got {}",
            i + 1,
            a.get(i).type_name()
        )));
    };
    items
        .iter()
        .map(|v| {
            v.as_i64()
                .ok_or_else(|| SimError::bad_argument(format!("argument {}: group handles must be integers", i + 1)))
        })
        .collect()
}

/// `simIK.handleGroups(env, {groups}, options={})`: as `handleGroup`, solving the groups in
/// order, each starting from the previous ones' solution. Result is the worst result,
/// flags are or-ed, precision is the largest remaining distance.
fn handle_groups(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let env = a.handle(0)?;
    let groups = groups_arg(a, 1)?;
    let apply = apply_policy(a, 2)?;
    Ok(outcome_values(&ik::handle_groups(
        &mut sim.world,
        &mut sim.ik,
        env,
        &groups,
        apply,
    )?))
}

/// `simIK.handleIkGroup(env, group)` → result: the 4.1-4.2 name. For a chain of the
/// environment's own objects the solution stays in them (a script copies it to the scene
/// with `simIK.getJointPosition`). For a chain made from the scene, the paper's script
/// followed it by copying the IK joints onto the scene whatever the result, so gantry
/// writes the solution to the scene always (finite values within limits). Either way the
/// group's flags may keep the previous values (`group_restoreonbadlintol`, ...).
fn handle_ik_group(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (env, group) = (a.handle(0)?, a.handle(1)?);
    let o = ik::handle_groups(&mut sim.world, &mut sim.ik, env, &[group], Apply::Always)?;
    Ok(vec![Value::Int(o.result.code())])
}

/// `simIK.applyIkEnvironmentToScene(env, group, applyOnlyWhenSuccessful=false)` → result:
/// solve from the scene and write back (4.2-4.3 convenience function).
fn apply_ik_environment_to_scene(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (env, group) = (a.handle(0)?, a.handle(1)?);
    let apply = if a.opt_bool(2, false)? {
        Apply::OnSuccess
    } else {
        Apply::Always
    };
    let o = ik::handle_groups(&mut sim.world, &mut sim.ik, env, &[group], apply)?;
    Ok(vec![Value::Int(o.result.code())])
}

/// `simIK.applySceneToIkEnvironment(env, group)`: gantry always solves from the scene, so
/// this only forgets the group's pending solution (and checks its arguments).
fn apply_scene_to_ik_environment(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (env, group) = (a.handle(0)?, a.handle(1)?);
    ik::sync_from_scene(&sim.world, &mut sim.ik, env, &[group])?;
    Ok(Vec::new())
}

/// `simIK.syncFromSim(env, {groups})`: forget pending solutions of those groups.
fn sync_from_sim(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let env = a.handle(0)?;
    let groups = groups_arg(a, 1)?;
    ik::sync_from_scene(&sim.world, &mut sim.ik, env, &groups)?;
    Ok(Vec::new())
}

/// `simIK.syncToSim(env, {groups})`: write pending solutions (from `syncWorlds=false`
/// solves) of those groups' joints into the scene.
fn sync_to_sim(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let env = a.handle(0)?;
    let groups = groups_arg(a, 1)?;
    ik::sync_to_scene(&mut sim.world, &mut sim.ik, env, &groups)?;
    Ok(Vec::new())
}

/// How many starts `findConfig` tries at most (the first from the scene).
const FIND_CONFIG_ATTEMPTS: u32 = 100;

/// `simIK.findConfig(env, group, jointHandles, thresholdDist=0.1, maxTime=0.5, metric=nil,
/// callback=nil, auxData=nil)` → joint values in the order of `jointHandles`, or `nil`.
///
/// Searches for a configuration that reaches the group's targets (multi-start solves, see
/// [`ik::find_config`]) without moving the scene; a script then applies it with
/// `sim.setJointPosition`. gantry searches up to a fixed number of starts instead of for
/// `maxTime` seconds, so the result does not depend on the machine's speed; `thresholdDist`,
/// `metric` and the validation callback are accepted and ignored.
fn find_config(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (env, group) = (a.handle(0)?, a.handle(1)?);
    let joints = groups_arg(a, 2).map_err(|_| SimError::bad_argument("argument 3: expected array of joint handles"))?;
    a.opt_f64(3, 0.1)?;
    a.opt_f64(4, 0.5)?;
    let Some(found) = ik::find_config(
        &sim.world,
        &sim.ik,
        env,
        group,
        &ik::ConfigSearch::attempts(FIND_CONFIG_ATTEMPTS),
    )?
    else {
        return Ok(vec![Value::Nil]);
    };
    Ok(vec![config_values(&found, &joints)?])
}

/// A found configuration as the caller's joint order asks for it (`findConfig` and the
/// 4.2 `getConfigForTipPose` answer the same way).
///
/// # Errors
/// A joint the group's chains do not move.
pub(super) fn config_values(
    found: &std::collections::BTreeMap<Handle, f64>,
    joints: &[Handle],
) -> Result<Value, SimError> {
    let values = joints
        .iter()
        .map(|h| {
            found
                .get(h)
                .map(|&q| Value::Float(q))
                .ok_or_else(|| SimError::bad_argument(format!("argument 3: joint {h} is not in the group's chains")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Value::Array(values))
}
