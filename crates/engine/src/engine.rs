//! The engine: the one owner of a simulation.
//!
//! An [`Engine`] owns the [`Sim`] (the world and its subsystems), the scene model a stop
//! rebuilds it from, and the Lua host that runs the scene's scripts (none for a scene
//! without scripts until a client needs one). It carries out every input through one
//! entry, [`Engine::serve`]; takes steps in CoppeliaSim's order (`step.rs`), calling the
//! host's hooks between the physics and sensing phases; starts, pauses and stops the
//! simulation itself (`lifecycle.rs`); decides when a step may be taken (stepping levels,
//! locks, real-time pacing); and tells its observers. It owns no socket, channel or
//! thread and reads the clock only where a caller asks it to: the front end decides how
//! to wait and how to answer.

use std::cell::{Ref, RefCell, RefMut};
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::Arc;
use std::time::{Duration, Instant};

use gantry_lua::ros::RosNetwork;
use gantry_lua::{
    DebugLink, HookError, Listeners, LuaHost, ScriptError, ScriptLimits, ScriptState, SimCell, WaitService,
};
use gantry_sim_core::api::{ApiFunction, Args, CallContext, CallError, ScriptHostFn, Target};
use gantry_sim_core::scene::{LoadOptions, SceneModel, load_client_scene};
use gantry_sim_core::sim::{Control, SimulationState};
use gantry_sim_core::{Handle, Sim, SimError, Value, World};
use tokio::sync::oneshot;

use crate::blocking::{BlockingCall, BlockingReply, ended_error, stopped_error};
use crate::history::{Entry, History};
use crate::host_call::{LoopControl, RemoteOp};
use crate::input::{Input, Output};
use crate::observer::{InputAt, Observer, RecorderFactory};
use crate::pacing::Pacing;
use crate::scene::build_sim;
use crate::scene_copy::{RestorePoint, SceneCopy};
use crate::stepping::{ClientId, Stepping, SteppingError};

/// How often scripts' `sysCall_nonSimulation` runs while the simulation is stopped:
/// about 20 times a second, as in CoppeliaSim.
pub const NON_SIMULATION_PERIOD: Duration = Duration::from_millis(50);

/// CoppeliaSim's `sim.verbosity_errors`: the level of the recorder's error lines.
const VERBOSITY_ERRORS: i64 = 200;

/// How often script files are checked for changes (hot reload).
pub const RELOAD_PERIOD: Duration = Duration::from_millis(500);

/// What a remote client's call runs as: no emitting object.
const REMOTE: CallContext<'static> = CallContext {
    script_object: None,
    source: "remote",
};

/// What an engine is built with, and keeps for every scene it loads later.
#[derive(Clone, Default)]
pub struct EngineConfig {
    /// Script time and memory limits.
    pub limits: ScriptLimits,
    /// How scenes and models loaded later (`sim.loadScene`, `sim.loadModel`) are read.
    pub load_options: LoadOptions,
    /// The front end's listeners, for scripts' `simRemoteApi.start` (none: scripts
    /// cannot start servers).
    pub listeners: Option<Arc<dyn Listeners>>,
    /// Without stepping clients: advance in real time (true) or as fast as asked.
    pub realtime: bool,
    /// Starts the recordings scripts ask for (`sim.startRecording`); without it,
    /// they are refused with a logged error.
    pub recorder: Option<Arc<dyn RecorderFactory>>,
    /// The ROS 2 network of scripts' `simROS2` (none: scripts' calls are refused).
    pub ros: Option<Arc<dyn RosNetwork>>,
}

/// What the front end does while a script holds the simulation thread in a blocking
/// call (a LuaSocket `accept` waiting for its client): called again and again with the
/// simulation and a slice of time, it serves what needs no step to finish (the scene,
/// the poses, the log) and returns when the slice is over. It may only read the
/// simulation (`RefCell::try_borrow`): the step it waits in is not finished.
pub type WhileWaiting = Rc<dyn Fn(&RefCell<Sim>, Duration)>;

/// When the next step may be taken (see [`Engine::due`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Due {
    /// Now.
    Now,
    /// At this instant (real-time pacing).
    At(Instant),
    /// Not until something changes: the simulation is paused or stopped, or a stepping
    /// client or a lock holds it.
    Held,
}

/// A simulation with its scripts and its loop rules.
pub struct Engine {
    /// The simulation, lent to the Lua host's `sim.*` functions through the cell.
    pub(crate) sim: SimCell,
    /// The scene as loaded, plus models loaded since: what a stop rebuilds when the
    /// run loaded models (see [`RestorePoint`]).
    pub(crate) model: SceneModel,
    /// The scene as the running simulation started: what a stop restores. `None` while
    /// stopped.
    pub(crate) restore: Option<RestorePoint>,
    /// The editor's undo and redo lists.
    history: History,
    /// The scene's scripts; none until a script or a client needs Lua.
    pub(crate) host: Option<LuaHost>,
    /// Steps taken since the engine was made; never reset (a stop does not rewind it),
    /// so remote clients' step targets stay comparable across a stop and start.
    pub(crate) steps: u64,
    pub(crate) stepping: Stepping,
    pacing: Pacing,
    pub(crate) config: EngineConfig,
    last_reload: Instant,
    last_idle: Instant,
    /// The recording in progress (`--record`, a script's `sim.startRecording`): an
    /// observer scripts may replace or end.
    pub(crate) recorder: Option<Box<dyn Observer>>,
    /// The other observers, for the engine's whole life.
    pub(crate) observers: Vec<Box<dyn Observer>>,
    /// Remote clients' blocking calls in progress, oldest first.
    blocking: Vec<BlockingCall>,
    /// The last blocking call's number.
    blocking_ids: u64,
    /// What the front end does while a script waits (given to every Lua host).
    while_waiting: Option<WhileWaiting>,
}

impl Engine {
    /// The simulation of `model`, stopped, with the debugger on `debug` when given.
    /// A scene with scripts (or a debugger) gets its Lua host now; one without gets it
    /// when a client first needs it.
    ///
    /// # Errors
    /// The Lua state could not be created.
    pub fn new(model: SceneModel, config: EngineConfig, debug: Option<DebugLink>) -> Result<Self, ScriptError> {
        let sim = SimCell::new(build_sim(&model));
        // The loader's warnings are the front end's to report, with the scene it loaded.
        report_warnings(&model, &sim.borrow(), false);
        let host = if model.scripts.is_empty() && debug.is_none() {
            None
        } else {
            Some(Self::lua_host(&sim, &model, &config, debug, None)?)
        };
        let now = Instant::now();
        Ok(Self {
            sim,
            model,
            restore: None,
            history: History::default(),
            host,
            steps: 0,
            stepping: Stepping::default(),
            pacing: Pacing::new(now),
            config,
            last_reload: now,
            last_idle: now,
            recorder: None,
            observers: Vec::new(),
            blocking: Vec::new(),
            blocking_ids: 0,
            while_waiting: None,
        })
    }

    /// A Lua host over `sim` for `model`'s scripts, with the engine's options,
    /// listeners and debugger: one recipe for the first scene, every scene loaded
    /// later and a host made on demand.
    fn lua_host(
        sim: &SimCell,
        model: &SceneModel,
        config: &EngineConfig,
        debug: Option<DebugLink>,
        while_waiting: Option<&WhileWaiting>,
    ) -> Result<LuaHost, ScriptError> {
        let mut host = LuaHost::new(
            sim.clone(),
            &model.scripts,
            model.settings.seed,
            config.limits.clone(),
            debug,
        )?;
        host.set_load_options(config.load_options.clone());
        if let Some(l) = &config.listeners {
            host.set_listeners(l.clone());
        }
        if let Some(n) = &config.ros {
            host.set_ros_network(n.clone());
        }
        host.set_wait_service(while_waiting.map(|w| wait_service(sim, w)));
        Ok(host)
    }

    /// Has scripts' blocking calls serve the front end through `while_waiting` (see
    /// [`WhileWaiting`]), in this scene and those loaded later.
    pub fn set_while_waiting(&mut self, while_waiting: WhileWaiting) {
        if let Some(host) = self.host.as_mut() {
            host.set_wait_service(Some(wait_service(&self.sim, &while_waiting)));
        }
        self.while_waiting = Some(while_waiting);
    }

    /// The Lua host, made now if the scene had none (a client calls a function only
    /// Lua serves, such as `sim.callScriptFunction` or a blocking `sim.wait`).
    ///
    /// # Errors
    /// The Lua state could not be created.
    fn host_mut(&mut self) -> Result<&mut LuaHost, ScriptError> {
        if self.host.is_none() {
            self.host = Some(Self::lua_host(
                &self.sim,
                &self.model,
                &self.config,
                None,
                self.while_waiting.as_ref(),
            )?);
        }
        Ok(self.host.as_mut().expect("made above"))
    }

    /// Lets scripts join a ROS 2 graph (`simROS2`, `simROS`) through `network`, in this
    /// scene and those loaded later.
    pub fn set_ros_network(&mut self, network: Arc<dyn RosNetwork>) {
        if let Some(host) = self.host.as_mut() {
            host.set_ros_network(network.clone());
        }
        self.config.ros = Some(network);
    }

    /// Lets scripts start legacy remote API servers (`simRemoteApi.start`) through
    /// `listeners`, in this scene and those loaded later.
    pub fn set_listeners(&mut self, listeners: Arc<dyn Listeners>) {
        if let Some(host) = self.host.as_mut() {
            host.set_listeners(listeners.clone());
        }
        self.config.listeners = Some(listeners);
    }

    /// Has `observer` see every input, step and the end of the run as the recorder
    /// (see [`Observer`]); the recorder already set, if any, is returned.
    pub fn set_recorder(&mut self, observer: Box<dyn Observer>) -> Option<Box<dyn Observer>> {
        self.recorder.replace(observer)
    }

    /// Stops recording: the recorder is returned, not finished.
    pub fn take_recorder(&mut self) -> Option<Box<dyn Observer>> {
        self.recorder.take()
    }

    /// Has `observer` see every input, step and the end of the run, after the
    /// recorder, for the engine's whole life.
    pub fn add_observer(&mut self, observer: Box<dyn Observer>) {
        self.observers.push(observer);
    }

    /// Tells the observers about an input served between steps.
    fn observe_input(&mut self, input: &Input<'_>) {
        if self.recorder.is_none() && self.observers.is_empty() {
            return;
        }
        let at = InputAt {
            step: self.steps,
            boundary: 0,
        };
        let sim = self.sim.borrow();
        for o in self.recorder.iter_mut().chain(self.observers.iter_mut()) {
            o.input(&sim, at, input);
        }
    }

    /// The front end served requests or waited without taking a step: the observers'
    /// idle tick (the viewer's frames of a paused simulation).
    pub fn idle(&mut self) {
        let sim = self.sim.borrow();
        for o in self.recorder.iter_mut().chain(self.observers.iter_mut()) {
            o.idle(&sim, self.steps);
        }
    }

    /// The simulation (the world and its subsystems), borrowed for reading.
    ///
    /// # Panics
    /// A script or a `sim.*` function holds it (never between two engine calls).
    pub fn sim(&self) -> Ref<'_, Sim> {
        self.sim.borrow()
    }

    /// The simulation, borrowed for writing: for front ends that change it between
    /// steps (the viewer's drag, a replay). Starting, pausing and stopping go through
    /// [`Engine::serve`].
    pub fn sim_mut(&self) -> RefMut<'_, Sim> {
        self.sim.borrow_mut()
    }

    /// The world (objects and physics), borrowed for reading.
    pub fn world(&self) -> Ref<'_, World> {
        Ref::map(self.sim.borrow(), |s| &s.world)
    }

    /// The world, borrowed for writing.
    pub fn world_mut(&self) -> RefMut<'_, World> {
        RefMut::map(self.sim.borrow_mut(), |s| &mut s.world)
    }

    /// The scene model a stop rebuilds the world from.
    pub fn model(&self) -> &SceneModel {
        &self.model
    }

    /// Each script's file, object and state (none without a Lua host).
    pub fn scripts(&self) -> Vec<(PathBuf, Handle, ScriptState)> {
        self.host.as_ref().map(LuaHost::scripts).unwrap_or_default()
    }

    /// The addresses scripts listen on now through LuaSocket (`socket.bind`).
    pub fn script_listeners(&self) -> Vec<std::net::SocketAddr> {
        self.host.as_ref().map(LuaHost::script_listeners).unwrap_or_default()
    }

    /// Whether this simulation runs with the script debugger.
    pub fn debugging(&self) -> bool {
        self.host.as_ref().is_some_and(LuaHost::debugging)
    }

    /// The simulation's state.
    pub fn state(&self) -> SimulationState {
        self.sim.borrow().state
    }

    /// Steps taken since the engine was made.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The time step, s.
    pub fn dt(&self) -> f64 {
        self.sim.borrow().world.settings().dt
    }

    /// Whether real-time pacing is on (see [`EngineConfig::realtime`]).
    pub fn realtime(&self) -> bool {
        self.config.realtime
    }

    /// Running, and no stepping client or lock holds the simulation.
    pub fn may_advance(&self) -> bool {
        self.state() == SimulationState::Running && self.stepping.may_advance(self.steps)
    }

    /// Whether some client is stepping: steps are then taken as soon as they are asked
    /// for, not in real time, as in CoppeliaSim.
    pub fn on_demand(&self) -> bool {
        self.stepping.any_stepping()
    }

    /// Whether `client` holds a lock (`sim.acquireLock`).
    pub fn holds_lock(&self, client: ClientId) -> bool {
        self.stepping.holds_lock(client)
    }

    /// When the next step may be taken, at `now`. While held, the real-time schedule
    /// restarts, so that time spent paused or held is not caught up afterwards.
    pub fn due(&mut self, now: Instant) -> Due {
        if !self.may_advance() {
            self.pacing.restart(now);
            return Due::Held;
        }
        if !self.config.realtime || self.on_demand() {
            return Due::Now;
        }
        let next = self.pacing.next_due(self.dt());
        if now >= next { Due::Now } else { Due::At(next) }
    }

    /// How many steps are due at `now`: all that real-time pacing owes (at most a
    /// simulated second's worth), one when stepping on demand or not in real time,
    /// none while held.
    pub fn due_steps(&mut self, now: Instant) -> u64 {
        match self.due(now) {
            Due::Held | Due::At(_) => 0,
            Due::Now if !self.config.realtime || self.on_demand() => 1,
            Due::Now => self.pacing.due_steps(now, self.dt()).max(1),
        }
    }

    /// Starts the real-time schedule afresh from `now`, after steps taken outside it
    /// (the in-process client's `advance(n)`).
    pub fn restart_pacing(&mut self, now: Instant) {
        self.pacing.restart(now);
    }

    /// A step was taken at `now` on the real-time schedule.
    pub(crate) fn pacing_taken(&mut self, now: Instant) {
        let dt = self.dt();
        self.pacing.taken(now, dt);
    }

    /// Carries out `input` (see [`Input`] for each kind and its [`Output`]): the one
    /// way into the simulation from outside it. The observers see the input first.
    pub fn serve(&mut self, input: Input<'_>) -> Output {
        self.observe_input(&input);
        match input {
            Input::Call { target, args } => Output::Values(self.call(target, args)),
            Input::Blocking { client, f, args, reply } => {
                self.call_blocking(client, f, args, reply);
                Output::Pending
            }
            Input::Packet(packet) => Output::Packet(self.packet(packet)),
            Input::Control(action) => Output::State(self.loop_control(action)),
            Input::Remote { client, op } => Output::Values(self.remote(client, op)),
            Input::Step { client, done } => {
                self.request_step(client, done);
                Output::Pending
            }
            Input::DropClient(client) => {
                self.drop_client(client);
                Output::Done
            }
            Input::LoadScene(path) => Output::Values(self.load_scene(path).map(|()| Vec::new())),
            Input::Edit { label, calls } => Output::Values(self.edit(label, calls)),
            Input::Undo(undo) => Output::Values(self.undo(undo)),
        }
    }

    /// See [`Input::Edit`].
    fn edit(&mut self, label: &str, calls: &[(String, Vec<Value>)]) -> Result<Vec<Value>, CallError> {
        let refuse = |why: String| CallError::failed(format!("edit '{label}'"), SimError::refused(why));
        if self.state() != SimulationState::Stopped {
            return Err(refuse(
                "the scene is edited while the simulation is stopped (CoppeliaSim's rule): stop it first".into(),
            ));
        }
        let before = SceneCopy::capture(&self.sim.borrow());
        let mut results = Vec::with_capacity(calls.len());
        for (k, (name, args)) in calls.iter().enumerate() {
            let outcome = match Target::resolve_or_error(name) {
                Ok(target @ Target::Core { function, .. }) => call_core(&self.sim, &target, function, args),
                Ok(other) => Err(refuse(format!(
                    "{} is not a scene edit (only the core sim.* functions are)",
                    other.qualified()
                ))),
                Err(e) => Err(e),
            };
            match outcome {
                Ok(values) => results.push(Value::Array(values)),
                Err(e) => {
                    // Nothing of a failed edit stays.
                    before.put_back(&mut self.sim.borrow_mut());
                    return Err(refuse(format!(
                        "call {} of {} failed, nothing changed: {e}",
                        k + 1,
                        calls.len()
                    )));
                }
            }
        }
        self.history.record(label, before);
        Ok(results)
    }

    /// See [`Input::Undo`].
    fn undo(&mut self, undo: bool) -> Result<Vec<Value>, CallError> {
        let what = if undo { "undo" } else { "redo" };
        if self.state() != SimulationState::Stopped {
            return Err(CallError::failed(
                what,
                SimError::refused("the scene is edited while the simulation is stopped: stop it first"),
            ));
        }
        let entry = if undo {
            self.history.take_undo()
        } else {
            self.history.take_redo()
        };
        let Some(entry) = entry else {
            return Ok(Vec::new());
        };
        let now = SceneCopy::capture(&self.sim.borrow());
        entry.scene.put_back(&mut self.sim.borrow_mut());
        let label = entry.label;
        let other = Entry {
            label: label.clone(),
            scene: now,
        };
        if undo {
            self.history.push_redo(other);
        } else {
            self.history.push_undo(other);
        }
        Ok(vec![Value::Str(label)])
    }

    /// How many edits can be undone and redone (see [`Input::Edit`]).
    pub fn history_depth(&self) -> (usize, usize) {
        self.history.depth()
    }

    /// Calls a resolved function for a remote client: a core function straight on the
    /// simulation, a function of the Lua host through it (script code it runs may
    /// start, pause or stop the simulation; that is carried out once it returns).
    fn call(&mut self, target: &Target, args: &[Value]) -> Result<Vec<Value>, CallError> {
        match *target {
            Target::Core { function, .. } => call_core(&self.sim, target, function, args),
            Target::ScriptHost(f) => {
                let host = self.host_mut().map_err(|e| no_host(f, &e))?;
                let out = host.call_script_host(f, args);
                self.carry_out_requests();
                self.serve_recording_request();
                out
            }
            Target::FrontEnd(_) => Err(CallError::NoSuchFunction(target.qualified())),
        }
    }

    /// See [`Input::Blocking`].
    fn call_blocking(&mut self, client: Option<ClientId>, f: ScriptHostFn, args: &[Value], reply: BlockingReply) {
        if self.state() == SimulationState::Stopped {
            let _ = reply.send(Err(stopped_error(f)));
            return;
        }
        self.blocking_ids += 1;
        let id = gantry_lua::BlockingId(self.blocking_ids);
        let started = match self.host_mut() {
            Ok(host) => host.start_blocking(id, f, args),
            Err(e) => gantry_lua::Blocking::Done(Err(no_host(f, &e))),
        };
        self.carry_out_requests();
        match started {
            gantry_lua::Blocking::Done(answer) => {
                let _ = reply.send(answer);
            }
            gantry_lua::Blocking::Waiting => {
                self.blocking.push(BlockingCall { id, client, f, reply });
                self.want_steps();
            }
        }
    }

    /// Whether a blocking call is in progress.
    pub fn has_blocking(&self) -> bool {
        !self.blocking.is_empty()
    }

    /// Resumes the blocking calls after a step and answers those that returned.
    pub(crate) fn resume_blocking(&mut self) {
        if self.blocking.is_empty() || self.state() != SimulationState::Running {
            return;
        }
        let Some(host) = self.host.as_mut() else {
            return;
        };
        // A call nobody waits for any more (its client left) goes no further.
        let (gone, kept): (Vec<_>, Vec<_>) = std::mem::take(&mut self.blocking)
            .into_iter()
            .partition(|c| c.reply.is_closed());
        self.blocking = kept;
        for c in gone {
            host.cancel_blocking(c.id);
        }
        let answers = host.resume_blocking();
        for (id, answer) in answers {
            if let Some(k) = self.blocking.iter().position(|c| c.id == id) {
                let _ = self.blocking.remove(k).reply.send(answer);
            }
        }
        self.carry_out_requests();
        self.want_steps();
    }

    /// Each stepping client with a blocking call in progress lets the simulation take
    /// the next step.
    fn want_steps(&mut self) {
        for c in &self.blocking {
            if let Some(client) = c.client {
                self.stepping.want_step(client, self.steps);
            }
        }
    }

    /// The simulation stopped or changed scene: the blocking calls end with an error.
    pub(crate) fn end_blocking(&mut self) {
        if let Some(host) = self.host.as_mut() {
            host.abort_blocking();
        }
        for c in self.blocking.drain(..) {
            let _ = c.reply.send(Err(ended_error(c.f)));
        }
    }

    /// The viewer's and the command line's control, [`LoopControl::Step`] included (a
    /// step whatever the state: a stopped or paused simulation starts, steps once and
    /// pauses). Returns the state afterwards.
    fn loop_control(&mut self, action: LoopControl) -> SimulationState {
        match action {
            LoopControl::Control(c) => self.control(c),
            LoopControl::Step => {
                if self.state() == SimulationState::Running {
                    self.step();
                } else {
                    self.control(Control::Start);
                    self.step();
                    self.control(Control::Pause);
                }
            }
        }
        self.state()
    }

    /// A remote client's simulation control or stepping call.
    ///
    /// # Errors
    /// Nesting too deep, in CoppeliaSim's words with the function's name.
    fn remote(&mut self, client: ClientId, op: RemoteOp) -> Result<Vec<Value>, CallError> {
        let in_function =
            |e: SteppingError, f: &str| CallError::failed(format!("sim.{f}"), SimError::refused(e.to_string()));
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

    /// See [`Input::Step`].
    fn request_step(&mut self, client: ClientId, done: oneshot::Sender<()>) {
        let advancing = self.state() == SimulationState::Running;
        self.stepping.request_step(client, self.steps, advancing, done);
    }

    /// See [`Input::DropClient`].
    fn drop_client(&mut self, client: ClientId) {
        self.stepping.drop_client(client);
        let (gone, kept) = std::mem::take(&mut self.blocking)
            .into_iter()
            .partition(|c| c.client == Some(client));
        self.blocking = kept;
        if let Some(host) = self.host.as_mut() {
            for c in gone {
                host.cancel_blocking(c.id);
            }
        }
    }

    /// No front end is left to release a hold: forget every client's stepping state.
    pub fn release_all_clients(&mut self) {
        self.stepping.clear();
    }

    /// `sim.loadScene(path)` (`Some`) or `sim.closeScene()` (`None`): the running
    /// simulation stops (its cleanup hooks run) and the new scene waits, stopped, for a
    /// start. The debugger's link and the listeners move to the new scene (the debug
    /// client sets its breakpoints again per file). A file that does not load leaves
    /// the current scene as it was (a Lua state that cannot be created leaves it
    /// stopped).
    fn load_scene(&mut self, path: Option<&Path>) -> Result<(), CallError> {
        let function = if path.is_some() {
            "sim.loadScene"
        } else {
            "sim.closeScene"
        };
        let refused = |e: &dyn std::fmt::Display| CallError::failed(function, SimError::refused(e.to_string()));
        let model = load_client_scene(path, &self.config.load_options).map_err(|e| refused(&e))?;
        let debug = self.host.as_mut().and_then(LuaHost::take_debug_link);
        // The old scene stops and its scripts release their ports before the new
        // scene's scripts bind theirs: a scene loaded again binds the same ones.
        self.control(Control::Stop);
        if let Some(host) = &self.host {
            host.close_sockets();
        }
        let sim = SimCell::new(build_sim(&model));
        // A client loaded this scene: nobody else reports its warnings.
        report_warnings(&model, &sim.borrow(), true);
        let host = if model.scripts.is_empty() && debug.is_none() {
            None
        } else {
            Some(
                Self::lua_host(&sim, &model, &self.config, debug, self.while_waiting.as_ref())
                    .map_err(|e| refused(&e))?,
            )
        };
        self.end_blocking();
        // The old host goes before the new simulation takes its place: its scripts'
        // cell is the old one.
        self.host = host;
        self.sim = sim;
        self.model = model;
        self.restore = None;
        self.history.clear();
        Ok(())
    }

    /// See [`Input::Packet`].
    fn packet(&mut self, packet: &Value) -> Result<Option<Vec<Value>>, HookError> {
        self.call_script_function("sysCall_packet", std::slice::from_ref(packet))
    }

    /// Calls the global function `name` of the first running script (in hook order)
    /// that defines it, as a client outside the scene: the text channel's
    /// `sysCall_packet`, an embedder's or a test's own functions. Script code it runs
    /// may start, pause or stop the simulation; that is carried out once it returns.
    /// `None`: no script defines it.
    ///
    /// # Errors
    /// The function raised an error (its script is then marked errored), or the values
    /// did not convert.
    pub fn call_script_function(&mut self, name: &str, args: &[Value]) -> Result<Option<Vec<Value>>, HookError> {
        let Some(host) = self.host.as_mut() else {
            return Ok(None);
        };
        let out = host.call_hook_function(name, args);
        self.carry_out_requests();
        self.serve_recording_request();
        out
    }

    /// Starts or stops the recording a script asked for, if one did. A recording
    /// that cannot start is an error line in the log (the script's call has returned).
    pub(crate) fn serve_recording_request(&mut self) {
        let Some(req) = self.host.as_ref().and_then(LuaHost::take_recording_request) else {
            return;
        };
        match req {
            gantry_lua::RecordingRequest::Stop => {
                if let Some(mut r) = self.recorder.take() {
                    r.finish(&self.sim.borrow(), self.steps);
                }
            }
            gantry_lua::RecordingRequest::Start { path, rate_hz, images } => {
                let started = match &self.config.recorder {
                    Some(f) => f.start(&self.sim.borrow(), self.steps, &path, rate_hz, &images),
                    None => Err(crate::observer::RecordingRefused(
                        "this front end cannot record".to_owned(),
                    )),
                };
                match started {
                    Ok(r) => {
                        if let Some(mut old) = self.recorder.replace(r) {
                            old.finish(&self.sim.borrow(), self.steps);
                        }
                    }
                    Err(e) => {
                        let msg = format!("sim.startRecording: cannot record to {}: {e}", path.display());
                        tracing::error!("{msg}");
                        self.sim.log(VERBOSITY_ERRORS, "recorder", &msg);
                    }
                }
            }
        }
    }

    /// Serves the debugger's requests that arrived while no script is stopped (a
    /// stopped script serves them itself).
    pub fn debug_poll(&mut self) {
        if let Some(host) = self.host.as_mut() {
            host.debug_poll();
        }
    }

    /// What happens between steps with time: edited scripts reload (every
    /// [`RELOAD_PERIOD`]) and, while stopped,
    /// scripts' `sysCall_nonSimulation` runs (every [`NON_SIMULATION_PERIOD`]).
    pub fn tick(&mut self, now: Instant) {
        self.serve_recording_request();
        if now.saturating_duration_since(self.last_reload) >= RELOAD_PERIOD {
            self.last_reload = now;
            self.reload_changed();
        }
        if self.state() == SimulationState::Stopped
            && now.saturating_duration_since(self.last_idle) >= NON_SIMULATION_PERIOD
        {
            self.last_idle = now;
            self.non_simulation();
        }
    }

    /// Reloads the scripts whose files changed on disk: the old version's cleanup runs
    /// (if the simulation runs), then the new one loads and initialises, with the world
    /// left as it is; one that fails to compile keeps the old version running and the
    /// error is logged. The scene model keeps the new source for the next stop.
    pub fn reload_changed(&mut self) {
        let Some(host) = self.host.as_mut() else {
            return;
        };
        for i in host.changed_on_disk() {
            self.reload(i);
        }
    }

    /// Reloads script `i` from its file (see [`Engine::reload_changed`]).
    pub fn reload(&mut self, i: usize) {
        let running = self.state() != SimulationState::Stopped;
        let Some(host) = self.host.as_mut() else {
            return;
        };
        if let Some(source) = host.reload(i, running)
            && let Some(s) = self.model.scripts.get_mut(i)
        {
            s.source = source;
        }
        self.carry_out_requests();
    }

    /// `sysCall_nonSimulation` of every script, if the simulation is stopped (see
    /// [`Engine::tick`]).
    pub fn non_simulation(&mut self) {
        if self.state() != SimulationState::Stopped {
            return;
        }
        if let Some(host) = self.host.as_mut() {
            host.non_simulation();
            self.carry_out_requests();
        }
    }

    /// Ends the run: cleanup hooks run (once; a second call does nothing), every
    /// parked client is answered, and the observers finish.
    pub fn finish(&mut self) {
        self.cleanup();
        self.stepping.stopped();
        let sim = self.sim.borrow();
        if let Some(mut r) = self.recorder.take() {
            r.finish(&sim, self.steps);
        }
        for o in &mut self.observers {
            o.finish(&sim, self.steps);
        }
    }
}

/// Logs what building `sim` from `model` warned of (unsupported features), and the
/// loader's own warnings too with `loader` (unknown keys, URDF features), each once.
fn report_warnings(model: &SceneModel, sim: &Sim, loader: bool) {
    for w in sim.world.warnings() {
        if loader || !model.warnings.contains(w) {
            tracing::warn!("{w}");
        }
    }
}

/// The Lua host's view of `while_waiting`: the engine's simulation bound in.
fn wait_service(sim: &SimCell, while_waiting: &WhileWaiting) -> WaitService {
    let (sim, f) = (sim.clone(), while_waiting.clone());
    Rc::new(move |slice| f(&sim, slice))
}

/// A core registry function called by a remote client (no emitting object), between
/// steps or at a phase boundary inside one: the world is borrowed for the call only.
pub(crate) fn call_core(
    sim: &SimCell,
    target: &Target,
    function: &ApiFunction,
    args: &[Value],
) -> Result<Vec<Value>, CallError> {
    let mut sim = sim
        .try_borrow_mut()
        .map_err(|_| CallError::failed(target.qualified(), SimError::refused("the world is busy")))?;
    function
        .invoke(&mut sim, &REMOTE, &Args::new(args))
        .map_err(|e| CallError::failed(target.qualified(), e))
}

/// A function of the Lua host called while no Lua state can be made.
fn no_host(f: ScriptHostFn, e: &ScriptError) -> CallError {
    CallError::failed(format!("sim.{}", f.name()), SimError::refused(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use gantry_sim_core::api::FrontEndFn;
    use gantry_sim_core::scene::load_client_scene;

    fn engine(realtime: bool) -> Engine {
        let model = load_client_scene(None, &LoadOptions::default()).expect("empty scene");
        Engine::new(
            model,
            EngineConfig {
                realtime,
                ..EngineConfig::default()
            },
            None,
        )
        .expect("engine")
    }

    const ME: ClientId = ClientId(1);

    fn control(e: &mut Engine, c: Control) {
        e.serve(Input::Control(LoopControl::Control(c)));
    }

    fn remote(e: &mut Engine, op: RemoteOp) -> Result<Vec<Value>, CallError> {
        e.serve(Input::Remote { client: ME, op }).into_values()
    }

    fn request_step(e: &mut Engine) -> oneshot::Receiver<()> {
        let (done, rx) = oneshot::channel();
        assert_eq!(e.serve(Input::Step { client: ME, done }), Output::Pending);
        rx
    }

    #[test]
    fn a_stepping_client_holds_the_simulation_until_it_steps() {
        let mut e = engine(true);
        control(&mut e, Control::Start);
        assert_eq!(e.due(Instant::now()), Due::Now);
        remote(&mut e, RemoteOp::SetStepping(true)).expect("stepping");
        assert_eq!(e.due(Instant::now()), Due::Held);
        let mut rx = request_step(&mut e);
        assert_eq!(e.due_steps(Instant::now()), 1);
        e.step();
        assert!(rx.try_recv().is_ok(), "the parked step is answered");
        assert_eq!(e.due(Instant::now()), Due::Held);
    }

    #[test]
    fn stop_resets_levels_and_pause_releases_waiters() {
        let mut e = engine(true);
        control(&mut e, Control::Start);
        remote(&mut e, RemoteOp::SetStepping(true)).expect("stepping");
        let mut rx = request_step(&mut e);
        control(&mut e, Control::Pause);
        assert!(rx.try_recv().is_ok());
        control(&mut e, Control::Stop);
        control(&mut e, Control::Start);
        // The level went back to 0 with the stop: the new run is not held.
        assert_eq!(e.due(Instant::now()), Due::Now);
    }

    #[test]
    fn free_running_follows_the_wall_clock() {
        let mut e = engine(true);
        control(&mut e, Control::Start);
        let now = Instant::now();
        assert_eq!(e.due_steps(now), 1);
        e.step();
        match e.due(Instant::now()) {
            Due::At(t) => assert!(t > now),
            other => panic!("expected a later step, got {other:?}"),
        }
        let mut fast = engine(false);
        control(&mut fast, Control::Start);
        fast.step();
        assert_eq!(fast.due(Instant::now()), Due::Now);
    }

    #[test]
    fn a_loop_step_from_stopped_starts_steps_and_pauses() {
        let mut e = engine(true);
        assert_eq!(
            e.serve(Input::Control(LoopControl::Step)),
            Output::State(SimulationState::Paused)
        );
        assert_eq!(e.steps(), 1);
    }

    #[test]
    fn a_scene_that_does_not_load_leaves_the_current_one() {
        let mut e = engine(true);
        control(&mut e, Control::Start);
        let err = e
            .serve(Input::LoadScene(Some(Path::new("/nonexistent/scene.toml"))))
            .into_values()
            .unwrap_err();
        assert!(err.to_string().ends_with("(in function 'sim.loadScene')"), "{err}");
        assert_eq!(e.state(), SimulationState::Running);
        e.serve(Input::LoadScene(None)).into_values().expect("empty scene");
        assert_eq!(e.state(), SimulationState::Stopped);
    }

    #[test]
    fn loop_functions_are_not_scene_calls() {
        let mut e = engine(true);
        let target = Target::FrontEnd(FrontEndFn::Step);
        let err = e
            .serve(Input::Call {
                target: &target,
                args: &[],
            })
            .into_values()
            .unwrap_err();
        assert!(matches!(err, CallError::NoSuchFunction(_)), "{err}");
    }

    #[test]
    fn a_scene_without_scripts_has_no_lua_until_a_client_needs_it() {
        let mut e = engine(false);
        assert!(e.host.is_none(), "no scripts, no Lua state");
        control(&mut e, Control::Start);
        e.step();
        assert!(e.host.is_none(), "stepping needs no Lua");
        let get_script = Target::resolve("sim.getScript").expect("resolves");
        let out = e.serve(Input::Call {
            target: &get_script,
            args: &[Value::Int(1)],
        });
        assert!(e.host.is_some(), "a function only Lua serves made the host: {out:?}");
    }
}
