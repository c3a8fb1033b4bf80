//! The simulation's clock and run state as scripts and clients read them, and the
//! wall clock.

use super::{Args, CallContext, Ret};
use crate::Value;
use crate::error::SimError;
use crate::sim::Sim;
use crate::world::World;

/// `sim.getSimulationTime()` → seconds at the start of the current step.
pub(super) fn get_simulation_time(w: &mut World, _: &CallContext<'_>, _: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Float(w.time())])
}

/// `sim.getSimulationTimeStep()` → dt in seconds.
pub(super) fn get_simulation_time_step(w: &mut World, _: &CallContext<'_>, _: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Float(w.settings().dt)])
}

/// `sim.getSimulationState()` → 0 stopped, 8 paused, 16-21 advancing (see `Advancing`).
pub(super) fn get_simulation_state(sim: &mut Sim, _: &CallContext<'_>, _: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Int(sim.simulation_state_code())])
}

/// `sim.getSystemTime()` → wall-clock seconds since the Unix epoch.
pub(super) fn get_system_time(_: &mut World, _: &CallContext<'_>, _: &Args<'_>) -> Result<Ret, SimError> {
    let t = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64());
    Ok(vec![Value::Float(t)])
}
