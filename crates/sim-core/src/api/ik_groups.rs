//! `sim.getIkGroupHandle`, `sim.handleIkGroup`, `sim.setExplicitHandling`, ...: V-REP 3 /
//! CoppeliaSim 4.0-4.2's built-in kinematics, on the IK groups the scene defines
//! ([`crate::ik_groups::SceneIkGroups`]; `[[ik_group]]` in a scene file). The groups are solved
//! by the same solver as `simIK`; those not flagged explicit are handled every step after
//! the scripts' actuation.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use std::collections::BTreeMap;

use crate::ik::{self, Constraints, IkMethod};
use crate::ik_groups::IkPath;
use crate::sim::Sim;
use crate::world::{Handle, ObjectKind};

/// The functions this file implements, in alphabetical order.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "checkIkGroup",
        call: ApiFn::Sim(check_ik_group),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "generateIkPath",
        call: ApiFn::Sim(generate_ik_path),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getConfigForTipPose",
        call: ApiFn::Sim(get_config_for_tip_pose),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getExplicitHandling",
        call: ApiFn::Sim(get_explicit_handling),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getIkGroupHandle",
        call: ApiFn::Sim(get_ik_group_handle),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getIkGroupMatrix",
        call: ApiFn::Sim(get_ik_group_matrix),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "handleIkGroup",
        call: ApiFn::Sim(handle_ik_group),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "setExplicitHandling",
        call: ApiFn::Sim(set_explicit_handling),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setIkElementProperties",
        call: ApiFn::Sim(set_ik_element_properties),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setIkGroupProperties",
        call: ApiFn::Sim(set_ik_group_properties),
        cost: Cost::Quick,
    },
];

/// The built-in kinematics' constants, with CoppeliaSim's values.
pub(super) const CONSTANTS: &[(&str, i64)] = &[
    ("ikresult_not_performed", 0),
    ("ikresult_success", 1),
    ("ikresult_fail", 2),
    ("ik_pseudo_inverse_method", 0),
    ("ik_damped_least_squares_method", 1),
    ("ik_jacobian_transpose_method", 2),
    ("ik_x_constraint", 1),
    ("ik_y_constraint", 2),
    ("ik_z_constraint", 4),
    ("ik_alpha_beta_constraint", 8),
    ("ik_gamma_constraint", 16),
    ("ik_avoidance_constraint", 64),
];

/// `sim.handle_all`.
const HANDLE_ALL: Handle = -2;
/// `sim.handle_all_except_explicit`.
const HANDLE_ALL_EXCEPT_EXPLICIT: Handle = -3;

/// The error of a handle that names no IK group.
fn no_group(h: Handle) -> SimError {
    SimError::no_such_item(format!("IK group {h} does not exist (use sim.getIkGroupHandle)"))
}

/// Argument `i` as the handle of one of the scene's IK groups.
fn group_arg(sim: &Sim, a: &Args<'_>, i: usize) -> Result<Handle, SimError> {
    let h = a.handle(i)?;
    sim.ik_groups.get(h).map(|g| g.handle).ok_or_else(|| no_group(h))
}

/// `sim.getIkGroupHandle(name)` → the handle of the scene's IK group of that name.
fn get_ik_group_handle(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let name = a.str(0)?;
    sim.ik_groups
        .by_name(name)
        .map(|g| vec![Value::Int(g.handle)])
        .ok_or_else(|| {
            // A CoppeliaSim file's group whose elements could not be imported is dropped
            // at load with a warning naming it: point there.
            SimError::no_such_item(format!(
                "IK group '{name}' does not exist in the scene (a file's group that could not be imported                  is named in the loading warnings)"
            ))
        })
}

/// `sim.handleIkGroup(ikGroupHandle)`: solves the group from the scene's joint values
/// and writes the solution into the scene (whatever the result, as CoppeliaSim's built-in
/// IK does) → `sim.ikresult_not_performed`, `ikresult_success` or `ikresult_fail`.
/// With `sim.handle_all` or `sim.handle_all_except_explicit` every group not flagged
/// explicit is handled, and the result is how many were performed.
fn handle_ik_group(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    if h == HANDLE_ALL || h == HANDLE_ALL_EXCEPT_EXPLICIT {
        let n = sim.ik_groups.handle_automatic(&mut sim.world);
        return Ok(vec![Value::Int(i64::try_from(n).unwrap_or(i64::MAX))]);
    }
    let h = group_arg(sim, a, 0)?;
    let result = sim.ik_groups.handle(&mut sim.world, h)?;
    Ok(vec![Value::Int(result.code())])
}

/// Argument `i`: nil or a table (joint options, accepted and not used: gantry's IK groups
/// have no joint-dependent options).
fn joint_options(a: &Args<'_>, i: usize) -> Result<(), SimError> {
    match a.get(i) {
        Value::Nil | Value::Array(_) | Value::Map(_) => Ok(()),
        other => Err(SimError::bad_argument(format!(
            "argument {}: expected table of joint options or nil, got {}",
            i + 1,
            other.type_name()
        ))),
    }
}

/// The value of each of `joints`: the one `solved` gives, else the joint's current
/// position (a joint outside the group's chains does not move). `arg` names the
/// argument in errors.
fn joint_values(
    sim: &Sim,
    joints: &[Handle],
    solved: &BTreeMap<Handle, f64>,
    arg: usize,
) -> Result<Vec<f64>, SimError> {
    joints
        .iter()
        .map(|&j| match solved.get(&j) {
            Some(&q) => Ok(q),
            None => sim
                .world
                .joint(j)
                .map(|joint| joint.position)
                .map_err(|_| SimError::bad_argument(format!("argument {arg}: object {j} is not a joint"))),
        })
        .collect()
}

/// `sim.checkIkGroup(ikGroupHandle, jointHandles, jointOptions=nil)` → result, joint
/// values: solves the group from the scene's joint values as `sim.handleIkGroup` does,
/// without applying the solution (CoppeliaSim 4.1). The values are in the order of
/// `jointHandles`; a joint outside the group's chains keeps its current value. The
/// result is `sim.ikresult_success`, `ikresult_fail` or `ikresult_not_performed`.
fn check_ik_group(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = group_arg(sim, a, 0)?;
    let joints = super::scene::handle_list(a, 1)?;
    joint_options(a, 2)?;
    let (result, solved) = sim.ik_groups.check(&mut sim.world, h)?;
    let values = joint_values(sim, &joints, &solved, 2)?;
    Ok(vec![Value::Int(result.code()), Value::floats(&values)])
}

/// Most points `sim.generateIkPath` computes (each a full solve).
const MAX_PATH_POINTS: i64 = 100_000;

/// `sim.generateIkPath(ikGroupHandle, jointHandles, ptCnt, collisionPairs=nil,
/// jointOptions=nil)` → the joint values of `ptCnt` configurations (at least 2), one
/// after the other, each in the order of `jointHandles`, that move the group's tips in a
/// straight line from where they are to their targets (the first is the current
/// configuration); nil when a point cannot be reached or, with collision pairs
/// ({entity1, entity2, ...}; entity2 may be `sim.handle_all`), when a configuration
/// collides. The scene is left as it was (the joints are put back after the collision
/// checks). Joint options are accepted and not used.
fn generate_ik_path(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = group_arg(sim, a, 0)?;
    let joints = super::scene::handle_list(a, 1)?;
    let points = a.int(2)?;
    if !(2..=MAX_PATH_POINTS).contains(&points) {
        return Err(SimError::bad_argument(format!(
            "argument 3: ptCnt must be 2..{MAX_PATH_POINTS}, got {points}"
        )));
    }
    let pairs = match a.get(3) {
        Value::Nil => Vec::new(),
        _ => super::scene::handle_list(a, 3)?,
    };
    if pairs.len() % 2 != 0 {
        return Err(SimError::bad_argument(format!(
            "argument 4: collision pairs come in twos (entity1, entity2, ...), got {} handles",
            pairs.len()
        )));
    }
    joint_options(a, 4)?;
    // Bad joint handles fail whether or not a path exists.
    joint_values(sim, &joints, &BTreeMap::new(), 2)?;
    let points = usize::try_from(points).unwrap_or(2);
    let Some(path) = sim.ik_groups.linear_path(&sim.world, h, points)? else {
        return Ok(vec![Value::Nil]);
    };
    if !pairs.is_empty() && path_collides(sim, &path, &pairs)? {
        return Ok(vec![Value::Nil]);
    }
    let mut out = Vec::with_capacity(path.configs.len() * joints.len());
    for config in &path.configs {
        let solved: BTreeMap<Handle, f64> = path.joints.iter().copied().zip(config.iter().copied()).collect();
        out.extend(joint_values(sim, &joints, &solved, 2)?);
    }
    Ok(vec![Value::floats(&out)])
}

/// Whether any configuration of `path` makes a collision pair collide. The path's joints
/// are put back where they were, also when a pair names no entity.
fn path_collides(sim: &mut Sim, path: &IkPath, pairs: &[Handle]) -> Result<bool, SimError> {
    let before = path
        .joints
        .iter()
        .map(|&j| sim.world.joint(j).map(|joint| joint.position))
        .collect::<Result<Vec<f64>, _>>()?;
    let check = |sim: &mut Sim| -> Result<bool, SimError> {
        for config in &path.configs {
            for (&j, &q) in path.joints.iter().zip(config) {
                sim.world.set_joint_position(j, q)?;
            }
            sim.world.refresh_queries();
            for pair in pairs.chunks(2) {
                let a = sim.world.entity_shapes(pair[0], &[])?;
                let b = sim.world.entity_shapes(pair[1], &a)?;
                if sim.world.collision(&a, &b).is_some() {
                    return Ok(true);
                }
            }
        }
        Ok(false)
    };
    let result = check(sim);
    for (&j, &q) in path.joints.iter().zip(&before) {
        sim.world.set_joint_position(j, q)?;
    }
    result
}

/// `sim.setExplicitHandling(handle, flags)`: for an IK group, bit 0 set means only
/// `sim.handleIkGroup` on it solves it; clear, the main script does every step. For a
/// vision sensor, bit 0 set means it renders only when `sim.handleVisionSensor` handles
/// it (readers get its last image); clear, it renders when read. For another scene
/// object (a proximity sensor, joint, graph, ...) it is accepted and does nothing:
/// gantry handles those every step or when read.
fn set_explicit_handling(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let flags = a.int(1)?;
    if let Ok(ObjectKind::VisionSensor(_)) = sim.world.object(h).map(|o| &o.kind) {
        crate::vision::set_explicit(&sim.world, &mut sim.vision, h, flags & 1 != 0)?;
        return Ok(Vec::new());
    }
    if sim.ik_groups.set_explicit(h, flags & 1 != 0) || sim.world.object(h).is_ok() {
        return Ok(Vec::new());
    }
    Err(SimError::no_such_item(format!(
        "{h} is neither an IK group nor an object"
    )))
}

/// `sim.getExplicitHandling(handle)` → flags: bit 0 set for an IK group or a vision
/// sensor handled explicitly; 0 for another scene object.
fn get_explicit_handling(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    if let Ok(ObjectKind::VisionSensor(_)) = sim.world.object(h).map(|o| &o.kind) {
        return Ok(vec![Value::Int(i64::from(crate::vision::is_explicit(&sim.vision, h)))]);
    }
    if let Some(g) = sim.ik_groups.get(h) {
        return Ok(vec![Value::Int(i64::from(g.explicit))]);
    }
    if sim.world.object(h).is_ok() {
        return Ok(vec![Value::Int(0)]);
    }
    Err(SimError::no_such_item(format!(
        "{h} is neither an IK group nor an object"
    )))
}

/// `sim.getIkGroupMatrix(ikGroupHandle, options)` → matrix, {columns, rows}. Options 0:
/// the group's Jacobian at the scene's current joint values, row by row: one row per
/// constrained component of each element (x, y, z in the base's frame, then the angular
/// components), one column per joint of the chains, base to tip. Options 1: the
/// manipulability measure `sqrt(det(J Jᵀ))`, as a 1×1 matrix.
fn get_ik_group_matrix(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = group_arg(sim, a, 0)?;
    let options = a.int(1)?;
    let j = sim.ik_groups.jacobian(&sim.world, h)?;
    let size = |cols: usize, rows: usize| {
        let n = |x: usize| Value::Int(i64::try_from(x).unwrap_or(i64::MAX));
        Value::Array(vec![n(cols), n(rows)])
    };
    match options {
        0 => {
            let values: Vec<f64> = j
                .row_iter()
                .flat_map(|r| r.iter().copied().collect::<Vec<_>>())
                .collect();
            Ok(vec![Value::floats(&values), size(j.ncols(), j.nrows())])
        }
        1 => {
            let m = (&j * j.transpose()).determinant().max(0.0).sqrt();
            Ok(vec![Value::floats(&[m]), size(1, 1)])
        }
        other => Err(SimError::bad_argument(format!(
            "argument 2: options must be 0 (Jacobian) or 1 (manipulability measure), got {other}"
        ))),
    }
}

/// `sim.setIkGroupProperties(ikGroupHandle, resolutionMethod, maxIterations, damping)`:
/// `sim.ik_pseudo_inverse_method`, `ik_damped_least_squares_method` or
/// `ik_jacobian_transpose_method`; 1 to 100000 iterations; damping >= 0.
fn set_ik_group_properties(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = group_arg(sim, a, 0)?;
    let code = a.int(1)?;
    let method = IkMethod::from_code(code).filter(|_| code <= 2).ok_or_else(|| {
        SimError::bad_argument(format!(
            "argument 2: unknown resolution method {code} (use sim.ik_pseudo_inverse_method, \
             ik_damped_least_squares_method or ik_jacobian_transpose_method)"
        ))
    })?;
    let iterations = a.int(2)?;
    let max_iterations = u32::try_from(iterations)
        .ok()
        .filter(|n| (1..=100_000).contains(n))
        .ok_or_else(|| {
            SimError::bad_argument(format!("argument 3: maxIterations must be 1..100000, got {iterations}"))
        })?;
    let damping = a.finite(3)?;
    if damping < 0.0 {
        return Err(SimError::bad_argument(format!(
            "argument 4: damping must be >= 0, got {damping}"
        )));
    }
    let g = sim.ik_groups.settings_mut(h).ok_or_else(|| no_group(h))?;
    g.method = method;
    // Exactly what the script asks for: unlike the groups of the scene file (see
    // `MIN_ITERATIONS`), no floor, so a script can solve step by step.
    g.max_iterations = max_iterations;
    g.damping = damping;
    Ok(Vec::new())
}

/// Argument `i`: nil (keep), or two finite numbers >= 0.
fn opt_pair(a: &Args<'_>, i: usize, what: &str) -> Result<Option<[f64; 2]>, SimError> {
    if matches!(a.get(i), Value::Nil) {
        return Ok(None);
    }
    let v = a.floats::<2>(i)?;
    if v.iter().any(|x| *x < 0.0) {
        return Err(SimError::bad_argument(format!(
            "argument {}: {what} must be >= 0",
            i + 1
        )));
    }
    Ok(Some(v))
}

/// `sim.setIkElementProperties(ikGroupHandle, tipDummyHandle, constraints, precision=nil,
/// weight=nil)`: the element of the group tipped at that dummy gets the constraints
/// (`sim.ik_x_constraint` ... `ik_gamma_constraint` combined), and when given the
/// precision {linear (m), angular (rad)} and weights {linear, angular}.
/// `sim.ik_avoidance_constraint` is refused (gantry has no avoidance elements).
fn set_ik_element_properties(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = group_arg(sim, a, 0)?;
    let tip = a.handle(1)?;
    let code = a.int(2)?;
    let constraints = Constraints::from_code(code).ok_or_else(|| {
        SimError::bad_argument(format!(
            "argument 3: invalid constraints {code} (combine sim.ik_x_constraint, ik_y_constraint, ik_z_constraint, \
             ik_alpha_beta_constraint and ik_gamma_constraint, 1..31)"
        ))
    })?;
    let precision = opt_pair(a, 3, "precisions")?;
    let weights = opt_pair(a, 4, "weights")?;
    let e = sim
        .ik_groups
        .element_mut(h, tip)
        .ok_or_else(|| SimError::no_such_item(format!("IK group {h} has no element whose tip is object {tip}")))?;
    e.constraints = constraints;
    if let Some(p) = precision {
        e.precision = p;
    }
    if let Some([lin, ang]) = weights {
        e.weights = [lin, ang, e.weights[2]];
    }
    Ok(Vec::new())
}

/// `sim.getConfigForTipPose(ikGroupHandle, jointHandles, thresholdDist, maxTimeInMs,
/// metric=nil, collisionPairs=nil, jointOptions=nil, lowLimits=nil, ranges=nil)` → joint
/// values in the order of `jointHandles`, or nil when none was found (V-REP 3's form).
/// The search is `simIK.getConfigForTipPose`'s: random configurations within the joints'
/// limits from a fixed seed (not for `maxTimeInMs`), solved from those within
/// `thresholdDist` of the targets in the `metric` (default {1, 1, 1, 0.1}). The scene is
/// not moved. Collision pairs, joint options and custom limits are ignored.
fn get_config_for_tip_pose(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = group_arg(sim, a, 0)?;
    let Value::Array(items) = a.get(1) else {
        return Err(SimError::bad_argument(format!(
            "argument 2: expected array of joint handles, got {}",
            a.get(1).type_name()
        )));
    };
    let joints = items
        .iter()
        .map(|v| {
            v.as_i64()
                .ok_or_else(|| SimError::bad_argument("argument 2: joint handles must be integers"))
        })
        .collect::<Result<Vec<Handle>, _>>()?;
    let threshold = a.opt_f64(2, 0.1)?;
    a.opt_f64(3, 100.0)?;
    let metric = match a.get(4) {
        Value::Nil => ik::ConfigSearch::DEFAULT_METRIC,
        _ => a.floats::<4>(4)?,
    };
    let search = ik::ConfigSearch {
        samples: super::ik_legacy::CONFIG_SAMPLES,
        solves: super::ik_legacy::CONFIG_SOLVES,
        threshold: Some(threshold),
        metric,
        min_iterations: super::ik_legacy::CONFIG_MIN_ITERATIONS,
    };
    let Some(found) = sim.ik_groups.find_config(&sim.world, h, &search)? else {
        return Ok(vec![Value::Nil]);
    };
    let values = joints
        .iter()
        .map(|j| {
            found
                .get(j)
                .map(|&q| Value::Float(q))
                .ok_or_else(|| SimError::bad_argument(format!("argument 2: joint {j} is not in the group's chains")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(vec![Value::Array(values)])
}
