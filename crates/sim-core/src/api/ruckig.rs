//! Jerk-limited online trajectories: `sim.ruckigPos`, `sim.ruckigVel`, `sim.ruckigStep`
//! and `sim.ruckigRemove`, on `rsruckig` (a Rust port of the Ruckig library that
//! CoppeliaSim's own implementation wraps).
//!
//! `ruckigPos`/`ruckigVel` create a generator and return its handle; each
//! `ruckigStep(handle, cycleTime)` advances it by `cycleTime` seconds and returns the
//! new position, velocity and acceleration of every DoF. The generators live in the
//! simulation ([`crate::motion::RuckigObjects`]), so they disappear with it when the simulation stops, as
//! CoppeliaSim removes a script's objects with the script.
//!
//! Conventions, as CoppeliaSim: the state and limit tables concatenate one value per
//! DoF for each quantity (`currentPosVelAccel` is all positions, then all velocities,
//! then all accelerations); `flags` -1 keeps Ruckig's defaults (time synchronisation),
//! otherwise `flags & 3` picks phase (`sim.ruckig_phasesync`, 0), time (1) or no (3)
//! synchronisation and `sim.ruckig_minvel` (256) / `sim.ruckig_minaccel` (512) add
//! minimum velocity / acceleration tables after the maximum ones. Units are the caller's (rad or m, per
//! second, per second squared, per second cubed).

use crate::error::SimError;
use rsruckig::prelude::{
    ControlInterface, DataArrayOrVec, InputParameter, OutputParameter, Ruckig, RuckigError, Synchronization,
};

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::motion::RuckigObject;
use crate::sim::Sim;

/// The functions this file implements, sorted by name.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "ruckigPos",
        call: ApiFn::Sim(ruckig_pos),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "ruckigRemove",
        call: ApiFn::Sim(ruckig_remove),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "ruckigStep",
        call: ApiFn::Sim(ruckig_step),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "ruckigVel",
        call: ApiFn::Sim(ruckig_vel),
        cost: Cost::Quick,
    },
];

/// `sim.ruckig_minvel`: `maxVelAccelJerk` also holds the minimum velocities.
const FLAG_MIN_VEL: i64 = 0x100;
/// `sim.ruckig_minaccel`: the limit table also holds the minimum accelerations.
const FLAG_MIN_ACCEL: i64 = 0x200;

/// The `sim.ruckig_*` flags, with CoppeliaSim's values: one synchronisation (`flags & 3`),
/// combined with the minimum-limit flags.
pub(super) const CONSTANTS: &[(&str, i64)] = &[
    ("ruckig_phasesync", 0),
    ("ruckig_timesync", 1),
    ("ruckig_nosync", 3),
    ("ruckig_minvel", FLAG_MIN_VEL),
    ("ruckig_minaccel", FLAG_MIN_ACCEL),
];
/// Most DoFs of one generator: far more than any robot, few enough that one step stays cheap.
pub(crate) const MAX_DOFS: usize = 1024;
/// How far `cycleTime` may be from a whole number of base cycles (relative), as
/// CoppeliaSim checks it.
const CYCLE_TOLERANCE: f64 = 1e-3;
/// `sim.verbosity_scriptwarnings`, for Ruckig's reason when it rejects an input.
const WARNING: i64 = 420;

fn no_object(h: i64) -> SimError {
    SimError::no_such_item(format!(
        "Ruckig object does not exist (handle {h}): it was removed, or not created with sim.ruckigPos/ruckigVel"
    ))
}

/// Argument `i`: at least `n` numbers (extra ones are ignored, as CoppeliaSim does);
/// infinities are allowed only where `allow_infinite` (limits), NaN never.
fn numbers(a: &Args<'_>, i: usize, what: &str, n: usize, allow_infinite: bool) -> Result<Vec<f64>, SimError> {
    let Value::Array(items) = a.get(i) else {
        return Err(SimError::bad_argument(format!(
            "argument {} ({what}): expected a table of {n} numbers, got {}",
            i + 1,
            a.get(i).type_name()
        )));
    };
    if items.len() < n {
        return Err(SimError::bad_argument(format!(
            "argument {} ({what}): expected {n} numbers, got {}",
            i + 1,
            items.len()
        )));
    }
    items[..n]
        .iter()
        .enumerate()
        .map(|(k, v)| match v.as_f64() {
            Some(f) if f.is_finite() || (allow_infinite && !f.is_nan()) => Ok(f),
            _ => Err(SimError::bad_argument(format!(
                "argument {} ({what}): element {} must be a {}number, got {}",
                i + 1,
                k + 1,
                if allow_infinite { "" } else { "finite " },
                match v {
                    Value::Float(f) => format!("{f}"),
                    other => other.type_name().to_owned(),
                }
            ))),
        })
        .collect()
}

/// The arguments both constructors share: DoF count, base cycle time and flags.
fn header(a: &Args<'_>) -> Result<(usize, f64, i64), SimError> {
    let dofs = a.int(0)?;
    let dofs = usize::try_from(dofs)
        .ok()
        .filter(|d| (1..=MAX_DOFS).contains(d))
        .ok_or_else(|| SimError::bad_argument(format!("argument 1 (dofs): expected 1 to {MAX_DOFS}, got {dofs}")))?;
    let base = a.f64(1)?;
    if !(base.is_finite() && base > 0.0) {
        return Err(SimError::bad_argument(format!(
            "argument 2 (baseCycleTime): expected a positive number of seconds, got {base}"
        )));
    }
    Ok((dofs, base, a.int(2)?))
}

/// A new generator with the current state `cur` (positions, velocities, accelerations)
/// and the selection of argument `sel_arg`.
fn generator(
    a: &Args<'_>,
    dofs: usize,
    base: f64,
    flags: i64,
    cur: &[f64],
    sel_arg: usize,
) -> Result<RuckigObject, SimError> {
    let selection = match a.get(sel_arg) {
        Value::Array(items) if items.len() >= dofs => items[..dofs]
            .iter()
            .enumerate()
            .map(|(k, v)| match v {
                Value::Bool(b) => Ok(*b),
                v => v.as_f64().map(|x| x != 0.0).ok_or_else(|| {
                    SimError::bad_argument(format!(
                        "argument {} (selection): element {} must be a number or a boolean",
                        sel_arg + 1,
                        k + 1
                    ))
                }),
            })
            .collect::<Result<Vec<bool>, _>>()?,
        other => {
            return Err(SimError::bad_argument(format!(
                "argument {} (selection): expected a table of {dofs} values, got {}",
                sel_arg + 1,
                match other {
                    Value::Array(items) => format!("{} values", items.len()),
                    v => v.type_name().to_owned(),
                }
            )));
        }
    };
    let mut input = InputParameter::<0>::new(Some(dofs));
    if flags >= 0 {
        // CoppeliaSim's values; 2 was the phase-only flag of its older Reflexxes functions.
        input.synchronization = match flags & 3 {
            1 => Synchronization::Time,
            3 => Synchronization::None,
            _ => Synchronization::Phase,
        };
    }
    for d in 0..dofs {
        input.current_position[d] = cur[d];
        input.current_velocity[d] = cur[dofs + d];
        input.current_acceleration[d] = cur[2 * dofs + d];
        input.enabled[d] = selection[d];
    }
    Ok(RuckigObject {
        otg: Ruckig::new(Some(dofs), base),
        input,
        output: OutputParameter::new(Some(dofs)),
        dofs,
        base_cycle: base,
        elapsed: 0.0,
        duration: None,
        warned: false,
    })
}

/// Which optional minimum tables the flags ask for (-1 asks for none).
fn min_flags(flags: i64) -> (bool, bool) {
    (
        flags >= 0 && flags & FLAG_MIN_VEL != 0,
        flags >= 0 && flags & FLAG_MIN_ACCEL != 0,
    )
}

/// `sim.ruckigPos(dofs, baseCycleTime, flags, currentPosVelAccel[3n],
/// maxVelAccelJerk[3n (+n minVel) (+n minAccel)], selection[n], targetPosVel[2n])` → handle.
fn ruckig_pos(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (n, base, flags) = header(a)?;
    let cur = numbers(a, 3, "currentPosVelAccel", 3 * n, false)?;
    let (min_vel, min_accel) = min_flags(flags);
    let limits_len = n * (3 + usize::from(min_vel) + usize::from(min_accel));
    let limits = numbers(a, 4, "maxVelAccelJerk", limits_len, true)?;
    let target = numbers(a, 6, "targetPosVel", 2 * n, false)?;
    let mut obj = generator(a, n, base, flags, &cur, 5)?;
    let input = &mut obj.input;
    for d in 0..n {
        input.max_velocity[d] = limits[d];
        input.max_acceleration[d] = limits[n + d];
        input.max_jerk[d] = limits[2 * n + d];
        input.target_position[d] = target[d];
        input.target_velocity[d] = target[n + d];
    }
    // The minimum tables follow the three maximum ones, velocities first.
    let mut next = 3 * n;
    if min_vel {
        input.min_velocity = Some(DataArrayOrVec::Heap(limits[next..next + n].to_vec()));
        next += n;
    }
    if min_accel {
        input.min_acceleration = Some(DataArrayOrVec::Heap(limits[next..next + n].to_vec()));
    }
    Ok(vec![Value::Int(sim.ruckig.insert(obj)?)])
}

/// `sim.ruckigVel(dofs, baseCycleTime, flags, currentPosVelAccel[3n],
/// maxAccelJerk[2n (+n minAccel)], selection[n], targetVel[n])` → handle.
fn ruckig_vel(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (n, base, flags) = header(a)?;
    let cur = numbers(a, 3, "currentPosVelAccel", 3 * n, false)?;
    let (_, min_accel) = min_flags(flags);
    let limits = numbers(a, 4, "maxAccelJerk", n * (2 + usize::from(min_accel)), true)?;
    let target = numbers(a, 6, "targetVel", n, false)?;
    let mut obj = generator(a, n, base, flags, &cur, 5)?;
    let input = &mut obj.input;
    input.control_interface = ControlInterface::Velocity;
    for d in 0..n {
        input.max_acceleration[d] = limits[d];
        input.max_jerk[d] = limits[n + d];
        input.target_velocity[d] = target[d];
    }
    if min_accel {
        input.min_acceleration = Some(DataArrayOrVec::Heap(limits[2 * n..3 * n].to_vec()));
    }
    Ok(vec![Value::Int(sim.ruckig.insert(obj)?)])
}

/// `sim.ruckigStep(handle, cycleTime)` → `result, newPosVelAccel[3n], synchronizationTime`.
///
/// `cycleTime` (s) must be a whole number of base cycles (within 0.1 %); the generator
/// advances by exactly `cycleTime`. `result` is 0 while moving, 1 once the target is
/// reached (and on every later step), or Ruckig's negative error code (-100 invalid
/// input, with the reason logged once; -101 to -111 calculation failures), in which case
/// the state is returned unchanged. `synchronizationTime` is the time still needed to
/// reach the target after this step: the trajectory's duration minus the time stepped,
/// negative by the unused part of the last cycle once finished.
fn ruckig_step(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let cycle = a.f64(1)?;
    let now = sim.world.time();
    let obj = sim.ruckig.get_mut(h).ok_or_else(|| no_object(h))?;
    let cycles = (cycle / obj.base_cycle).round();
    if !(cycle.is_finite() && cycles >= 1.0 && (1.0 - cycles * obj.base_cycle / cycle).abs() < CYCLE_TOLERANCE) {
        return Err(SimError::bad_argument(format!(
            "argument 2 (cycleTime): expected a positive multiple of the base cycle time {} s, got {cycle}",
            obj.base_cycle
        )));
    }
    // One update over the whole cycle: the trajectory is a function of time, so this is
    // the state CoppeliaSim reaches with `cycles` updates of the base cycle, without
    // their cost (delta_time only matters to calculations with a discretised duration,
    // which are not used here).
    obj.otg.delta_time = cycle;
    let (code, warning) = match obj.otg.update(&obj.input, &mut obj.output) {
        Ok(r) => (r as i64, None),
        Err(RuckigError::ValidationError(m)) => (-100, Some(m)),
        Err(RuckigError::CalculatorError(m)) => (-1, Some(m)),
    };
    let sync = if code >= 0 {
        obj.output.pass_to_input(&mut obj.input);
        obj.elapsed += cycle;
        let duration = *obj.duration.get_or_insert(obj.output.trajectory.get_duration());
        duration - obj.elapsed
    } else {
        0.0
    };
    let n = obj.dofs;
    let state: Vec<f64> = (0..n)
        .map(|d| obj.input.current_position[d])
        .chain((0..n).map(|d| obj.input.current_velocity[d]))
        .chain((0..n).map(|d| obj.input.current_acceleration[d]))
        .collect();
    if let Some(m) = warning.filter(|_| !obj.warned) {
        obj.warned = true;
        sim.world.log.push(
            now,
            WARNING,
            ctx.source,
            &format!("sim.ruckigStep: Ruckig object {h}: {m}"),
        );
    }
    Ok(vec![Value::Int(code), Value::floats(&state), Value::Float(sync)])
}

/// `sim.ruckigRemove(handle)`.
fn ruckig_remove(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    sim.ruckig.objects.remove(&h).ok_or_else(|| no_object(h))?;
    Ok(Vec::new())
}
