//! What a front end hands the engine, and what it gets back: one [`Input`] type for
//! everything that reaches a simulation from outside, served by `Engine::serve`.
//!
//! Each front end builds inputs at its edge (the text channel a packet, ZMQ and Python
//! a resolved call, the viewer a control, the legacy remote API all of these) and
//! answers its client from the [`Output`]. Inputs whose answer comes steps later (a
//! blocking call, a stepping client's `sim.step()`) carry their reply channel and are
//! answered on it; their output is [`Output::Pending`].

use std::path::Path;

use gantry_lua::HookError;
use gantry_sim_core::Value;
use gantry_sim_core::api::{CallError, ScriptHostFn, Target};
use gantry_sim_core::sim::SimulationState;
use tokio::sync::oneshot;

use crate::blocking::BlockingReply;
use crate::host_call::{LoopControl, RemoteOp};
use crate::stepping::ClientId;

/// One request to the simulation from outside it.
#[derive(Debug)]
pub enum Input<'a> {
    /// A call of a core registry function or a function the Lua host serves, for a
    /// remote client (no emitting object). Answered by [`Output::Values`].
    Call {
        /// The function, resolved by the front end.
        target: &'a Target,
        /// Its arguments.
        args: &'a [Value],
    },
    /// A remote client's blocking call (`sim.wait`, `sim.waitForSignal`,
    /// `sim.moveToConfig`, `sim.moveToPose`): run up to its first wait now, then
    /// resumed after each step until it returns, when `reply` gets its answer. While
    /// `client` steps the simulation, its call takes the steps it needs, as its own
    /// `sim.step()` calls would. Refused at once while the simulation is stopped.
    Blocking {
        /// The client (none for the in-process client, which steps itself).
        client: Option<ClientId>,
        /// The function.
        f: ScriptHostFn,
        /// Its arguments.
        args: &'a [Value],
        /// Where the answer goes.
        reply: BlockingReply,
    },
    /// A text packet to the scripts' `sysCall_packet(packet)`: the first running script
    /// that defines it answers. Answered by [`Output::Packet`].
    Packet(&'a Value),
    /// The viewer's and the command line's start, pause, stop or single step.
    /// Answered by [`Output::State`], the state afterwards.
    Control(LoopControl),
    /// A remote client's simulation control or stepping call. Answered by
    /// [`Output::Values`].
    Remote {
        /// The client, for per-client stepping levels and locks.
        client: ClientId,
        /// What to do.
        op: RemoteOp,
    },
    /// `sim.step()` of a stepping client: `done` is answered once the simulation has
    /// taken the next step (at once if it is stopped or paused).
    Step {
        /// The client asking.
        client: ClientId,
        /// Sent to (or dropped, if the simulation ends) when the step is done.
        done: oneshot::Sender<()>,
    },
    /// A client left or timed out: it can no longer hold the simulation.
    DropClient(ClientId),
    /// The editor's edit: `calls`, each a core registry function by name (`sim.*`)
    /// with its arguments, carried out in order as one step of the undo history. Only
    /// while the simulation is stopped (CoppeliaSim's rule); when a call fails, the
    /// scene is put back as it was before the first and the error names the call.
    /// Answered by [`Output::Values`]: each call's results, as one list per call.
    Edit {
        /// What the edit does, for the history ("Add cuboid", "Move leftWheel").
        label: &'a str,
        /// The calls.
        calls: &'a [(String, Vec<Value>)],
    },
    /// Undoes the last edit (`true`) or redoes the last undone one (`false`). Answered
    /// by [`Output::Values`]: the edit's label, or nothing when there is none.
    Undo(bool),
    /// `sim.loadScene(path)` (`Some`) or `sim.closeScene()` (`None`): the running
    /// simulation stops and the new scene waits, stopped, for a start. Answered by
    /// [`Output::Values`] (empty on success).
    LoadScene(Option<&'a Path>),
}

/// The engine's answer to an [`Input`].
#[derive(Debug, PartialEq)]
pub enum Output {
    /// A call's results, or a CoppeliaSim-style error naming the function.
    Values(Result<Vec<Value>, CallError>),
    /// What the scripts' `sysCall_packet` returned (`None`: no script defines it).
    Packet(Result<Option<Vec<Value>>, HookError>),
    /// The simulation's state after a control.
    State(SimulationState),
    /// Answered later on the input's own channel.
    Pending,
    /// Nothing to answer.
    Done,
}

impl Output {
    /// The results of an input answered by [`Output::Values`]; the other outputs carry
    /// no values and give none.
    ///
    /// # Errors
    /// The call's error.
    pub fn into_values(self) -> Result<Vec<Value>, CallError> {
        match self {
            Output::Values(r) => r,
            Output::Packet(_) | Output::State(_) | Output::Pending | Output::Done => Ok(Vec::new()),
        }
    }
}
