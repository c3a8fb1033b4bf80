//! Remote clients' blocking calls in progress (`sim.wait`, `sim.moveToConfig`, ...):
//! what the engine keeps while the Lua host's coroutine waits for steps
//! ([`gantry_lua::LuaHost::start_blocking`]).

use gantry_lua::BlockingId;
use gantry_sim_core::Value;
use gantry_sim_core::api::{CallError, ScriptHostFn};
use tokio::sync::oneshot;

use crate::stepping::ClientId;

/// Where a blocking call's answer goes.
pub type BlockingReply = oneshot::Sender<Result<Vec<Value>, CallError>>;

/// One blocking call in progress.
pub(crate) struct BlockingCall {
    /// The Lua host's name for it.
    pub id: BlockingId,
    /// The client that made it: while it steps the simulation, its call takes the
    /// steps it needs (none for an in-process client, which steps itself).
    pub client: Option<ClientId>,
    /// The function.
    pub f: ScriptHostFn,
    /// Its answer's way back.
    pub reply: BlockingReply,
}

/// Why a blocking call cannot start: it waits for steps that will not come.
pub(crate) fn stopped_error(f: ScriptHostFn) -> CallError {
    CallError::failed(
        format!("sim.{}", f.name()),
        gantry_sim_core::SimError::refused(
            "it waits for simulation steps, and the simulation is stopped: start it first (sim.startSimulation)",
        ),
    )
}

/// The answer to a blocking call the simulation's stop ended.
pub(crate) fn ended_error(f: ScriptHostFn) -> CallError {
    CallError::failed(
        format!("sim.{}", f.name()),
        gantry_sim_core::SimError::refused("the simulation stopped before the call returned"),
    )
}
