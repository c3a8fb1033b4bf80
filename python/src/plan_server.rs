//! Where a vector environment's worker thread waits, outside Python, for the next
//! batch of step plans.
//!
//! Why: a client's simulation belongs to the thread that made it (its Lua state cannot
//! move), so each worker thread of `gantry.vector.VectorEnv` keeps its block of
//! simulations for life. Driving it with Python commands (a queue, then
//! `Engine.run_plans`) costs two GIL hand-overs and two thread wake-ups per vector step,
//! a few hundred microseconds on a 2-core VM: more than a block of cheap steps (the
//! kinematic arm of ArmReach: 16 us an env). Parked here instead
//! (`Engine.serve_plans`), the worker takes each batch of actions from a channel and
//! runs its plans without ever taking the GIL; the caller's thread sends the actions
//! (`step`), runs its own block meanwhile, collects the numbers (`collect`) and does
//! the Python part of every block itself. `release` sends the worker back to Python
//! (for a reset, an attribute, closing).
//!
//! The server holds only channels: the simulations stay on their thread, borrowed by
//! `serve` for as long as it runs.

use std::sync::Mutex;
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender, channel};
use std::time::Duration;

use numpy::{PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyException, PyRuntimeError, PyValueError};
use pyo3::prelude::*;

use crate::direct::Direct;
use crate::plan::{self, StepPlan};

/// What the caller's thread asks of the parked worker.
enum Request {
    /// One action per simulation: `actions` holds the rows, `width` values each; `seq`
    /// comes back with the reply.
    Step { seq: u64, actions: Vec<f32>, width: usize },
    /// Back to Python.
    Release,
}

/// The request's `seq` and its batch's observed numbers, one row per simulation, or
/// the first failure: its message and the position of the simulation that failed.
type Reply = (u64, Result<Vec<Vec<f64>>, (String, usize)>);

/// A parked worker's two channels (see the module docs).
#[pyclass(frozen, module = "gantry._gantry")]
pub struct PlanServer {
    requests: Sender<Request>,
    incoming: Mutex<Receiver<Request>>,
    replies: Sender<Reply>,
    outgoing: Mutex<Receiver<Reply>>,
}

#[pymethods]
impl PlanServer {
    #[new]
    fn new() -> Self {
        let (requests, incoming) = channel();
        let (replies, outgoing) = channel();
        Self {
            requests,
            incoming: Mutex::new(incoming),
            replies,
            outgoing: Mutex::new(outgoing),
        }
    }

    /// Sends the worker its simulations' actions, one `float32` row each, in the order
    /// its simulations were given to `Engine.serve_plans`, numbered `seq`. Returns at
    /// once.
    fn step(&self, seq: u64, actions: PyReadonlyArray2<'_, f32>) -> PyResult<()> {
        let width = actions.shape()[1];
        let actions = actions.as_slice()?.to_vec();
        self.requests
            .send(Request::Step { seq, actions, width })
            .map_err(|_| PyRuntimeError::new_err("the plan server is gone"))
    }

    /// The numbers of batch `seq`, as a `(n, m)` `float64` array, waiting with the GIL
    /// released; `None` if they have not come within `timeout` seconds (the caller then
    /// checks that the worker is alive and asks again). Replies to earlier batches (whose
    /// caller was interrupted) are dropped. A failed plan raises an `Exception` whose
    /// `args` are `(message, position)`.
    fn collect<'py>(&self, py: Python<'py>, seq: u64, timeout: f64) -> PyResult<Option<Bound<'py, PyAny>>> {
        let wait = Duration::try_from_secs_f64(timeout).map_err(|e| PyValueError::new_err(format!("timeout: {e}")))?;
        let reply = py.detach(|| {
            let outgoing = self.outgoing.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
            loop {
                match outgoing.recv_timeout(wait) {
                    Ok((got, reply)) if got == seq => return Ok(reply),
                    Ok(_) => continue,
                    Err(e) => return Err(e),
                }
            }
        });
        let rows = match reply {
            Ok(Ok(rows)) => rows,
            Ok(Err((message, k))) => return Err(PyException::new_err((message, k))),
            Err(RecvTimeoutError::Timeout) => return Ok(None),
            Err(RecvTimeoutError::Disconnected) => return Err(PyRuntimeError::new_err("the plan server is gone")),
        };
        plan::rows_array(py, rows).map(Some)
    }

    /// The worker's side when it cannot serve its plans (a bad argument to
    /// `Engine.serve_plans`): answers each batch with `message` until released, so that
    /// the caller, which has sent one already, hears of it.
    fn refuse(&self, py: Python<'_>, message: &str) {
        py.detach(|| self.serve(&mut [], &[], Some(message)));
    }

    /// Sends the worker back to Python, once it has answered what it was sent before.
    fn release(&self) -> PyResult<()> {
        self.requests
            .send(Request::Release)
            .map_err(|_| PyRuntimeError::new_err("the plan server is gone"))
    }
}

impl PlanServer {
    /// The worker's side, the GIL released: runs `plans[k]` on `sims[k]` for each batch
    /// of actions until told to release. A batch whose rows are too few or too short
    /// for the plans is answered with an error, not run; so is every batch when the
    /// worker could not start serving (`refusal`), so that the caller hears of it.
    pub(crate) fn serve(&self, sims: &mut [&mut Direct], plans: &[&StepPlan], refusal: Option<&str>) {
        let incoming = self.incoming.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        while let Ok(Request::Step { seq, actions, width }) = incoming.recv() {
            let reply = if let Some(why) = refusal {
                Err((why.to_owned(), 0))
            } else if actions.len() != sims.len() * width {
                Err((
                    format!("{} action values for {} plans of {width}", actions.len(), sims.len()),
                    0,
                ))
            } else if let Some(k) = plans.iter().position(|p| p.action_size > width) {
                Err((
                    format!("the plan reads {} action values, got {width}", plans[k].action_size),
                    k,
                ))
            } else {
                for d in sims.iter_mut() {
                    d.settle();
                }
                let work: Vec<(&StepPlan, &[f32])> = plans.iter().copied().zip(actions.chunks(width.max(1))).collect();
                Direct::plans_detached(sims, &work).map_err(|(k, e)| (e.to_string(), k))
            };
            if self.replies.send((seq, reply)).is_err() {
                return;
            }
        }
    }
}
