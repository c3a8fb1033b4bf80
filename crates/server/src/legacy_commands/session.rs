//! A legacy client's session and one command being run: what every command family
//! reads and answers with.

use gantry_engine::{ClientId, RemoteOp};
use gantry_protocol::legacy_remote_api::Command;
use gantry_sim_core::Value;
use gantry_sim_core::sim::Control;
use tokio::sync::oneshot;

use super::layout::{CommandError, as_i32, id_int, put_count, put_string};
use crate::sim_thread::{Request, SendError, SimHandle};

/// Most error messages kept for `simxGetLastErrors` between two calls.
const MAX_ERRORS: usize = 64;

/// A client's state across its commands.
pub struct Session {
    pub(super) client: ClientId,
    pub(super) synchronous: bool,
    pub(super) killed: bool,
    pub(super) errors: Vec<String>,
    pub(super) scene_id: u16,
}

/// What a command gave.
pub struct Outcome {
    /// It succeeded (status bit 0 clear).
    pub ok: bool,
    /// The reply's pure data.
    pub data: Vec<u8>,
    /// A streaming command that must not run again (CoppeliaSim's
    /// `simxGetAndClearStringSignal` stops streaming once it found the signal).
    pub ends_stream: bool,
}

impl Session {
    /// A new client's session.
    pub fn new(client: ClientId) -> Self {
        Self {
            client,
            synchronous: false,
            killed: false,
            errors: Vec::new(),
            scene_id: 0,
        }
    }

    /// Whether the client asked to close the connection (`simxFinish`).
    pub fn killed(&self) -> bool {
        self.killed
    }

    /// Changes when a command loaded another scene, so clients can notice.
    pub fn scene_id(&self) -> u16 {
        self.scene_id
    }

    /// The header's server state bits (0: not stopped, 1: paused) and the simulation
    /// time in ms (0 while stopped), as the reply's commands carry it.
    pub async fn clock(&mut self, sim: &SimHandle) -> (u8, i32) {
        let state = sim.call("getSimulationState", vec![]).await;
        let state = as_i32(state.as_ref().ok().and_then(|v| v.first())).unwrap_or(0);
        if state == 0 {
            return (0, 0);
        }
        let time = sim.call("getSimulationTime", vec![]).await;
        let t = time.ok().and_then(|v| v.first().and_then(Value::as_f64)).unwrap_or(0.0);
        let bits = if state == 8 { 0b11 } else { 0b01 };
        (bits, (t * 1000.0).round().clamp(0.0, f64::from(i32::MAX)) as i32)
    }

    pub(super) fn fail(&mut self, cmd: &Command, why: impl Into<String>) -> Outcome {
        let why = why.into();
        tracing::debug!("legacy remote API command 0x{:04x}: {why}", cmd.code);
        if self.errors.len() < MAX_ERRORS {
            self.errors.push(why);
        }
        Outcome {
            ok: false,
            data: Vec::new(),
            ends_stream: false,
        }
    }
}

pub(super) fn ok(data: Vec<u8>) -> Outcome {
    Outcome {
        ok: true,
        data,
        ends_stream: false,
    }
}

/// One command being run: the simulation, the client's session and what it sent.
pub(super) struct Ctx<'a> {
    pub(super) sim: &'a SimHandle,
    pub(super) session: &'a mut Session,
    pub(super) cmd: &'a Command,
}

impl Ctx<'_> {
    /// One registry function's results.
    pub(super) async fn call(&self, name: &str, args: Vec<Value>) -> Result<Vec<Value>, CommandError> {
        self.sim.call(name, args).await.map_err(CommandError::Call)
    }

    /// A request that the registry does not serve because it concerns the client
    /// (stepping, simulation control), answered by the simulation thread.
    pub(super) async fn remote(&self, op: RemoteOp) -> Result<Vec<Value>, CommandError> {
        let (reply, rx) = oneshot::channel();
        self.sim.send(Request::Remote {
            client: self.session.client,
            op,
            reply,
        })?;
        Ok(rx.await.map_err(|_| SendError::Closed)??)
    }

    /// `simxSynchronous`: one stepping level per client, however often it asks.
    pub(super) async fn set_synchronous(&mut self, enable: bool) -> Result<Vec<u8>, CommandError> {
        if enable != self.session.synchronous {
            self.remote(RemoteOp::SetStepping(enable)).await?;
            self.session.synchronous = enable;
        }
        Ok(Vec::new())
    }

    /// `simxSynchronousTrigger`: answered once the step is done, so the client's next
    /// command sees it.
    pub(super) async fn synchronous_trigger(&self) -> Result<Vec<u8>, CommandError> {
        if !self.session.synchronous {
            return Err(CommandError::NotSynchronous);
        }
        let running = self.call("getSimulationState", vec![]).await?;
        if as_i32(running.first()).is_none_or(|s| s == 0 || s == 8) {
            return Err(CommandError::NotRunning);
        }
        let (done, rx) = oneshot::channel();
        self.sim.send(Request::Step {
            client: self.session.client,
            done,
        })?;
        rx.await.map_err(|_| CommandError::StoppedBeforeStep)?;
        Ok(Vec::new())
    }

    /// `simxStartSimulation`, `simxPauseSimulation`, `simxStopSimulation`: one code, the
    /// identity saying which (0, 1, 2).
    pub(super) async fn control_simulation(&self) -> Result<Vec<u8>, CommandError> {
        let control = match id_int(self.cmd) {
            0 => Control::Start,
            1 => Control::Pause,
            2 => Control::Stop,
            other => return Err(CommandError::UnknownControl(other)),
        };
        self.remote(RemoteOp::Control(control)).await?;
        Ok(Vec::new())
    }

    /// `simxGetLastErrors`: the count, then each message NUL-terminated. Reading them is
    /// not itself an error to report.
    pub(super) fn take_errors(&mut self) -> Vec<u8> {
        let errors = std::mem::take(&mut self.session.errors);
        let mut out = Vec::new();
        put_count(&mut out, errors.len());
        for e in errors {
            put_string(&mut out, &e);
        }
        out
    }

    /// `simxFinish`'s command: the transport closes the connection after this reply.
    pub(super) fn kill(&mut self) -> Vec<u8> {
        self.session.killed = true;
        Vec::new()
    }
}
