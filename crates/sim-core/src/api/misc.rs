//! Time, simulation state, the log and signals.

use super::{ApiError, Args, CallContext, Ret};
use crate::Value;
use crate::sim::Sim;
use crate::world::World;

/// `sim.getSimulationTime()` → seconds at the start of the current step.
pub(super) fn get_simulation_time(w: &mut World, _: &CallContext<'_>, _: &Args<'_>) -> Result<Ret, ApiError> {
    Ok(vec![Value::Float(w.time())])
}

/// `sim.getSimulationTimeStep()` → dt in seconds.
pub(super) fn get_simulation_time_step(w: &mut World, _: &CallContext<'_>, _: &Args<'_>) -> Result<Ret, ApiError> {
    Ok(vec![Value::Float(w.settings().dt)])
}

/// `sim.getSimulationState()` → 0 stopped, 8 paused, 16-21 advancing (see `Advancing`).
pub(super) fn get_simulation_state(sim: &mut Sim, _: &CallContext<'_>, _: &Args<'_>) -> Result<Ret, ApiError> {
    Ok(vec![Value::Int(sim.simulation_state_code())])
}

/// `sim.getSystemTime()` → wall-clock seconds since the Unix epoch.
pub(super) fn get_system_time(_: &mut World, _: &CallContext<'_>, _: &Args<'_>) -> Result<Ret, ApiError> {
    let t = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64());
    Ok(vec![Value::Float(t)])
}

/// `sim.addLog(verbosity, message)`.
pub(super) fn add_log(w: &mut World, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, ApiError> {
    let verbosity = a.int(0)?;
    let msg = a.str(1)?;
    let t = w.time();
    w.log.push(t, verbosity, ctx.source, msg);
    Ok(Vec::new())
}

/// `sim.setInt32Signal(name, value)`.
pub(super) fn set_int32_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, ApiError> {
    let name = a.str(0)?.to_owned();
    let v = a.int(1)?;
    let v = i32::try_from(v).map_err(|_| ApiError::new(format!("argument 2: {v} does not fit in 32 bits")))?;
    sim.signals.int32.insert(name, v);
    Ok(Vec::new())
}

/// `sim.getSimulatorMessage()` → `message, auxiliaryData, auxiliaryData2`: the caller's
/// next user-interface event (each script, and the remote clients together, read their
/// own queue), `-1, {0, 0, 0, 0}, {}` when there is none. gantry posts key presses in
/// the viewer: `sim.message_keypress`, `{code, modifiers, 0, 0}`.
pub(super) fn get_simulator_message(sim: &mut Sim, ctx: &CallContext<'_>, _: &Args<'_>) -> Result<Ret, ApiError> {
    let (kind, aux) = sim
        .messages
        .next(ctx.script_object)
        .map_or((-1, [0; 4]), |m| (m.kind, m.aux));
    let aux = Value::Array(aux.iter().map(|&v| Value::Int(v)).collect());
    Ok(vec![Value::Int(kind), aux, Value::Array(Vec::new())])
}

/// `sim.getInt32Signal(name)` → value, or nil when not set.
pub(super) fn get_int32_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, ApiError> {
    Ok(vec![
        sim.signals
            .int32
            .get(a.str(0)?)
            .map_or(Value::Nil, |v| Value::Int(i64::from(*v))),
    ])
}

/// `sim.clearInt32Signal(name)`; with no name, clears them all.
pub(super) fn clear_int32_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, ApiError> {
    match a.get(0) {
        Value::Nil => sim.signals.int32.clear(),
        _ => {
            sim.signals.int32.remove(a.str(0)?);
        }
    }
    Ok(Vec::new())
}

/// `sim.setFloatSignal(name, value)`.
pub(super) fn set_float_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, ApiError> {
    let name = a.str(0)?.to_owned();
    sim.signals.float.insert(name, a.f64(1)?);
    Ok(Vec::new())
}

/// `sim.getFloatSignal(name)` → value, or nil when not set.
pub(super) fn get_float_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, ApiError> {
    Ok(vec![
        sim.signals
            .float
            .get(a.str(0)?)
            .map_or(Value::Nil, |v| Value::Float(*v)),
    ])
}

/// `sim.clearFloatSignal(name)`; with no name, clears them all.
pub(super) fn clear_float_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, ApiError> {
    match a.get(0) {
        Value::Nil => sim.signals.float.clear(),
        _ => {
            sim.signals.float.remove(a.str(0)?);
        }
    }
    Ok(Vec::new())
}

/// `sim.setStringSignal(name, value)`: text or bytes.
pub(super) fn set_string_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, ApiError> {
    let name = a.str(0)?.to_owned();
    sim.signals.string.insert(name, a.bytes(1)?);
    Ok(Vec::new())
}

/// `sim.getStringSignal(name)` → the value as bytes, or nil.
pub(super) fn get_string_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, ApiError> {
    // Always a byte buffer, as in CoppeliaSim 4.6+ (Python clients get `bytes`);
    // Lua sees a string either way.
    Ok(vec![match sim.signals.string.get(a.str(0)?) {
        None => Value::Nil,
        Some(b) => Value::Bytes(b.clone()),
    }])
}

/// `sim.clearStringSignal(name)`; with no name, clears them all.
pub(super) fn clear_string_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, ApiError> {
    match a.get(0) {
        Value::Nil => sim.signals.string.clear(),
        _ => {
            sim.signals.string.remove(a.str(0)?);
        }
    }
    Ok(Vec::new())
}
