//! The simulation in the caller's own thread: every `sim.*` call is a function call,
//! with no queue and no other thread in between (a few hundred nanoseconds of work).
//!
//! The Python thread that created the client plays the part the simulation thread
//! plays in the binary: it steps, and it answers calls. Remote-API semantics are kept:
//! `sim.setStepping(True)` holds the simulation until `sim.step()`; without stepping the
//! simulation runs free in real time, which in-process means that each call first
//! takes the steps the wall clock says are due (so a loop polling
//! `sim.getSimulationTime()` sees time pass, as against a running CoppeliaSim).

#![allow(unsafe_code, reason = "one Send assertion, for Python::detach; see OnThisThread")]

use gantry_sim_core::SimError;
use std::path::Path;
use std::time::Instant;

use gantry_engine::{ClientId, Due, Engine, EngineConfig, HostCall, RemoteOp};
use gantry_lua::ScriptError;
use gantry_record::{RecordTap, Recorder};
use gantry_sim_core::Value;
use gantry_sim_core::api::{CallError, ScriptHostFn, Target};
use gantry_sim_core::scene::SceneModel;
use gantry_sim_core::sim::{Control, SimulationState};
use pyo3::Python;

use crate::plan::{StepPlan, push_numbers};

/// The one client of an in-process simulation, for the stepping rules shared with the
/// remote API.
const ME: ClientId = ClientId(0);

/// A simulation owned by the calling thread, driven through the engine every front
/// end shares.
pub struct Direct {
    engine: Engine,
}

/// A `&mut` to a simulation (or to several: a vector environment's block, all made
/// by this thread) crossing [`Python::detach`], whose `Send` bound is there to keep
/// GIL-bound Python references out of the closure. The simulation holds none (its Lua
/// state and world are plain Rust), and `detach` runs the closure at once on this same
/// thread, so the value never actually moves to another thread: that is what makes
/// the assertion sound. The pyclass that owns the simulation is `unsendable`, so
/// no other thread can reach it while the GIL is released.
struct OnThisThread<'a, T: ?Sized>(&'a mut T);

// SAFETY: see the type's comment: the closure runs synchronously on the owning thread.
// Only `Direct` and slices of `&mut Direct` are wrapped (the functions below).
unsafe impl<T: ?Sized> Send for OnThisThread<'_, T> {}

impl<T: ?Sized> OnThisThread<'_, T> {
    /// The wrapped value. A method, not a field access, so that closures capture the
    /// whole (Send) wrapper rather than its non-Send field.
    fn get(&mut self) -> &mut T {
        self.0
    }
}

impl Direct {
    /// Creates the simulation of `model`; started at once when `autostart` (as
    /// `gantry run` does); recorded by `recorder` when given.
    ///
    /// # Errors
    /// The Lua state could not be created.
    pub fn new(
        py: Python<'_>,
        model: SceneModel,
        config: EngineConfig,
        autostart: bool,
        recorder: Option<Recorder>,
        ros_graph: Option<gantry_ros2::RosGraph>,
    ) -> Result<Self, ScriptError> {
        let mut engine = Engine::new(model, config, None)?;
        if let Some(g) = ros_graph {
            engine.add_observer(Box::new(g));
        }
        if let Some(r) = recorder {
            // Before the start, so that the start is the recording's first input.
            let tap = RecordTap::new(r, engine.sim());
            engine.set_tap(Box::new(tap));
        }
        let mut d = Self { engine };
        if autostart {
            d.detached(py, |d| d.engine.control(Control::Start));
        }
        Ok(d)
    }

    /// Runs `f` with the GIL released, so that other Python threads (and other
    /// simulations in them) run meanwhile.
    fn detached<R: Send>(&mut self, py: Python<'_>, f: impl FnOnce(&mut Direct) -> R + Send) -> R {
        let mut this = OnThisThread(self);
        py.detach(move || f(this.get()))
    }

    /// A core or script-host function, resolved once when the function object was
    /// made. `release_gil` says whether it may take long enough (rendering, IK, script
    /// code) to be worth releasing the GIL for; the quick ones (a pose, a signal) keep
    /// it, since releasing and retaking it costs more than they do.
    ///
    /// # Errors
    /// The CoppeliaSim-style message.
    pub fn call(
        &mut self,
        py: Python<'_>,
        target: &Target,
        release_gil: bool,
        args: &[Value],
    ) -> Result<Vec<Value>, CallError> {
        self.before_call(py);
        if let Target::ScriptHost(f) = *target
            && f.blocks()
        {
            return self.call_blocking(py, f, args);
        }
        if release_gil {
            self.detached(py, |d| d.engine.call(target, args))
        } else {
            self.engine.call(target, args)
        }
    }

    /// A blocking call (`sim.wait`, `sim.moveToConfig`, ...): this client owns the loop,
    /// so it takes the steps the call waits for itself, paced as its `sim.step()` is (in
    /// real time when free running, at once when stepping or not in real time), with
    /// the GIL released. `sim.wait(dt, false)` waits `dt` seconds of wall-clock time.
    fn call_blocking(&mut self, py: Python<'_>, f: ScriptHostFn, args: &[Value]) -> Result<Vec<Value>, CallError> {
        if f == ScriptHostFn::Wait && args.get(1) == Some(&Value::Bool(false)) {
            let dt = match args.first().and_then(Value::as_f64) {
                Some(dt) if dt.is_finite() => dt.clamp(0.0, 86_400.0),
                _ => {
                    return Err(CallError::failed(
                        "sim.wait",
                        SimError::bad_argument("argument 1: expected number"),
                    ));
                }
            };
            let start = Instant::now();
            py.detach(|| std::thread::sleep(std::time::Duration::from_secs_f64(dt)));
            return Ok(vec![Value::Float((dt - start.elapsed().as_secs_f64()).min(0.0))]);
        }
        let (reply, mut answer) = tokio::sync::oneshot::channel();
        self.detached(py, |d| d.engine.call_blocking(None, f, args, reply));
        loop {
            match answer.try_recv() {
                Ok(out) => return out,
                Err(tokio::sync::oneshot::error::TryRecvError::Closed) => {
                    return Err(CallError::failed(
                        format!("sim.{}", f.name()),
                        SimError::refused("the simulation ended before the call returned"),
                    ));
                }
                Err(tokio::sync::oneshot::error::TryRecvError::Empty) => {}
            }
            if self.engine.state() != SimulationState::Running {
                // Paused: nothing this client does will take the call further.
                return Err(CallError::failed(
                    format!("sim.{}", f.name()),
                    SimError::refused("the simulation is paused: the call waits for steps that will not come"),
                ));
            }
            py.check_signals().map_err(|e| {
                CallError::failed(
                    format!("sim.{}", f.name()),
                    SimError::refused(format!("interrupted: {e}")),
                )
            })?;
            if self.engine.on_demand() || !self.engine.realtime() {
                self.run_steps(py, 1);
            } else {
                self.step(py);
            }
        }
    }

    /// Simulation control and stepping (`sim.startSimulation`, `sim.step`, ...).
    ///
    /// # Errors
    /// Bad arguments, nesting too deep, or a scene that does not load.
    pub fn host(&mut self, py: Python<'_>, call: HostCall) -> Result<Vec<Value>, CallError> {
        self.before_call(py);
        match call {
            // The Python client always waits (its calls are synchronous).
            HostCall::Step { .. } => {
                if self.engine.holds_lock(ME) {
                    // The remote API would wait for ever: the lock holds the simulation.
                    return Err(CallError::failed(
                        "sim.step",
                        SimError::refused("this client holds sim.acquireLock: release it before stepping"),
                    ));
                }
                self.step(py);
                Ok(Vec::new())
            }
            HostCall::LoadScene(path) => self.load_scene(py, path.as_deref()).map(|()| Vec::new()),
            HostCall::Remote(op @ RemoteOp::Control(_)) => self.detached(py, |d| d.engine.remote(ME, op)),
            HostCall::Remote(op) => self.engine.remote(ME, op),
        }
    }

    /// `sim.step()`: with stepping (or not in real time), one step; free running in
    /// real time, waits for the next step that is due (as a remote client parked in
    /// `sim.step()` does); stopped or paused, returns at once.
    pub fn step(&mut self, py: Python<'_>) {
        if self.engine.state() != SimulationState::Running {
            return;
        }
        if self.engine.on_demand() || !self.engine.realtime() {
            self.run_steps(py, 1);
            return;
        }
        if let Due::At(t) = self.engine.due(Instant::now()) {
            py.detach(|| std::thread::sleep(t.saturating_duration_since(Instant::now())));
        }
        self.catch_up(py);
    }

    /// Replaces the scene; one that does not load leaves the current one as it was.
    fn load_scene(&mut self, py: Python<'_>, path: Option<&Path>) -> Result<(), CallError> {
        self.detached(py, |d| d.engine.load_scene(path))
    }

    /// What happens between calls: the steps real time says are due, or the stopped
    /// simulation's periodic hooks.
    fn before_call(&mut self, py: Python<'_>) {
        match self.engine.state() {
            SimulationState::Running => self.catch_up(py),
            _ => self.settle(),
        }
    }

    /// What a call does first on a simulation that is not running (the engine's
    /// housekeeping: recording requests, changed scripts, `sysCall_nonSimulation`); no
    /// GIL needed.
    pub(crate) fn settle(&mut self) {
        if self.engine.state() != SimulationState::Running {
            self.engine.tick(Instant::now());
        }
    }

    /// Free running in real time: takes the steps the wall clock says are due (at most
    /// a simulated second's worth: a simulation slower than real time then falls
    /// behind instead of stalling the caller).
    fn catch_up(&mut self, py: Python<'_>) {
        if !self.paced() {
            return;
        }
        let n = self.engine.due_steps(Instant::now());
        if n > 0 {
            self.run_steps(py, n);
        }
    }

    /// Takes up to `n` steps with the GIL released; fewer when a script pauses or stops
    /// the simulation. Returns how many were taken. The caller has checked that the
    /// steps may be taken (this client's own `sim.step()` is what releases its
    /// stepping level).
    fn run_steps(&mut self, py: Python<'_>, n: u64) -> u64 {
        self.detached(py, |d| {
            let mut taken = 0;
            while taken < n && d.engine.state() == SimulationState::Running {
                d.engine.step();
                taken += 1;
            }
            taken
        })
    }

    /// Steps `n` times as fast as possible whatever the stepping mode (stopped: starts
    /// first). Returns the steps taken. The fast path for training loops and benchmarks.
    /// Ctrl-C interrupts it between batches of steps.
    ///
    /// # Errors
    /// `KeyboardInterrupt` (or another signal's exception) raised meanwhile.
    pub fn advance(&mut self, py: Python<'_>, n: u64) -> pyo3::PyResult<u64> {
        /// Steps between checks for a signal: a few milliseconds of bubble_rob.
        const BATCH: u64 = 16;
        if self.engine.state() != SimulationState::Running {
            self.detached(py, |d| d.engine.control(Control::Start));
        }
        let mut taken = 0;
        while taken < n && self.engine.state() == SimulationState::Running {
            let batch = (n - taken).min(BATCH);
            taken += self.run_steps(py, batch);
            py.check_signals()?;
        }
        // Steps taken outside the real-time schedule: it starts afresh from now.
        self.engine.restart_pacing(Instant::now());
        Ok(taken)
    }

    /// One action of a step plan with the GIL released throughout: the act calls, up to
    /// `plan.steps` steps (fewer if the simulation stops), the observe calls. Returns the
    /// observation's numbers. The calls and steps are those the task's own `sim.*` calls
    /// and `sim.step()` would make, without the Python between them.
    ///
    /// # Errors
    /// A call's error (CoppeliaSim-style message), or an observe call whose reply is
    /// not numbers.
    pub fn run_plan(&mut self, py: Python<'_>, plan: &StepPlan, action: &[f32]) -> Result<Vec<f64>, CallError> {
        self.before_call(py);
        self.detached(py, |d| d.plan_step(plan, action))
    }

    /// [`Direct::run_plan`] on several simulations of this thread, one after the other,
    /// with the GIL released once for all: a vector environment's worker hands the GIL
    /// over twice per batch instead of twice per environment. `work[k]` is the plan and
    /// action of `sims[k]`. Stops at the first error, returned with its position.
    ///
    /// # Errors
    /// As [`Direct::run_plan`], with the index of the simulation that failed.
    pub fn run_plans(
        py: Python<'_>,
        sims: &mut [&mut Direct],
        work: &[(&StepPlan, &[f32])],
    ) -> Result<Vec<Vec<f64>>, (usize, CallError)> {
        for d in sims.iter_mut() {
            d.before_call(py);
        }
        Self::detached_all(py, sims, |sims| Self::plans_detached(sims, work))
    }

    /// `f` on several simulations of this thread with the GIL released.
    pub(crate) fn detached_all<R: Send>(
        py: Python<'_>,
        sims: &mut [&mut Direct],
        f: impl FnOnce(&mut [&mut Direct]) -> R + Send,
    ) -> R {
        let mut all = OnThisThread(sims);
        py.detach(move || f(all.get()))
    }

    /// [`Direct::run_plans`] for a caller that has released the GIL already (a parked
    /// vector-env worker, `plan_server`), which has done what `before_call` does: it
    /// checked that none of its simulations paces itself ([`Direct::paced`]), and settles
    /// each ([`Direct::settle`]).
    ///
    /// # Errors
    /// As [`Direct::run_plans`].
    pub(crate) fn plans_detached(
        sims: &mut [&mut Direct],
        work: &[(&StepPlan, &[f32])],
    ) -> Result<Vec<Vec<f64>>, (usize, CallError)> {
        sims.iter_mut()
            .zip(work)
            .enumerate()
            .map(|(k, (d, (plan, action)))| d.plan_step(plan, action).map_err(|e| (k, e)))
            .collect()
    }

    /// Whether this simulation follows the wall clock (free running in real time), so
    /// that a call must first take the steps that are due.
    pub(crate) fn paced(&self) -> bool {
        self.engine.realtime() && !self.engine.on_demand()
    }

    /// One action of `plan`, the GIL already released.
    fn plan_step(&mut self, plan: &StepPlan, action: &[f32]) -> Result<Vec<f64>, CallError> {
        for op in &plan.act {
            let mut value = f64::from(action[op.index] * op.scale);
            if let Some(read) = &op.read {
                let reply = self.engine.call(read, std::slice::from_ref(&op.handle))?;
                value += reply.first().and_then(Value::as_f64).ok_or_else(|| {
                    CallError::failed(read.qualified(), SimError::refused("the plan reads a number here"))
                })?;
            }
            self.engine.call(&op.set, &[op.handle.clone(), Value::Float(value)])?;
        }
        if plan.steps > 0 && self.engine.holds_lock(ME) {
            // As sim.step() refuses: the lock holds the simulation.
            return Err(CallError::failed(
                "sim.step",
                SimError::refused("this client holds sim.acquireLock: release it before stepping"),
            ));
        }
        for _ in 0..plan.steps {
            if self.engine.state() != SimulationState::Running {
                break;
            }
            self.engine.step();
        }
        let mut values = Vec::new();
        for op in &plan.observe {
            let reply = self.engine.call(&op.get, &op.args)?;
            push_numbers(&reply, &mut values).ok_or_else(|| {
                CallError::failed(op.get.qualified(), SimError::refused("the plan observes numbers only"))
            })?;
        }
        Ok(values)
    }

    /// Cleanup hooks, once, when the client closes.
    pub fn close(&mut self) {
        self.engine.finish();
    }
}

/// A client dropped without `close()` (garbage collected on its own thread) still ends
/// its simulation properly: `sysCall_cleanup` runs (a second cleanup does nothing).
impl Drop for Direct {
    fn drop(&mut self) {
        self.engine.finish();
    }
}
