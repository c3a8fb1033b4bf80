//! Signals: named integer, float, double and string values that scripts and clients share,
//! set, read and cleared by name.

use super::{Args, CallContext, Ret};
use crate::Value;
use crate::error::SimError;
use crate::sim::Sim;

/// `sim.setInt32Signal(name, value)`.
pub(super) fn set_int32_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let name = a.str(0)?.to_owned();
    let v = a.int(1)?;
    let v = i32::try_from(v).map_err(|_| SimError::bad_argument(format!("argument 2: {v} does not fit in 32 bits")))?;
    sim.signals.int32.insert(name, v);
    Ok(Vec::new())
}

/// `sim.getInt32Signal(name)` → value, or nil when not set.
pub(super) fn get_int32_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![
        sim.signals
            .int32
            .get(a.str(0)?)
            .map_or(Value::Nil, |v| Value::Int(i64::from(*v))),
    ])
}

/// `sim.clearInt32Signal(name)`; with no name, clears them all.
pub(super) fn clear_int32_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    match a.get(0) {
        Value::Nil => sim.signals.int32.clear(),
        _ => {
            sim.signals.int32.remove(a.str(0)?);
        }
    }
    Ok(Vec::new())
}

/// `sim.setFloatSignal(name, value)`.
pub(super) fn set_float_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let name = a.str(0)?.to_owned();
    sim.signals.float.insert(name, a.f64(1)?);
    Ok(Vec::new())
}

/// `sim.getFloatSignal(name)` → value, or nil when not set.
pub(super) fn get_float_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![
        sim.signals
            .float
            .get(a.str(0)?)
            .map_or(Value::Nil, |v| Value::Float(*v)),
    ])
}

/// `sim.clearFloatSignal(name)`; with no name, clears them all.
pub(super) fn clear_float_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    match a.get(0) {
        Value::Nil => sim.signals.float.clear(),
        _ => {
            sim.signals.float.remove(a.str(0)?);
        }
    }
    Ok(Vec::new())
}

/// `sim.setDoubleSignal(name, value)` (CoppeliaSim 4.1): double signals have their own
/// names, apart from the float signals.
pub(super) fn set_double_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let name = a.str(0)?.to_owned();
    sim.signals.double.insert(name, a.f64(1)?);
    Ok(Vec::new())
}

/// `sim.getDoubleSignal(name)` → value, or nil when not set.
pub(super) fn get_double_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![
        sim.signals
            .double
            .get(a.str(0)?)
            .map_or(Value::Nil, |v| Value::Float(*v)),
    ])
}

/// `sim.clearDoubleSignal(name)`; with no name, clears them all.
pub(super) fn clear_double_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    match a.get(0) {
        Value::Nil => sim.signals.double.clear(),
        _ => {
            sim.signals.double.remove(a.str(0)?);
        }
    }
    Ok(Vec::new())
}

/// `sim.setStringSignal(name, value)`: text or bytes.
pub(super) fn set_string_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let name = a.str(0)?.to_owned();
    sim.signals.string.insert(name, a.bytes(1)?);
    Ok(Vec::new())
}

/// `sim.getStringSignal(name)` → the value as bytes, or nil.
pub(super) fn get_string_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    // Always a byte buffer, as in CoppeliaSim 4.6+ (Python clients get `bytes`);
    // Lua sees a string either way.
    Ok(vec![match sim.signals.string.get(a.str(0)?) {
        None => Value::Nil,
        Some(b) => Value::Bytes(b.clone()),
    }])
}

/// `sim.clearStringSignal(name)`; with no name, clears them all.
pub(super) fn clear_string_signal(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    match a.get(0) {
        Value::Nil => sim.signals.string.clear(),
        _ => {
            sim.signals.string.remove(a.str(0)?);
        }
    }
    Ok(Vec::new())
}
