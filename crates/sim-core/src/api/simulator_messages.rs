//! `sim.getSimulatorMessage`: user-interface events (the viewer's key presses) queued
//! for each script and for the remote clients.

use super::{Args, CallContext, Ret};
use crate::Value;
use crate::error::SimError;
use crate::sim::Sim;

/// `sim.getSimulatorMessage()` → `message, auxiliaryData, auxiliaryData2`: the caller's
/// next user-interface event (each script, and the remote clients together, read their
/// own queue), `-1, {0, 0, 0, 0}, {}` when there is none. gantry posts key presses in
/// the viewer: `sim.message_keypress`, `{code, modifiers, 0, 0}`.
pub(super) fn get_simulator_message(sim: &mut Sim, ctx: &CallContext<'_>, _: &Args<'_>) -> Result<Ret, SimError> {
    let (kind, aux) = sim
        .messages
        .next(ctx.script_object)
        .map_or((-1, [0; 4]), |m| (m.kind, m.aux));
    let aux = Value::Array(aux.iter().map(|&v| Value::Int(v)).collect());
    Ok(vec![Value::Int(kind), aux, Value::Array(Vec::new())])
}
