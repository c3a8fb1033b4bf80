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

use std::path::Path;
use std::time::{Duration, Instant};

use gantry_script::{ScriptLimits, Simulation};
use gantry_server::ClientId;
use gantry_server::RemoteOp;
use gantry_server::stepping::Stepping;
use gantry_server::zmq::{HostCall, HostFn};
use gantry_sim_core::Value;
use gantry_sim_core::api::ApiFunction;
use gantry_sim_core::scene::{LoadOptions, SceneModel, load_client_scene};
use gantry_sim_core::sim::Control;
use gantry_sim_core::sim::SimulationState;
use pyo3::Python;

/// Whether a registry function may take long enough (rendering, IK, collision and
/// distance queries) to be worth releasing the GIL for; the quick ones (a pose, a
/// signal) keep it, since releasing and retaking it costs more than they do.
fn releases_gil(qualified: &str) -> bool {
    qualified.starts_with("simIK.")
        || qualified.starts_with("simVision.")
        || ["Vision", "handle", "check", "IK"]
            .iter()
            .any(|k| qualified.contains(k))
}

/// The one client of an in-process simulation, for the stepping rules shared with the
/// remote API ([`Stepping`]).
const ME: ClientId = ClientId(0);

/// How often scripts' `sysCall_nonSimulation` runs while the simulation is stopped
/// (as the binary's simulation thread does), checked at each call.
const NON_SIMULATION_PERIOD: Duration = Duration::from_millis(50);

/// A simulation owned by the calling thread.
pub struct Direct {
    sim: Simulation,
    stepping: Stepping,
    /// Steps taken in this client's lifetime (never reset), for [`Stepping`].
    steps: u64,
    /// Without stepping: advance with the wall clock (true) or only on `sim.step()`.
    realtime: bool,
    /// Real-time pacing: when free running began and how many steps were taken since.
    pace: Option<(Instant, u64)>,
    last_idle: Instant,
    limits: ScriptLimits,
    load_options: LoadOptions,
}

/// A `&mut` crossing [`Python::detach`], whose `Send` bound is there to keep
/// GIL-bound Python references out of the closure. The simulation holds none (its Lua
/// state and world are plain Rust), and `detach` runs the closure at once on this same
/// thread, so the value never actually moves to another thread: that is what makes
/// the assertion sound. The pyclass that owns the simulation is `unsendable`, so
/// no other thread can reach it while the GIL is released.
struct OnThisThread<'a>(&'a mut Direct);

// SAFETY: see the type's comment: the closure runs synchronously on the owning thread.
unsafe impl Send for OnThisThread<'_> {}

impl OnThisThread<'_> {
    /// The wrapped value. A method, not a field access, so that closures capture the
    /// whole (Send) wrapper rather than its non-Send field.
    fn get(&mut self) -> &mut Direct {
        self.0
    }
}

impl Direct {
    /// Creates the simulation of `model`; started at once when `autostart` (as
    /// `gantry run` does).
    ///
    /// # Errors
    /// The Lua state could not be created.
    pub fn new(
        py: Python<'_>,
        model: SceneModel,
        limits: ScriptLimits,
        load_options: LoadOptions,
        autostart: bool,
        realtime: bool,
    ) -> Result<Self, String> {
        let mut sim = Simulation::new(model, limits).map_err(|e| e.to_string())?;
        sim.set_load_options(load_options.clone());
        let mut d = Self {
            sim,
            stepping: Stepping::default(),
            steps: 0,
            realtime,
            pace: None,
            last_idle: Instant::now(),
            limits,
            load_options,
        };
        if autostart {
            d.detached(py, |d| d.sim.start());
            d.sync_state(SimulationState::Stopped);
        }
        Ok(d)
    }

    /// Runs `f` with the GIL released, so that other Python threads (and other
    /// simulations in them) run meanwhile.
    fn detached<R: Send>(&mut self, py: Python<'_>, f: impl FnOnce(&mut Direct) -> R + Send) -> R {
        let mut this = OnThisThread(self);
        py.detach(move || f(this.get()))
    }

    /// A registry function, looked up once when the module was built.
    ///
    /// # Errors
    /// The CoppeliaSim-style message, qualified with `qualified`.
    pub fn call_function(
        &mut self,
        py: Python<'_>,
        f: &ApiFunction,
        qualified: &str,
        args: &[Value],
    ) -> Result<Vec<Value>, String> {
        self.before_call(py);
        let out = if releases_gil(qualified) {
            self.detached(py, |d| d.sim.call_function(f, args))
        } else {
            self.sim.call_function(f, args)
        };
        out.map_err(|e| e.in_function(qualified))
    }

    /// A function the Lua host implements (`getScript`, `callScriptFunction`, ...).
    ///
    /// # Errors
    /// The CoppeliaSim-style message.
    pub fn call_named(&mut self, py: Python<'_>, name: &str, args: &[Value]) -> Result<Vec<Value>, String> {
        self.before_call(py);
        // A called script function may run for a while (up to the script time budget),
        // and may start, pause or stop the simulation.
        let before = self.sim.state();
        let out = self.detached(py, |d| d.sim.call(name, args));
        self.sync_state(before);
        // The edge: the structured error becomes CoppeliaSim's text here.
        out.map_err(|e| e.to_string())
    }

    /// Simulation control and stepping (`sim.startSimulation`, `sim.step`, ...).
    ///
    /// # Errors
    /// Bad arguments, nesting too deep, or a scene that does not load.
    pub fn host(&mut self, py: Python<'_>, f: HostFn, name: &str, args: &[Value]) -> Result<Vec<Value>, String> {
        let in_function = |e: &dyn std::fmt::Display| format!("{e} (in function 'sim.{name}')");
        self.before_call(py);
        let before = self.sim.state();
        match HostCall::parse(f, args).map_err(|e| e.to_string())? {
            // Not re-paced below: the step keeps the real-time schedule it follows. The
            // Python client always waits (its calls are synchronous).
            HostCall::Step { .. } => {
                if self.stepping.holds_lock(ME) {
                    // The remote API would wait for ever: the lock holds the simulation.
                    return Err(in_function(
                        &"this client holds sim.acquireLock: release it before stepping",
                    ));
                }
                self.step(py);
                return Ok(Vec::new());
            }
            HostCall::LoadScene(path) => self.load_scene(py, path.as_deref()).map_err(|e| in_function(&e))?,
            HostCall::Remote(RemoteOp::Control(Control::Start)) => self.detached(py, |d| d.sim.start()),
            HostCall::Remote(RemoteOp::Control(Control::Pause)) => {
                self.sim.pause();
                self.stepping.release_waiters();
            }
            HostCall::Remote(RemoteOp::Control(Control::Stop)) => self.stop(py),
            HostCall::Remote(RemoteOp::Lock(acquire)) => {
                self.stepping.lock(ME, acquire).map_err(|e| in_function(&e))?;
            }
            HostCall::Remote(RemoteOp::SetStepping(enable)) => {
                let previous = self
                    .stepping
                    .set_stepping(ME, enable, self.steps)
                    .map_err(|e| in_function(&e))?;
                return Ok(vec![Value::Int(i64::from(previous))]);
            }
        }
        self.sync_state(before);
        Ok(Vec::new())
    }

    /// `sim.step()`: with stepping, one step; free running in real time, waits for the
    /// next step that is due (as a remote client parked in `sim.step()` does); stopped
    /// or paused, returns at once.
    pub fn step(&mut self, py: Python<'_>) {
        if self.sim.state() != SimulationState::Running {
            return;
        }
        if self.stepping.any_stepping() || !self.realtime {
            self.run_steps(py, 1);
            return;
        }
        // Free running: sleep until the next step is due, then take it.
        let dt = self.sim.world().settings().dt;
        let (origin, paced) = *self.pace.get_or_insert((Instant::now(), 0));
        let next = origin + Duration::from_secs_f64(paced as f64 * dt);
        let wait = next.saturating_duration_since(Instant::now());
        if !wait.is_zero() {
            py.detach(|| std::thread::sleep(wait));
        }
        self.catch_up(py);
    }

    /// Stop: cleanup hooks, the initial scene back, stepping levels reset.
    fn stop(&mut self, py: Python<'_>) {
        let before = self.sim.state();
        self.detached(py, |d| d.sim.stop());
        // A stop resets the stepping levels, as the remote API's does, even when the
        // simulation was stopped already.
        self.stepping.stopped();
        self.sync_state(before);
    }

    /// After anything that may have started, paused or stopped the simulation or
    /// changed the stepping (a control call, a script's `sim.stopSimulation()`), given
    /// the state `before` it: a change to stopped or paused is followed by the stepping
    /// rules, as for remote clients (a call made while stopped leaves the levels alone),
    /// and real-time pacing starts afresh from now when the simulation runs free, so
    /// the wall time since counts.
    fn sync_state(&mut self, before: SimulationState) {
        let now = self.sim.state();
        if now != before {
            match now {
                SimulationState::Stopped => self.stepping.stopped(),
                SimulationState::Paused => self.stepping.release_waiters(),
                SimulationState::Running => {}
            }
        }
        self.pace = self.free_running().then(|| (Instant::now(), 0));
    }

    /// Running, in real time, held by no stepping level or lock.
    fn free_running(&self) -> bool {
        self.realtime
            && self.sim.state() == SimulationState::Running
            && !self.stepping.any_stepping()
            && self.stepping.may_advance(self.steps)
    }

    /// Replaces the scene; one that does not load leaves the current one as it was.
    fn load_scene(&mut self, py: Python<'_>, path: Option<&Path>) -> Result<(), String> {
        let options = self.load_options.clone();
        let limits = self.limits;
        let model = py.detach(|| load_client_scene(path, &options))?;
        let mut sim = Simulation::new(model, limits).map_err(|e| e.to_string())?;
        sim.set_load_options(options);
        self.stop(py);
        self.sim = sim;
        Ok(())
    }

    /// What happens between calls: due real-time steps, or the stopped simulation's
    /// `sysCall_nonSimulation`.
    fn before_call(&mut self, py: Python<'_>) {
        match self.sim.state() {
            SimulationState::Running => self.catch_up(py),
            SimulationState::Stopped if self.last_idle.elapsed() >= NON_SIMULATION_PERIOD => {
                self.last_idle = Instant::now();
                self.sim.non_simulation();
            }
            _ => {}
        }
    }

    /// Free running in real time: takes the steps the wall clock says are due, at most
    /// one simulated second's worth per call (a simulation slower than real time then
    /// falls behind instead of stalling the caller).
    fn catch_up(&mut self, py: Python<'_>) {
        if !self.free_running() {
            self.pace = None;
            return;
        }
        let dt = self.sim.world().settings().dt;
        let (origin, paced) = *self.pace.get_or_insert((Instant::now(), 0));
        // Step k is due at origin + k dt, the first at once: as the binary's loop paces.
        let due = (origin.elapsed().as_secs_f64() / dt) as u64 + 1;
        let n = due.saturating_sub(paced);
        if n == 0 {
            return;
        }
        let cap = (1.0 / dt).ceil().max(1.0) as u64;
        let taken = self.run_steps(py, n.min(cap));
        self.pace = if n > cap { None } else { Some((origin, paced + taken)) };
    }

    /// Takes up to `n` steps with the GIL released; fewer when a script pauses or stops
    /// the simulation. Returns how many were taken.
    fn run_steps(&mut self, py: Python<'_>, n: u64) -> u64 {
        let taken = self.detached(py, |d| {
            let mut taken = 0;
            while taken < n && d.sim.state() == SimulationState::Running {
                d.sim.step();
                d.steps += 1;
                taken += 1;
            }
            taken
        });
        self.stepping.stepped(self.steps);
        // A script may have paused or stopped the simulation (`sim.stopSimulation()`):
        // stepping follows, as it does for remote clients.
        if self.sim.state() != SimulationState::Running {
            self.sync_state(SimulationState::Running);
        }
        taken
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
        let before = self.sim.state();
        if before != SimulationState::Running {
            self.detached(py, |d| d.sim.start());
        }
        let mut taken = 0;
        while taken < n && self.sim.state() == SimulationState::Running {
            let batch = (n - taken).min(BATCH);
            taken += self.run_steps(py, batch);
            py.check_signals()?;
        }
        self.sync_state(before);
        Ok(taken)
    }

    /// Cleanup hooks, once, when the client closes.
    pub fn close(&mut self) {
        self.sim.cleanup();
    }
}

/// A client dropped without `close()` (garbage collected on its own thread) still ends
/// its simulation properly: `sysCall_cleanup` runs (a second cleanup does nothing).
impl Drop for Direct {
    fn drop(&mut self) {
        self.sim.cleanup();
    }
}
