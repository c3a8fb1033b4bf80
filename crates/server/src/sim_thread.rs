//! The simulation thread: the only owner of the world and the Lua state.
//!
//! Transports never touch the world. They send [`Request`]s through a bounded channel
//! ([`SimHandle`]) and await the reply on a oneshot. The thread steps the simulation on
//! its real-time schedule and, between steps — including while it waits for the next
//! tick — serves every request as soon as it arrives, so a reply never waits for the
//! next 50 ms step.

use std::collections::VecDeque;
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, SyncSender, TrySendError};
use std::time::{Duration, Instant};

use gantry_script::{ScriptLimits, Simulation, StepBoundary};
use gantry_sim_core::api::{ApiError, CallError};
use gantry_sim_core::scene::SceneModel;
use gantry_sim_core::sim::{Control, SimulationState};
use gantry_sim_core::{Handle, Value, api};
use tokio::sync::oneshot;

use crate::stepping::{ClientId, Stepping, SteppingError};

/// Most requests queued for the simulation thread; beyond this, transports answer
/// "busy" instead of growing memory.
pub const QUEUE_CAPACITY: usize = 4096;
/// How long the simulation thread polls for the next request before parking, and for
/// how long after the last request it keeps doing so. The poll yields the core, so an
/// idle simulator burns nothing and a busy client saves a thread wake-up per call.
const SPIN_FOR: Duration = Duration::from_micros(200);
const SPIN_AFTER_ACTIVITY: Duration = Duration::from_millis(20);

/// A request to the simulation thread.
pub enum Request {
    /// Call `sim.<name>(args)` as a remote client (no emitting object).
    Call {
        /// Function name without `sim.`.
        name: String,
        /// Arguments.
        args: Vec<Value>,
        /// The results or a CoppeliaSim-style error message.
        reply: oneshot::Sender<Result<Vec<Value>, CallError>>,
    },
    /// Deliver a text packet to the scripts' `sysCall_packet(packet)`.
    Packet {
        /// The packet as a table (see `text` module docs).
        packet: Value,
        /// What the scripts answered.
        reply: oneshot::Sender<PacketOutcome>,
    },
    /// Start, pause or stop the simulation, or do a single step while paused.
    Control {
        /// What to do.
        action: LoopControl,
        /// The state afterwards.
        reply: oneshot::Sender<SimulationState>,
    },
    /// A remote API client's simulation control or stepping call (see [`RemoteOp`]).
    Remote {
        /// The client, for per-client stepping levels and locks.
        client: ClientId,
        /// What to do.
        op: RemoteOp,
        /// The results (as for [`Request::Call`]) or a CoppeliaSim-style error message.
        reply: oneshot::Sender<Result<Vec<Value>, CallError>>,
    },
    /// `sim.step()` of a remote client: answered on `done` once the simulation has taken
    /// the next step (at once if it is stopped or paused; see [`crate::stepping`]).
    Step {
        /// The client asking.
        client: ClientId,
        /// Sent to (or dropped, if the simulation ends) when the step is done.
        done: oneshot::Sender<()>,
    },
    /// A remote client left or timed out: forget its stepping level and locks, so it
    /// can no longer hold the simulation.
    DropClient(ClientId),
    /// `sim.loadScene(path)` (`Some`) or `sim.closeScene()` (`None`, an empty scene):
    /// the running simulation stops and the new scene waits, stopped, for a start.
    LoadScene {
        /// The scene file (`.toml`) or URDF, as the client named it.
        path: Option<std::path::PathBuf>,
        /// Empty results, or a CoppeliaSim-style error message.
        reply: oneshot::Sender<Result<Vec<Value>, CallError>>,
    },
    /// Run a closure on the simulation thread (for viewer snapshots and tests).
    With(Box<dyn FnOnce(&mut Simulation) + Send>),
}

/// Remote-API functions that live in the transport layer rather than in the core,
/// because they concern the client or the simulation loop, not the world.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RemoteOp {
    /// `sim.setStepping(enable)`: returns the client's previous stepping level.
    SetStepping(bool),
    /// `sim.startSimulation()` (start, or resume from pause; `sysCall_init` runs on
    /// start), `sim.pauseSimulation()`, `sim.stopSimulation()` (cleanup, initial scene
    /// restored, stepping levels reset).
    Control(Control),
    /// `sim.acquireLock()` (`true`) or `sim.releaseLock()` (`false`).
    Lock(bool),
}

/// What the viewer's buttons and the command line ask of the simulation loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoopControl {
    /// Start or resume, pause, or stop (cleanup hooks run and the scene returns to its
    /// initial state).
    Control(Control),
    /// One step, whatever the state (a stopped simulation starts, then pauses).
    Step,
}

/// What the scripts did with a packet.
#[derive(Debug, Clone, PartialEq)]
pub enum PacketOutcome {
    /// A script returned this string.
    Reply(String),
    /// A script handled it and returned nothing (the transport echoes the packet).
    Handled,
    /// No running script defines `sysCall_packet`.
    NoHandler,
    /// The handling script raised this error.
    Error(String),
}

/// Why a request could not be delivered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum SendError {
    /// The queue is full: the simulation is overloaded.
    #[error("the simulator is busy (request queue full); retry later")]
    Busy,
    /// The simulation thread has ended.
    #[error("the simulation has ended")]
    Closed,
}

/// A cloneable handle to the simulation thread.
#[derive(Clone)]
pub struct SimHandle {
    tx: SyncSender<Request>,
}

impl SimHandle {
    /// Queues a request without blocking.
    ///
    /// # Errors
    /// [`SendError::Busy`] when the queue is full, [`SendError::Closed`] after shutdown.
    pub fn send(&self, req: Request) -> Result<(), SendError> {
        self.tx.try_send(req).map_err(|e| match e {
            TrySendError::Full(_) => SendError::Busy,
            TrySendError::Disconnected(_) => SendError::Closed,
        })
    }

    /// Calls `sim.<name>` and awaits the result.
    ///
    /// # Errors
    /// The call's error message, or why it could not be delivered.
    pub async fn call(&self, name: &str, args: Vec<Value>) -> Result<Vec<Value>, String> {
        let (reply, rx) = oneshot::channel();
        self.send(Request::Call {
            name: name.to_owned(),
            args,
            reply,
        })
        .map_err(|e| e.to_string())?;
        rx.await
            .map_err(|_| SendError::Closed.to_string())?
            .map_err(|e| e.to_string())
    }

    /// Sends a control action and awaits the resulting state.
    ///
    /// # Errors
    /// Why it could not be delivered.
    pub async fn control(&self, action: LoopControl) -> Result<SimulationState, SendError> {
        let (reply, rx) = oneshot::channel();
        self.send(Request::Control { action, reply })?;
        rx.await.map_err(|_| SendError::Closed)
    }

    /// Runs `f` on the simulation thread and awaits its result.
    ///
    /// # Errors
    /// Why it could not be delivered.
    pub async fn with<R: Send + 'static>(
        &self,
        f: impl FnOnce(&mut Simulation) -> R + Send + 'static,
    ) -> Result<R, SendError> {
        let (reply, rx) = oneshot::channel();
        self.send(Request::With(Box::new(move |sim| {
            let _ = reply.send(f(sim));
        })))?;
        rx.await.map_err(|_| SendError::Closed)
    }
}

/// How the simulation thread runs.
#[derive(Debug, Clone, Default)]
pub struct SimConfig {
    /// Stop after this many steps.
    pub steps: Option<u64>,
    /// Step as fast as possible instead of in real time.
    pub fast: bool,
    /// Script time and memory limits.
    pub limits: ScriptLimits,
    /// Start running at once (otherwise wait for a start request).
    pub autostart: bool,
    /// Write every graph stream as CSV into this folder when the run ends.
    pub export_graphs: Option<std::path::PathBuf>,
    /// How scenes loaded later by remote clients (`sim.loadScene`) are read.
    pub load_options: gantry_sim_core::scene::LoadOptions,
    /// The front end's listeners, for scripts' `simRemoteApi.start` (none: scripts
    /// cannot start servers).
    pub listeners: Option<std::sync::Arc<dyn gantry_script::Listeners>>,
}

/// What a finished run reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunSummary {
    /// Steps executed.
    pub steps: u64,
    /// Final simulation time, s.
    pub sim_time: f64,
    /// Wall-clock duration of the run, s.
    pub wall_s: f64,
}

impl RunSummary {
    /// The machine-readable line `steps=N sim_time=S wall_s=W steps_per_s=R rtf=X`.
    pub fn line(&self) -> String {
        let wall = self.wall_s.max(1e-9);
        format!(
            "steps={} sim_time={:.6} wall_s={:.6} steps_per_s={:.1} rtf={:.3}",
            self.steps,
            self.sim_time,
            self.wall_s,
            self.steps as f64 / wall,
            self.sim_time / wall
        )
    }
}

/// Watches the simulation from its own thread, between steps: how the viewer publishes
/// its pose stream without a request per frame.
///
/// [`Observer::observe`] runs on the simulation thread at every turn of its loop (after
/// each step, after each batch of served requests, and at least every 50 ms while
/// paused), so it must be cheap and decide quickly when it has nothing to do.
pub trait Observer {
    /// Looks at the simulation. `run_steps` counts the steps of this run (never reset).
    fn observe(&mut self, sim: &Simulation, run_steps: u64);
}

/// No observer: what [`run_sim_thread`] uses.
impl Observer for () {
    fn observe(&mut self, _: &Simulation, _: u64) {}
}

/// Creates the request channel: the handle for transports and the receiver for
/// [`run_sim_thread`].
pub fn channel() -> (SimHandle, Receiver<Request>) {
    let (tx, rx) = mpsc::sync_channel(QUEUE_CAPACITY);
    (SimHandle { tx }, rx)
}

/// The simulation loop. Runs until `config.steps` is reached, `should_stop` returns
/// true, or every [`SimHandle`] is dropped. Runs cleanup hooks before returning.
///
/// The simulation advances only when [`Stepping`] allows it (no remote client holds it
/// back). While some client is stepping, steps are taken as soon as they are asked for,
/// not in real time, as CoppeliaSim does; real-time pacing resumes from that moment
/// when the last client stops stepping.
///
/// # Errors
/// The simulation could not be created (Lua state).
pub fn run_sim_thread(
    model: SceneModel,
    config: SimConfig,
    rx: Receiver<Request>,
    should_stop: impl Fn() -> bool,
) -> Result<RunSummary, gantry_script::ScriptError> {
    run_sim_thread_observed(model, config, rx, should_stop, &mut ())
}

/// [`run_sim_thread`], with `observer` looking at the simulation at every turn of the
/// loop (see [`Observer`]).
///
/// # Errors
/// The simulation could not be created (Lua state).
pub fn run_sim_thread_observed(
    model: SceneModel,
    config: SimConfig,
    rx: Receiver<Request>,
    should_stop: impl Fn() -> bool,
    observer: &mut impl Observer,
) -> Result<RunSummary, gantry_script::ScriptError> {
    run_sim_thread_debugged(model, config, rx, should_stop, observer, None)
}

/// [`run_sim_thread_observed`], with the script debugger on `debug` when given
/// (`gantry run --debug`; see [`crate::debug`]).
///
/// # Errors
/// The simulation could not be created (Lua state).
pub fn run_sim_thread_debugged(
    model: SceneModel,
    config: SimConfig,
    rx: Receiver<Request>,
    should_stop: impl Fn() -> bool,
    observer: &mut impl Observer,
    debug: Option<gantry_script::DebugLink>,
) -> Result<RunSummary, gantry_script::ScriptError> {
    let dt = model.settings.dt;
    let mut sim = match debug {
        Some(link) => Simulation::with_debugger(model, config.limits, link)?,
        None => Simulation::new(model, config.limits)?,
    };
    sim.set_load_options(config.load_options.clone());
    if let Some(l) = &config.listeners {
        sim.set_listeners(l.clone());
    }
    let mut lp = SimLoop {
        sim,
        steps: 0,
        stepping: Stepping::default(),
        deferred: VecDeque::new(),
        limits: config.limits,
        load_options: config.load_options.clone(),
        listeners: config.listeners.clone(),
    };
    if config.autostart {
        lp.sim.start();
    }
    let start = Instant::now();
    // Real-time pacing from a fixed origin, re-anchored after pauses and while stepping.
    let mut origin = Instant::now();
    let mut paced_steps = 0u64;
    let mut last_reload = Instant::now();
    let mut last_idle = Instant::now();
    let mut last_served = start.checked_sub(SPIN_AFTER_ACTIVITY).unwrap_or(start);
    'outer: loop {
        observer.observe(&lp.sim, lp.steps);
        if should_stop() || config.steps.is_some_and(|n| lp.steps >= n) {
            break;
        }
        let running = lp.sim.state() == SimulationState::Running;
        let may_advance = running && lp.stepping.may_advance(lp.steps);
        let wait = if may_advance {
            let on_demand = lp.stepping.any_stepping();
            let due = origin + Duration::from_secs_f64(paced_steps as f64 * dt);
            let now = Instant::now();
            if config.fast || on_demand || now >= due {
                lp.step_serving(&rx);
                if on_demand {
                    origin = Instant::now();
                    paced_steps = 0;
                } else {
                    paced_steps += 1;
                }
                // Serve what arrived during the step before the next one.
                while let Ok(req) = rx.try_recv() {
                    lp.serve(req);
                }
                continue;
            }
            due - now
        } else {
            // Paused, stopped, or held by a remote client: nothing is due. Requests
            // (such as the `sim.step` that releases the hold) still wake the loop at once.
            origin = Instant::now();
            paced_steps = 0;
            Duration::from_millis(50)
        };
        // A remote client in a call loop sends its next request within microseconds of
        // the last reply; waking a parked thread costs tens of microseconds, which would
        // be most of such a call. So, right after serving, poll briefly before parking.
        let mut early = None;
        if last_served.elapsed() < SPIN_AFTER_ACTIVITY {
            let until = Instant::now() + SPIN_FOR.min(wait);
            while Instant::now() < until {
                if let Ok(req) = rx.try_recv() {
                    early = Some(req);
                    break;
                }
                std::thread::yield_now();
            }
        }
        let received = match early {
            Some(req) => Ok(req),
            None => rx.recv_timeout(wait),
        };
        match received {
            Ok(req) => {
                last_served = Instant::now();
                lp.serve(req);
                while let Ok(req) = rx.try_recv() {
                    lp.serve(req);
                }
            }
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => {
                if !running {
                    break 'outer;
                }
                // No transport is left, so no client can release a hold any more; and
                // recv_timeout now returns at once, so sleep instead of spinning.
                lp.stepping.clear();
                std::thread::sleep(wait);
            }
        }
        if last_reload.elapsed() > Duration::from_millis(500) {
            last_reload = Instant::now();
            lp.sim.reload_changed();
        }
        // Scripts' sysCall_nonSimulation, about 20 times a second while stopped (the
        // loop wakes every 50 ms then, or on a request).
        if lp.sim.state() == SimulationState::Stopped && last_idle.elapsed() >= Duration::from_millis(50) {
            last_idle = Instant::now();
            lp.sim.non_simulation();
        }
    }
    lp.sim.cleanup();
    if let Some(dir) = &config.export_graphs {
        // Cleanup hooks ran first: their last values are part of the export.
        let core = lp.sim.core();
        let w = &core.world;
        let alias = |h: Handle| {
            w.object(h)
                .map(|o| o.alias.clone())
                .unwrap_or_else(|_| format!("graph{h}"))
        };
        match core.graphs.export_csv(dir, alias) {
            Ok(files) => {
                for f in files {
                    tracing::info!("graph streams written to {}", f.display());
                }
            }
            Err(e) => tracing::error!("cannot export graph streams to {}: {e}", dir.display()),
        }
    }
    lp.stepping.stopped();
    let sim_time = lp.sim.world().time();
    Ok(RunSummary {
        steps: lp.steps,
        sim_time,
        wall_s: start.elapsed().as_secs_f64(),
    })
}

/// What the loop owns besides its schedule.
struct SimLoop {
    sim: Simulation,
    /// Steps executed so far in this run; never reset (stop does not rewind it), so
    /// remote clients' step targets stay comparable across a stop and start.
    steps: u64,
    stepping: Stepping,
    /// Requests that arrived during a step and wait for its end, in arrival order.
    deferred: VecDeque<Request>,
    /// For scenes loaded later (`sim.loadScene`).
    limits: ScriptLimits,
    load_options: gantry_sim_core::scene::LoadOptions,
    listeners: Option<std::sync::Arc<dyn gantry_script::Listeners>>,
}

impl SimLoop {
    fn step(&mut self) {
        self.sim.step();
        self.steps += 1;
        self.stepping.stepped(self.steps);
        self.after_script_control();
    }

    /// A script may have paused or stopped the simulation during the step
    /// (`sim.pauseSimulation()` ...): the remote clients' stepping follows, as when a
    /// client asks.
    fn after_script_control(&mut self) {
        match self.sim.state() {
            SimulationState::Stopped => self.stepping.stopped(),
            SimulationState::Paused => self.stepping.release_waiters(),
            SimulationState::Running => {}
        }
    }

    /// A step during which requests are served at the boundaries between its phases
    /// (see `Simulation::step_with`), so that a call arriving during a long step (a
    /// vision sensor rendering, physics with many substeps) is answered within one
    /// phase rather than one step. Only world calls and text packets are served
    /// there, and between a vision sensor's render and its `sysCall_vision` only world
    /// calls that cannot see its unprocessed image; anything that controls the
    /// simulation or the stepping clients (start, stop, `sim.step`, stepping levels,
    /// viewer closures) waits for the end of the step, and so does every request
    /// behind a waiting one, so replies keep arrival order.
    fn step_serving(&mut self, rx: &Receiver<Request>) {
        let deferred = &mut self.deferred;
        self.sim.step_with(&mut |sim: &mut Simulation, at: StepBoundary| {
            while let Ok(req) = rx.try_recv() {
                match req {
                    req if !deferred.is_empty() || !may_serve_mid_step(&req, at) => deferred.push_back(req),
                    Request::Call { name, args, reply } => serve_call(sim, &name, &args, reply),
                    Request::Packet { packet, reply } => serve_packet(sim, packet, reply),
                    other => deferred.push_back(other),
                }
            }
        });
        self.steps += 1;
        self.stepping.stepped(self.steps);
        self.after_script_control();
        while let Some(req) = self.deferred.pop_front() {
            self.serve(req);
        }
    }

    /// Stop: cleanup, the initial scene back, and every remote client's stepping level
    /// reset (CoppeliaSim's add-on does the same, so a stopped client cannot hold the
    /// next run).
    fn stop(&mut self) {
        self.sim.stop();
        self.stepping.stopped();
    }

    fn pause(&mut self) {
        self.sim.pause();
        self.stepping.release_waiters();
    }

    /// Start, pause or stop, whoever asks (a remote client, the viewer, the command line).
    fn control(&mut self, c: Control) {
        match c {
            Control::Start => self.sim.start(),
            Control::Pause => self.pause(),
            Control::Stop => self.stop(),
        }
    }

    fn serve(&mut self, req: Request) {
        match req {
            Request::Call { name, args, reply } => {
                let before = self.sim.state();
                serve_call(&mut self.sim, &name, &args, reply);
                // A called script function may have stopped or paused the simulation;
                // the stepping clients follow such a change (and only a change: a call
                // made while stopped must not reset their levels).
                if self.sim.state() != before {
                    self.after_script_control();
                }
            }
            Request::Packet { packet, reply } => serve_packet(&mut self.sim, packet, reply),
            Request::Control { action, reply } => {
                match action {
                    LoopControl::Control(c) => self.control(c),
                    LoopControl::Step => {
                        if self.sim.state() != SimulationState::Running {
                            self.sim.start();
                            self.step();
                            self.pause();
                        } else {
                            self.step();
                        }
                    }
                }
                let _ = reply.send(self.sim.state());
            }
            Request::Remote { client, op, reply } => {
                let _ = reply.send(self.remote(client, op));
            }
            Request::Step { client, done } => {
                let advancing = self.sim.state() == SimulationState::Running;
                self.stepping.request_step(client, self.steps, advancing, done);
            }
            Request::DropClient(client) => self.stepping.drop_client(client),
            Request::LoadScene { path, reply } => {
                let _ = reply.send(self.load_scene(path.as_deref()));
            }
            Request::With(f) => f(&mut self.sim),
        }
    }

    /// Replaces the scene (see [`Request::LoadScene`]). A file that does not load
    /// leaves the current scene as it was.
    fn load_scene(&mut self, path: Option<&std::path::Path>) -> Result<Vec<Value>, CallError> {
        let function = if path.is_some() {
            "sim.loadScene"
        } else {
            "sim.closeScene"
        };
        let refused = |e: &dyn std::fmt::Display| CallError::failed(function, ApiError::new(e.to_string()));
        let model = gantry_sim_core::scene::load_client_scene(path, &self.load_options).map_err(|e| refused(&e))?;
        // The debugger's link moves to the new scene (its breakpoints stay with the
        // client, which sets them again per file).
        let mut sim = match self.sim.take_debug_link() {
            Some(link) => Simulation::with_debugger(model, self.limits, link),
            None => Simulation::new(model, self.limits),
        }
        .map_err(|e| refused(&e))?;
        sim.set_load_options(self.load_options.clone());
        if let Some(l) = &self.listeners {
            sim.set_listeners(l.clone());
        }
        // Cleanup hooks of the old scene run; its log goes with it.
        self.stop();
        self.sim = sim;
        Ok(Vec::new())
    }

    fn remote(&mut self, client: ClientId, op: RemoteOp) -> Result<Vec<Value>, CallError> {
        let in_function =
            |e: SteppingError, f: &str| CallError::failed(format!("sim.{f}"), ApiError::new(e.to_string()));
        match op {
            RemoteOp::SetStepping(enable) => {
                let previous = self
                    .stepping
                    .set_stepping(client, enable, self.steps)
                    .map_err(|e| in_function(e, "setStepping"))?;
                return Ok(vec![Value::Int(i64::from(previous))]);
            }
            RemoteOp::Control(c) => self.control(c),
            RemoteOp::Lock(acquire) => {
                let name = if acquire { "acquireLock" } else { "releaseLock" };
                self.stepping.lock(client, acquire).map_err(|e| in_function(e, name))?;
            }
        }
        Ok(Vec::new())
    }
}

/// Whether `req` may be served at boundary `at` inside a step (see
/// [`SimLoop::step_serving`]).
fn may_serve_mid_step(req: &Request, at: StepBoundary) -> bool {
    match req {
        // The Lua host's functions run script code, which may start, stop or pause the
        // simulation, load a model or remove a script: never inside a step.
        Request::Call { name, .. }
            if api::host_function(name).is_some_and(|h| h.remote == api::Remote::ByScriptHost) =>
        {
            false
        }
        Request::Call { name, .. } => at == StepBoundary::Phase || !sees_vision(name),
        Request::Packet { .. } => at == StepBoundary::Phase,
        Request::Control { .. }
        | Request::Remote { .. }
        | Request::Step { .. }
        | Request::DropClient(_)
        | Request::LoadScene { .. }
        | Request::With(_) => false,
    }
}

/// Whether `sim.<name>` (or a qualified module function) may read a vision sensor's
/// image, directly or through a script: such calls wait while an image is unprocessed.
fn sees_vision(name: &str) -> bool {
    name.contains("Vision") || name.contains("Script")
}

/// `sim.<name>(args)` for a remote client.
fn serve_call(sim: &mut Simulation, name: &str, args: &[Value], reply: oneshot::Sender<Result<Vec<Value>, CallError>>) {
    let _ = reply.send(sim.call(name, args));
}

/// A text packet to the scripts' `sysCall_packet`.
fn serve_packet(sim: &mut Simulation, packet: Value, reply: oneshot::Sender<PacketOutcome>) {
    let outcome = match sim.call_hook_function("sysCall_packet", &[packet]) {
        Ok(None) => PacketOutcome::NoHandler,
        Ok(Some(values)) => match values.into_iter().next() {
            Some(Value::Str(s)) => PacketOutcome::Reply(s),
            _ => PacketOutcome::Handled,
        },
        Err(e) => PacketOutcome::Error(e),
    };
    let _ = reply.send(outcome);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_function_that_reads_a_vision_image_waits_for_its_callback() {
        for m in gantry_sim_core::api::MODULES {
            for f in m.iter() {
                let remote = if m.name == "sim" {
                    f.name.to_owned()
                } else {
                    format!("{}.{}", m.name, f.name)
                };
                if m.name == "simVision" || f.name.contains("VisionSensor") || f.name.contains("Script") {
                    assert!(sees_vision(&remote), "{remote}");
                }
            }
        }
        for world_call in [
            "getObjectPosition",
            "setJointTargetVelocity",
            "readProximitySensor",
            "getSimulationTime",
        ] {
            assert!(!sees_vision(world_call), "{world_call}");
        }
    }

    fn call(name: &str) -> Request {
        Request::Call {
            name: name.to_owned(),
            args: Vec::new(),
            reply: oneshot::channel().0,
        }
    }

    #[test]
    fn what_is_served_inside_a_step() {
        use StepBoundary::{Phase, VisionUnprocessed};
        assert!(may_serve_mid_step(&call("getObjectPosition"), Phase));
        assert!(may_serve_mid_step(&call("getObjectPosition"), VisionUnprocessed));
        assert!(may_serve_mid_step(&call("getVisionSensorImg"), Phase));
        assert!(!may_serve_mid_step(&call("getVisionSensorImg"), VisionUnprocessed));
        assert!(!may_serve_mid_step(
            &call("simVision.sensorImgToWorkImg"),
            VisionUnprocessed
        ));
        let packet = Request::Packet {
            packet: Value::Nil,
            reply: oneshot::channel().0,
        };
        assert!(may_serve_mid_step(&packet, Phase));
        assert!(!may_serve_mid_step(&packet, VisionUnprocessed));
        let control = Request::Control {
            action: LoopControl::Control(Control::Stop),
            reply: oneshot::channel().0,
        };
        assert!(!may_serve_mid_step(&control, Phase));
        let step = Request::Step {
            client: ClientId(1),
            done: oneshot::channel().0,
        };
        assert!(!may_serve_mid_step(&step, Phase));
        assert!(!may_serve_mid_step(&Request::With(Box::new(|_| {})), Phase));
        // Script code (which may stop the simulation or load a model) waits for the end.
        for script_host in api::host::remote_names(api::Remote::ByScriptHost) {
            assert!(!may_serve_mid_step(&call(script_host), Phase), "{script_host}");
        }
    }
}
