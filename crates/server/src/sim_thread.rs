//! The simulation thread: the only owner of the world and the Lua state.
//!
//! Transports never touch the world. They send [`Request`]s through a bounded channel
//! ([`SimHandle`]) and await the reply on a oneshot. The thread steps the simulation on
//! its real-time schedule and, between steps — including while it waits for the next
//! tick — serves every request as soon as it arrives, so a reply never waits for the
//! next 50 ms step.

use std::cell::RefCell;
use std::collections::VecDeque;
use std::path::PathBuf;
use std::rc::Rc;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, SyncSender, TrySendError};
use std::time::{Duration, Instant};

use gantry_engine::{
    ClientId, Due, Engine, EngineConfig, Input, MidStep, Observer, Output, StepBoundary, WhileWaiting,
};
pub use gantry_engine::{LoopControl, RemoteOp};
use gantry_lua::{ScriptLimits, ScriptState};
use gantry_sim_core::Value;
use gantry_sim_core::api::{CallError, StepSafety, Target};
use gantry_sim_core::scene::SceneModel;
use gantry_sim_core::sim::SimulationState;
use gantry_sim_core::{Handle, Sim};
use tokio::sync::oneshot;

/// Most requests queued for the simulation thread; beyond this, transports answer
/// "busy" instead of growing memory.
pub const QUEUE_CAPACITY: usize = 4096;
/// How long the simulation thread polls for the next request before parking, and for
/// how long after the last request it keeps doing so. The poll yields the core, so an
/// idle simulator burns nothing and a busy client saves a thread wake-up per call.
const SPIN_FOR: Duration = Duration::from_micros(200);
const SPIN_AFTER_ACTIVITY: Duration = Duration::from_millis(20);
/// The longest the simulation thread keeps serving a calling client between two steps
/// of a free-running (`--fast`) simulation; see [`serve_share`].
const MAX_CALL_SHARE: Duration = Duration::from_millis(5);
/// The longest the simulation thread serves requests at one boundary between the
/// phases of a step (see [`SimLoop::step_serving`]).
const MAX_BOUNDARY_SHARE: Duration = Duration::from_millis(1);

/// A request to the simulation thread.
pub enum Request {
    /// Call a function as a remote client (no emitting object).
    Call {
        /// The function, resolved by the front end.
        target: Target,
        /// Arguments.
        args: Vec<Value>,
        /// The results or a CoppeliaSim-style error message.
        reply: oneshot::Sender<Result<Vec<Value>, CallError>>,
    },
    /// A remote API client's blocking call (`sim.wait`, `sim.moveToConfig`, ...): run
    /// over as many steps as it needs, then answered (see `Input::Blocking`).
    Blocking {
        /// The client, whose stepping level the call's steps go through.
        client: ClientId,
        /// The function.
        f: gantry_sim_core::api::ScriptHostFn,
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
    /// Run a closure on the simulation thread with the engine, between steps (the
    /// viewer's edits, tests).
    With(Box<dyn FnOnce(&mut Engine) + Send>),
    /// Run a closure that only reads the simulation (the viewer's scene, status and
    /// panels): served between steps, and also while a script holds the step in a
    /// blocking call (see [`SimView`]).
    Read(Box<dyn FnOnce(&SimView<'_>) + Send>),
}

/// What a [`Request::Read`] sees.
pub struct SimView<'a> {
    /// The simulation.
    pub sim: &'a Sim,
    /// Each script's file, object and state; `None` while a script holds the step (the
    /// Lua host is busy running it).
    pub scripts: Option<&'a [(PathBuf, Handle, ScriptState)]>,
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

/// Why [`SimHandle::call`] has no result; the text is the call's error or the
/// delivery's.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HandleCallError {
    /// The function is unknown or failed.
    #[error(transparent)]
    Failed(#[from] CallError),
    /// The simulation thread did not take the request.
    #[error(transparent)]
    NotDelivered(#[from] SendError),
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
    /// Set when a request that stops the simulation is queued, so that a script blocked
    /// in a LuaSocket call gives up and the request is served (see
    /// [`gantry_lua::NetworkParams::interrupt`]); the Lua host clears it.
    interrupt: Option<Arc<AtomicBool>>,
}

/// Whether `req` stops the running simulation (a stop, or another scene).
fn stops_the_simulation(req: &Request) -> bool {
    use gantry_sim_core::sim::Control;
    matches!(
        req,
        Request::Control {
            action: LoopControl::Control(Control::Stop),
            ..
        } | Request::Remote {
            op: RemoteOp::Control(Control::Stop),
            ..
        } | Request::LoadScene { .. }
    )
}

impl SimHandle {
    /// This handle, and its clones, set `flag` when they queue a request that stops the
    /// simulation (see [`SimHandle::send`]); the runner passes the same flag to the Lua
    /// host as [`gantry_lua::NetworkParams::interrupt`].
    #[must_use]
    pub fn interrupting(mut self, flag: Arc<AtomicBool>) -> Self {
        self.interrupt = Some(flag);
        self
    }

    /// Queues a request without blocking.
    ///
    /// # Errors
    /// [`SendError::Busy`] when the queue is full, [`SendError::Closed`] after shutdown.
    pub fn send(&self, req: Request) -> Result<(), SendError> {
        if let Some(flag) = &self.interrupt
            && stops_the_simulation(&req)
        {
            flag.store(true, Ordering::SeqCst);
        }
        self.tx.try_send(req).map_err(|e| match e {
            TrySendError::Full(_) => SendError::Busy,
            TrySendError::Disconnected(_) => SendError::Closed,
        })
    }

    /// Calls `sim.<name>` (or a qualified `module.name`) and awaits the result: the
    /// name is resolved here, at the caller's edge.
    ///
    /// # Errors
    /// The call's error, or why it could not be delivered.
    pub async fn call(&self, name: &str, args: Vec<Value>) -> Result<Vec<Value>, HandleCallError> {
        let target = Target::resolve_or_error(name)?;
        let (reply, rx) = oneshot::channel();
        self.send(Request::Call { target, args, reply })?;
        Ok(rx.await.map_err(|_| SendError::Closed)??)
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

    /// Runs `f` on the simulation thread with a read-only view and awaits its result:
    /// answered even while a script holds the step in a blocking call.
    ///
    /// # Errors
    /// Why it could not be delivered.
    pub async fn read<R: Send + 'static>(
        &self,
        f: impl FnOnce(&SimView<'_>) -> R + Send + 'static,
    ) -> Result<R, SendError> {
        let (reply, rx) = oneshot::channel();
        self.send(Request::Read(Box::new(move |view| {
            let _ = reply.send(f(view));
        })))?;
        rx.await.map_err(|_| SendError::Closed)
    }

    /// Runs `f` on the simulation thread and awaits its result.
    ///
    /// # Errors
    /// Why it could not be delivered.
    pub async fn with<R: Send + 'static>(
        &self,
        f: impl FnOnce(&mut Engine) -> R + Send + 'static,
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
    /// End the run when the simulation stops after having run (a script's
    /// `sim.stopSimulation`), as CoppeliaSim's `-q` does: for headless runs where no
    /// client could start it again (`gantry run --no-listen`).
    pub quit_when_stopped: bool,
    /// Write every graph stream as CSV into this folder when the run ends.
    pub export_graphs: Option<std::path::PathBuf>,
    /// How scenes loaded later by remote clients (`sim.loadScene`) are read.
    pub load_options: gantry_sim_core::scene::LoadOptions,
    /// The front end's listeners, for scripts' `simRemoteApi.start` (none: scripts
    /// cannot start servers).
    pub listeners: Option<std::sync::Arc<dyn gantry_lua::Listeners>>,
    /// Record the run into an MCAP file (`gantry run --record`); [`crate::start`]
    /// creates the file before anything runs.
    pub record: Option<gantry_record::RecordParams>,
    /// Starts the recordings scripts ask for (`sim.startRecording`); without it they
    /// are refused.
    pub recorder_factory: Option<std::sync::Arc<dyn gantry_engine::RecorderFactory>>,
    /// ROS 2: the network of scripts' `simROS2`, and the graph's topics when asked for
    /// (`--ros2`).
    pub ros2: Option<gantry_ros2::RosSetup>,
    /// The viewer's pose stream: frames go out after each step, at the loop's idle
    /// ticks, and while a script holds the step in a blocking call.
    pub frames: Option<crate::http::FrameSender>,
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

/// Creates the request channel: the handle for transports and the receiver for
/// [`run_sim_thread`].
pub fn channel() -> (SimHandle, Receiver<Request>) {
    let (tx, rx) = mpsc::sync_channel(QUEUE_CAPACITY);
    (SimHandle { tx, interrupt: None }, rx)
}

/// The simulation loop. Runs until `config.steps` is reached, `should_stop` returns
/// true, or every [`SimHandle`] is dropped. Runs cleanup hooks before returning.
///
/// The simulation advances only when `Stepping` allows it (no remote client holds it
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
) -> Result<RunSummary, gantry_lua::ScriptError> {
    run_sim_thread_observed(model, config, rx, should_stop, Vec::new())
}

/// [`run_sim_thread`], with `observers` looking at the simulation after every step and
/// at every turn of the loop that took none (the viewer's frames; see [`Observer`]).
///
/// # Errors
/// The simulation could not be created (Lua state).
pub fn run_sim_thread_observed(
    model: SceneModel,
    config: SimConfig,
    rx: Receiver<Request>,
    should_stop: impl Fn() -> bool,
    observers: Vec<Box<dyn Observer>>,
) -> Result<RunSummary, gantry_lua::ScriptError> {
    run_sim_thread_debugged(model, config, rx, should_stop, observers, None, None)
}

/// [`run_sim_thread_observed`], with the script debugger on `debug` when given
/// (`gantry run --debug`; see [`crate::debug`]) and the run recorded by `recorder`
/// (`gantry run --record`): every step and every request that reaches the engine.
///
/// # Errors
/// The simulation could not be created (Lua state).
pub fn run_sim_thread_debugged(
    model: SceneModel,
    config: SimConfig,
    rx: Receiver<Request>,
    should_stop: impl Fn() -> bool,
    observers: Vec<Box<dyn Observer>>,
    debug: Option<gantry_lua::DebugLink>,
    recorder: Option<gantry_record::Recorder>,
) -> Result<RunSummary, gantry_lua::ScriptError> {
    let mut engine = Engine::new(
        model,
        EngineConfig {
            limits: config.limits,
            load_options: config.load_options.clone(),
            listeners: config.listeners.clone(),
            realtime: !config.fast,
            recorder: config.recorder_factory.clone(),
            ros: config
                .ros2
                .as_ref()
                .map(|r| r.network.clone() as std::sync::Arc<dyn gantry_lua::ros::RosNetwork>),
        },
        debug,
    )?;
    for o in observers {
        engine.add_observer(o);
    }
    if let Some(g) = config.ros2.as_ref().and_then(gantry_ros2::RosSetup::graph) {
        engine.add_observer(Box::new(g));
    }
    if let Some(r) = recorder {
        let tap = gantry_record::RecordTap::new(r, &engine.sim());
        engine.set_recorder(Box::new(tap));
    }
    let frames = config.frames.as_ref().map(|tx| {
        let p = crate::http::SharedPublisher(Rc::new(RefCell::new(crate::http::FramePublisher::on(tx.clone()))));
        engine.add_observer(Box::new(p.clone()));
        p
    });
    let rx = Rc::new(rx);
    let deferred = Rc::new(RefCell::new(VecDeque::new()));
    engine.set_while_waiting(while_waiting(rx.clone(), deferred.clone(), frames));
    let mut lp = SimLoop { engine, deferred };
    if config.autostart {
        lp.engine.serve(Input::Control(LoopControl::Control(
            gantry_sim_core::sim::Control::Start,
        )));
    }
    let start = Instant::now();
    let mut last_served = start.checked_sub(SPIN_AFTER_ACTIVITY).unwrap_or(start);
    // An autostarted run has run once its scripts initialised, even when one of them
    // stopped the simulation in `sysCall_init` (a headless run then ends at once).
    let mut has_run = config.autostart;
    loop {
        lp.engine.idle();
        if should_stop() || config.steps.is_some_and(|n| lp.engine.steps() >= n) {
            break;
        }
        if lp.engine.state() == SimulationState::Stopped {
            if has_run && config.quit_when_stopped {
                break;
            }
        } else {
            has_run = true;
        }
        let now = Instant::now();
        let wait = match lp.engine.due(now) {
            Due::Now => {
                let began = Instant::now();
                if lp.step_serving(&rx) {
                    last_served = Instant::now();
                }
                let step_took = began.elapsed();
                // What arrived during the step is served before the next one, and a
                // client that is calling gets its share of the thread.
                let calling = last_served.elapsed() < SPIN_AFTER_ACTIVITY;
                if serve_share(&mut lp, &rx, step_took, calling) {
                    last_served = Instant::now();
                }
                continue;
            }
            Due::At(t) => t.saturating_duration_since(now),
            // Paused, stopped, or held by a remote client: nothing is due. Requests (such
            // as the `sim.step` that releases the hold) still wake the loop at once.
            Due::Held => Duration::from_millis(50),
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
                if lp.engine.state() != SimulationState::Running {
                    break;
                }
                // No transport is left, so no client can release a hold any more; and
                // recv_timeout now returns at once, so sleep instead of spinning.
                lp.engine.release_all_clients();
                std::thread::sleep(wait);
            }
        }
        lp.engine.tick(Instant::now());
    }
    lp.engine.finish();
    if let Some(dir) = &config.export_graphs {
        // Cleanup hooks ran first: their last values are part of the export.
        export_graphs(&lp.engine.sim(), dir);
    }
    Ok(RunSummary {
        steps: lp.engine.steps(),
        sim_time: lp.engine.world().time(),
        wall_s: start.elapsed().as_secs_f64(),
    })
}

/// A free-running simulation shares its thread fairly with its clients. After a step
/// that took `step_took`, requests are served as they come for up to as long again (at
/// most [`MAX_CALL_SHARE`]), at least one if any is waiting; then the next step starts.
/// With `calling` (a client was served lately), the thread also waits for the client's
/// next request until it has been quiet for [`SPIN_FOR`]: a client calling in a loop
/// (`sim.getObjectPosition` from a GUI or a controller) would otherwise find a step under
/// way at almost every call and wait for a phase of it. Either way the simulation keeps
/// at least half of the thread however fast clients call (an unbounded drain of the
/// queue would let a client that calls without pause stop it). Whether anything was
/// served is returned.
fn serve_share(lp: &mut SimLoop, rx: &Receiver<Request>, step_took: Duration, calling: bool) -> bool {
    let began = Instant::now();
    let share_ends = began + step_took.min(MAX_CALL_SHARE);
    let mut quiet_since = began;
    let mut served = false;
    loop {
        match rx.try_recv() {
            Ok(req) => {
                served = true;
                lp.serve(req);
                quiet_since = Instant::now();
                if quiet_since >= share_ends {
                    return served;
                }
            }
            Err(_) => {
                let now = Instant::now();
                if !calling || now >= share_ends || now.duration_since(quiet_since) >= SPIN_FOR {
                    return served;
                }
                std::thread::yield_now();
            }
        }
    }
}

/// What the simulation thread does while a script holds the step in a blocking call
/// (see [`WhileWaiting`]): the viewer's reads are answered and its frames go out; every
/// other request waits for the end of the step, in arrival order (a stop also ends the
/// script's wait: [`SimHandle::send`] raises the interrupt).
fn while_waiting(
    rx: Rc<Receiver<Request>>,
    deferred: Rc<RefCell<VecDeque<Request>>>,
    frames: Option<crate::http::SharedPublisher>,
) -> WhileWaiting {
    Rc::new(move |sim: &RefCell<Sim>, slice: Duration| {
        let until = Instant::now() + slice;
        loop {
            let left = until.saturating_duration_since(Instant::now());
            match rx.recv_timeout(left) {
                Ok(Request::Read(f)) if deferred.borrow().is_empty() => match sim.try_borrow() {
                    Ok(s) => f(&SimView { sim: &s, scripts: None }),
                    Err(_) => deferred.borrow_mut().push_back(Request::Read(f)),
                },
                Ok(other) => deferred.borrow_mut().push_back(other),
                Err(RecvTimeoutError::Timeout) => break,
                Err(RecvTimeoutError::Disconnected) => {
                    std::thread::sleep(left);
                    break;
                }
            }
            if Instant::now() >= until {
                break;
            }
        }
        if let Some(p) = &frames
            && let Ok(s) = sim.try_borrow()
        {
            p.0.borrow_mut().observe_waiting(&s);
        }
    })
}

/// Every graph stream as CSV into `dir` (`--export-graphs`).
fn export_graphs(core: &gantry_sim_core::Sim, dir: &std::path::Path) {
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

/// The engine and the requests waiting for the end of a step.
struct SimLoop {
    engine: Engine,
    /// Requests that arrived during a step (or while a script waited) and wait for its
    /// end, in arrival order.
    deferred: Rc<RefCell<VecDeque<Request>>>,
}

impl SimLoop {
    /// A step during which requests are served at the boundaries between its phases
    /// (see `Simulation::step_with`), so that a call arriving during a long step (a
    /// vision sensor rendering, physics with many substeps) is answered within one
    /// phase rather than one step. Only calls and text packets are served there, each
    /// where what it touches allows ([`may_serve_mid_step`]); anything that controls
    /// the simulation or the stepping clients (start, stop, `sim.step`, stepping
    /// levels, viewer closures) waits for the end of the step, and so does every
    /// request behind a waiting one, so replies keep arrival order.
    /// Whether any request arrived during the step is returned.
    fn step_serving(&mut self, rx: &Receiver<Request>) -> bool {
        let deferred = self.deferred.clone();
        let mut arrived = false;
        self.engine.step_with(&mut |mid: &mut MidStep<'_>| {
            let at = mid.boundary();
            // Bounded, so that a client calling without pause cannot hold the step at
            // a boundary: what is left waits for the next boundary or the step's end.
            let until = Instant::now() + MAX_BOUNDARY_SHARE;
            while Instant::now() < until {
                let Ok(req) = rx.try_recv() else { break };
                arrived = true;
                let waiting = !deferred.borrow().is_empty();
                match req {
                    req if waiting || !may_serve_mid_step(&req, at) => deferred.borrow_mut().push_back(req),
                    Request::Call { target, args, reply } => {
                        let _ = reply.send(mid.call(&target, &args));
                    }
                    Request::Packet { packet, reply } => {
                        let _ = reply.send(packet_outcome(mid.packet(&packet)));
                    }
                    Request::Read(f) => f(&SimView {
                        sim: &mid.sim(),
                        scripts: None,
                    }),
                    other => deferred.borrow_mut().push_back(other),
                }
            }
        });
        self.serve_deferred();
        arrived
    }

    /// Serves the requests that waited for the end of a step or of a script's wait.
    fn serve_deferred(&mut self) {
        loop {
            let next = self.deferred.borrow_mut().pop_front();
            match next {
                Some(req) => self.serve_now(req),
                None => break,
            }
        }
    }

    /// Serves `req` between steps, then what waited meanwhile.
    fn serve(&mut self, req: Request) {
        self.serve_now(req);
        self.serve_deferred();
    }

    /// Serves `req` between steps: the engine's one entry for every input, the
    /// viewer's closures on the engine itself.
    fn serve_now(&mut self, req: Request) {
        let e = &mut self.engine;
        match req {
            // A blocking function called without a client's session (the in-process
            // client on the simulation thread, the legacy remote API).
            Request::Call {
                target: Target::ScriptHost(f),
                args,
                reply,
            } if f.blocks() => {
                e.serve(Input::Blocking {
                    client: None,
                    f,
                    args: &args,
                    reply,
                });
            }
            Request::Call { target, args, reply } => {
                let _ = reply.send(
                    e.serve(Input::Call {
                        target: &target,
                        args: &args,
                    })
                    .into_values(),
                );
            }
            Request::Blocking { client, f, args, reply } => {
                e.serve(Input::Blocking {
                    client: Some(client),
                    f,
                    args: &args,
                    reply,
                });
            }
            Request::Packet { packet, reply } => {
                let out = match e.serve(Input::Packet(&packet)) {
                    Output::Packet(r) => r,
                    _ => Ok(None),
                };
                let _ = reply.send(packet_outcome(out));
            }
            Request::Control { action, reply } => {
                e.serve(Input::Control(action));
                let _ = reply.send(e.state());
            }
            Request::Remote { client, op, reply } => {
                let _ = reply.send(e.serve(Input::Remote { client, op }).into_values());
            }
            Request::Step { client, done } => {
                e.serve(Input::Step { client, done });
            }
            Request::DropClient(client) => {
                e.serve(Input::DropClient(client));
            }
            Request::LoadScene { path, reply } => {
                let _ = reply.send(e.serve(Input::LoadScene(path.as_deref())).into_values());
            }
            Request::With(f) => f(e),
            Request::Read(f) => {
                let scripts = e.scripts();
                f(&SimView {
                    sim: &e.sim(),
                    scripts: Some(&scripts),
                });
            }
        }
    }
}

/// Whether `req` may be served at boundary `at` inside a step (see
/// [`SimLoop::step_serving`]), from what its target touches.
fn may_serve_mid_step(req: &Request, at: StepBoundary) -> bool {
    match req {
        Request::Call { target, .. } => match target.step_safety() {
            StepSafety::AnyBoundary => true,
            StepSafety::PhaseBoundary => at == StepBoundary::Phase,
            // Script code may start, stop or pause the simulation, load a model or
            // remove a script: never inside a step.
            StepSafety::BetweenSteps => false,
        },
        Request::Packet { .. } | Request::Read(_) => at == StepBoundary::Phase,
        Request::Control { .. }
        | Request::Blocking { .. }
        | Request::Remote { .. }
        | Request::Step { .. }
        | Request::DropClient(_)
        | Request::LoadScene { .. }
        | Request::With(_) => false,
    }
}

/// What the scripts' `sysCall_packet` did with a packet, for the transport.
fn packet_outcome(result: Result<Option<Vec<Value>>, gantry_lua::HookError>) -> PacketOutcome {
    match result {
        Ok(None) => PacketOutcome::NoHandler,
        Ok(Some(values)) => match values.into_iter().next() {
            Some(Value::Str(s)) => PacketOutcome::Reply(s),
            _ => PacketOutcome::Handled,
        },
        Err(e) => PacketOutcome::Error(e.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use gantry_sim_core::api;
    use gantry_sim_core::sim::Control;

    #[test]
    fn every_function_that_reads_a_vision_image_waits_for_its_callback() {
        // Images live in the floors above the world, so only functions typed as
        // touching them can read one; those wait while an image is unprocessed.
        for name in Target::accepted_names() {
            let target = Target::resolve(&name).expect("resolves");
            let world_only = target.step_safety() == StepSafety::AnyBoundary;
            if name.starts_with("simVision.") || name.contains("getVisionSensorImg") {
                assert!(!world_only, "{name}");
            }
        }
    }

    fn call(name: &str) -> Request {
        Request::Call {
            target: Target::resolve(name).expect("resolves"),
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
        for (script_host, _) in api::host::script_host_functions() {
            assert!(!may_serve_mid_step(&call(script_host), Phase), "{script_host}");
        }
    }
}
