//! The simulation on gantry's own simulation thread, with its listeners (viewer, text
//! channel, ZMQ remote API) open, so that a run driven from Python can be watched and
//! joined by other clients. The Python client is then one more client of that thread:
//! its calls travel as the ZMQ transport's do ([`Request`]s), minus the bytes, and it
//! has its own stepping level beside theirs.

use gantry_engine::{ClientId, HostCall};
use gantry_server::sim_thread::{Request, SendError, SimHandle};
use gantry_server::{BoundAddrs, Running};
use gantry_sim_core::Value;
use gantry_sim_core::api::{CallError, Target};
use pyo3::{PyErr, Python};
use std::time::{Duration, Instant};

use tokio::sync::oneshot;

/// The Python client's id among the remote clients; the ZMQ transport counts from 1.
const ME: ClientId = ClientId(u64::MAX);

/// Why a call from Python to the served simulation failed; the text is the Python
/// exception's message.
#[derive(Debug, thiserror::Error)]
pub enum ServedError {
    /// The simulation thread did not take the request.
    #[error("{source} (in function '{function}')")]
    Send {
        /// The function called, e.g. `sim.step`.
        function: String,
        /// Why the request was not taken.
        source: SendError,
    },
    /// The simulation thread ended before answering.
    #[error("the simulation has ended (in function '{0}')")]
    Ended(String),
    /// A Python signal (Ctrl-C) arrived while waiting: the handler's exception.
    #[error("{error} (in function '{function}')")]
    Interrupted {
        /// The function called.
        function: String,
        /// The exception the signal handler raised.
        error: PyErr,
    },
    /// The function itself failed: its CoppeliaSim-style message.
    #[error(transparent)]
    Call(#[from] CallError),
}

/// A simulation thread with listeners, driven from Python.
pub struct Served {
    running: Option<Running>,
    handle: SimHandle,
}

impl Served {
    /// Wraps a started run (see [`gantry_server::start`]).
    pub fn new(running: Running) -> Self {
        let handle = running.handle();
        Self {
            running: Some(running),
            handle,
        }
    }

    /// The addresses the listeners bound.
    pub fn bound(&self) -> Option<&BoundAddrs> {
        self.running.as_ref().map(Running::bound)
    }

    /// Sends a request built around a reply channel and waits for the answer with the
    /// GIL released, checking for Ctrl-C now and then (a `sim.step()` may wait as long
    /// as another client holds the simulation).
    fn ask<T: Send>(
        &self,
        py: Python<'_>,
        name: &str,
        make: impl FnOnce(oneshot::Sender<T>) -> Request,
    ) -> Result<T, ServedError> {
        use tokio::sync::oneshot::error::TryRecvError;
        let (reply, mut rx) = oneshot::channel();
        self.handle.send(make(reply)).map_err(|source| ServedError::Send {
            function: name.to_owned(),
            source,
        })?;
        let started = Instant::now();
        loop {
            match rx.try_recv() {
                Ok(v) => return Ok(v),
                Err(TryRecvError::Closed) => return Err(ServedError::Ended(name.to_owned())),
                Err(TryRecvError::Empty) => {}
            }
            // Most answers come within tens of microseconds: yield at first, then sleep
            // so that a long wait costs no CPU.
            let pause = if started.elapsed() < Duration::from_millis(2) {
                Duration::ZERO
            } else {
                Duration::from_millis(1)
            };
            py.detach(|| {
                if pause.is_zero() {
                    std::thread::yield_now();
                } else {
                    std::thread::sleep(pause);
                }
            });
            if started.elapsed() > Duration::from_millis(50) {
                py.check_signals().map_err(|error| ServedError::Interrupted {
                    function: name.to_owned(),
                    error,
                })?;
            }
        }
    }

    /// A core or script-host function, served on the simulation thread as the ZMQ
    /// transport's calls are.
    ///
    /// # Errors
    /// The CoppeliaSim-style message.
    pub fn call(&self, py: Python<'_>, target: Target, args: &[Value]) -> Result<Vec<Value>, ServedError> {
        let args = args.to_vec();
        Ok(self.ask(py, &target.qualified(), |reply| Request::Call { target, args, reply })??)
    }

    /// Simulation control and stepping, as the ZMQ transport serves them.
    ///
    /// # Errors
    /// Nesting too deep, a scene that does not load, or an ended run.
    pub fn host(&self, py: Python<'_>, qualified: &str, call: HostCall) -> Result<Vec<Value>, ServedError> {
        match call {
            HostCall::Remote(op) => {
                Ok(self.ask(py, qualified, |reply| Request::Remote { client: ME, op, reply })??)
            }
            // The Python client always waits: its calls are synchronous.
            HostCall::Step { .. } => {
                self.ask(py, qualified, |done| Request::Step { client: ME, done })?;
                Ok(Vec::new())
            }
            HostCall::LoadScene(path) => Ok(self.ask(py, qualified, |reply| Request::LoadScene { path, reply })??),
        }
    }

    /// Ends the run: cleanup hooks, listeners closed.
    pub fn close(&mut self, py: Python<'_>) {
        if let Some(running) = self.running.take() {
            py.detach(|| end(running, &self.handle));
        }
    }
}

/// A served client dropped without `close()` still ends its run, so no simulation thread
/// is left running (the thread needs no GIL to finish).
impl Drop for Served {
    fn drop(&mut self) {
        if let Some(running) = self.running.take() {
            end(running, &self.handle);
        }
    }
}

/// Stops a run and waits for its threads: cleanup hooks, listeners closed.
fn end(running: Running, handle: &SimHandle) {
    running.stop();
    let _ = handle.send(Request::DropClient(ME));
    if let Err(e) = running.wait() {
        tracing::error!("the served simulation ended with an error: {e}");
    }
}
