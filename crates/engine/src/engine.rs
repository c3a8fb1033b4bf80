//! The engine: the one owner of a running simulation's loop rules.
//!
//! Every front end reaches the simulation through an [`Engine`]: the server's
//! simulation thread (for the text channel, ZMQ, the legacy remote API, the viewer and
//! the debugger) and the in-process Python client. It decides when a step may be
//! taken (stepping levels, locks, real-time pacing), carries out start, pause and stop
//! with what follows from them for the stepping clients, replaces the scene, runs the
//! stopped simulation's `sysCall_nonSimulation` and reloads edited scripts. It owns no
//! socket, channel or thread and reads the clock only where a caller asks it to: the
//! front end decides how to wait and how to answer.

use gantry_sim_core::SimError;
use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use gantry_lua::ros::RosNetwork;
use gantry_lua::{
    DebugLink, HookError, Listeners, RecordingRequest, ScriptError, ScriptLimits, Simulation, StepBoundary,
};
use gantry_sim_core::Value;
use gantry_sim_core::api::{CallError, ScriptHostFn, Target};
use gantry_sim_core::scene::{LoadOptions, SceneModel, load_client_scene};
use gantry_sim_core::sim::{Control, SimulationState};
use tokio::sync::oneshot;

use crate::blocking::{BlockingCall, BlockingReply, ended_error, stopped_error};
use crate::host_call::{LoopControl, RemoteOp};
use crate::pacing::Pacing;
use crate::stepping::{ClientId, Stepping, SteppingError};
use crate::tap::{EngineInput, InputAt, MidStep, RecorderFactory, Tap};

/// How often scripts' `sysCall_nonSimulation` runs while the simulation is stopped:
/// about 20 times a second, as in CoppeliaSim.
pub const NON_SIMULATION_PERIOD: Duration = Duration::from_millis(50);

/// CoppeliaSim's `sim.verbosity_errors`: the level of the recorder's error lines.
const VERBOSITY_ERRORS: i64 = 200;

/// How often script files are checked for changes (hot reload).
pub const RELOAD_PERIOD: Duration = Duration::from_millis(500);

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

/// A simulation with its loop rules.
pub struct Engine {
    sim: Simulation,
    /// Steps taken since the engine was made; never reset (a stop does not rewind it),
    /// so remote clients' step targets stay comparable across a stop and start.
    steps: u64,
    stepping: Stepping,
    pacing: Pacing,
    config: EngineConfig,
    last_reload: Instant,
    last_idle: Instant,
    /// Looks at every input and step (the recorder), when set.
    tap: Option<Box<dyn Tap>>,
    /// Look at every step and the end of the run (the ROS 2 graph's publisher), for
    /// the engine's whole life.
    observers: Vec<Box<dyn Tap>>,
    /// Remote clients' blocking calls in progress, oldest first.
    blocking: Vec<BlockingCall>,
    /// The last blocking call's number.
    blocking_ids: u64,
}

impl Engine {
    /// The simulation of `model`, stopped, with the debugger on `debug` when given.
    ///
    /// # Errors
    /// The Lua state could not be created.
    pub fn new(model: SceneModel, config: EngineConfig, debug: Option<DebugLink>) -> Result<Self, ScriptError> {
        let sim = Self::simulation(model, &config, debug)?;
        let now = Instant::now();
        Ok(Self {
            sim,
            steps: 0,
            stepping: Stepping::default(),
            pacing: Pacing::new(now),
            config,
            last_reload: now,
            last_idle: now,
            tap: None,
            observers: Vec::new(),
            blocking: Vec::new(),
            blocking_ids: 0,
        })
    }

    /// Has `tap` look at every input and step from now on (see [`Tap`]); the tap
    /// already set, if any, is returned.
    pub fn set_tap(&mut self, tap: Box<dyn Tap>) -> Option<Box<dyn Tap>> {
        self.tap.replace(tap)
    }

    /// Has `observer` see every step and the end of the run, after the tap, for the
    /// engine's whole life (its inputs are not shown to it).
    pub fn add_observer(&mut self, observer: Box<dyn Tap>) {
        self.observers.push(observer);
    }

    /// Stops tapping: the tap is returned, not finished.
    pub fn take_tap(&mut self) -> Option<Box<dyn Tap>> {
        self.tap.take()
    }

    /// Tells the tap about an input served between steps.
    fn tap_input(&mut self, input: EngineInput<'_>) {
        if let Some(t) = &mut self.tap {
            let at = InputAt {
                step: self.steps,
                boundary: 0,
            };
            t.input(&self.sim, at, input);
        }
    }

    /// A scene's simulation with the engine's options, listeners and debugger: one
    /// recipe for the first scene and every scene loaded later.
    fn simulation(
        model: SceneModel,
        config: &EngineConfig,
        debug: Option<DebugLink>,
    ) -> Result<Simulation, ScriptError> {
        let mut sim = match debug {
            Some(link) => Simulation::with_debugger(model, config.limits.clone(), link)?,
            None => Simulation::new(model, config.limits.clone())?,
        };
        sim.set_load_options(config.load_options.clone());
        if let Some(l) = &config.listeners {
            sim.set_listeners(l.clone());
        }
        if let Some(n) = &config.ros {
            sim.set_ros_network(n.clone());
        }
        Ok(sim)
    }

    /// The simulation, to read.
    pub fn sim(&self) -> &Simulation {
        &self.sim
    }

    /// The simulation, for front ends that act on it directly (the viewer's closures,
    /// the debugger). A start, pause or stop made through it bypasses the stepping
    /// rules: use [`Engine::control`] for those.
    pub fn sim_mut(&mut self) -> &mut Simulation {
        &mut self.sim
    }

    /// The simulation's state.
    pub fn state(&self) -> SimulationState {
        self.sim.state()
    }

    /// Steps taken since the engine was made.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The time step, s.
    pub fn dt(&self) -> f64 {
        self.sim.world().settings().dt
    }

    /// Whether real-time pacing is on (see [`EngineConfig::realtime`]).
    pub fn realtime(&self) -> bool {
        self.config.realtime
    }

    /// Running, and no stepping client or lock holds the simulation.
    pub fn may_advance(&self) -> bool {
        self.sim.state() == SimulationState::Running && self.stepping.may_advance(self.steps)
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

    /// Takes one step (scripts' hooks in CoppeliaSim's order) and does what follows
    /// from it: the schedule moves on, parked clients whose step it was are answered,
    /// and a start, pause or stop a script asked for is followed by the stepping rules.
    pub fn step(&mut self) {
        self.sim.step();
        self.after_step();
    }

    /// [`Engine::step`], letting `between` serve requests at the step's phase
    /// boundaries (see [`Simulation::step_with`]) through a [`MidStep`], which the tap
    /// sees too.
    pub fn step_with(&mut self, between: &mut dyn FnMut(&mut MidStep<'_>)) {
        let step = self.steps;
        let mut boundary = 0u32;
        let tap = &mut self.tap;
        self.sim.step_with(&mut |sim: &mut Simulation, at: StepBoundary| {
            boundary += 1;
            let mut mid = MidStep {
                sim,
                tap: tap.as_deref_mut(),
                at: InputAt { step, boundary },
                boundary: at,
            };
            between(&mut mid);
        });
        self.after_step();
    }

    fn after_step(&mut self) {
        self.steps += 1;
        if let Some(t) = &mut self.tap {
            t.stepped(&self.sim, self.steps);
        }
        for o in &mut self.observers {
            o.stepped(&self.sim, self.steps);
        }
        self.serve_recording_request();
        let now = Instant::now();
        if self.on_demand() || !self.config.realtime {
            // Stepping on demand: real time resumes from the last step taken.
            self.pacing.restart(now);
        } else {
            self.pacing.taken(now, self.dt());
        }
        self.resume_blocking();
        self.stepping.stepped(self.steps);
        self.follow_state(SimulationState::Running);
    }

    /// A remote client's blocking call (`sim.wait`, `sim.waitForSignal`,
    /// `sim.moveToConfig`, `sim.moveToPose`): run up to its first wait now, then
    /// resumed after each step until it returns, when `reply` gets its answer. While
    /// `client` steps the simulation, its call takes the steps it needs, as its own
    /// `sim.step()` calls would. Refused while the simulation is stopped (the steps it
    /// waits for would never come); while paused, it waits.
    pub fn call_blocking(&mut self, client: Option<ClientId>, f: ScriptHostFn, args: &[Value], reply: BlockingReply) {
        if self.sim.state() == SimulationState::Stopped {
            let _ = reply.send(Err(stopped_error(f)));
            return;
        }
        let target = Target::ScriptHost(f);
        self.tap_input(EngineInput::Call { target: &target, args });
        let before = self.sim.state();
        self.blocking_ids += 1;
        let id = gantry_lua::BlockingId(self.blocking_ids);
        match self.sim.start_blocking(id, f, args) {
            gantry_lua::Blocking::Done(answer) => {
                let _ = reply.send(answer);
            }
            gantry_lua::Blocking::Waiting => {
                self.blocking.push(BlockingCall { id, client, f, reply });
                self.want_steps();
            }
        }
        self.follow_state(before);
    }

    /// Whether a blocking call is in progress.
    pub fn has_blocking(&self) -> bool {
        !self.blocking.is_empty()
    }

    /// Resumes the blocking calls after a step and answers those that returned.
    fn resume_blocking(&mut self) {
        if self.blocking.is_empty() || self.sim.state() != SimulationState::Running {
            return;
        }
        // A call nobody waits for any more (its client left) goes no further.
        let (gone, kept): (Vec<_>, Vec<_>) = std::mem::take(&mut self.blocking)
            .into_iter()
            .partition(|c| c.reply.is_closed());
        self.blocking = kept;
        for c in gone {
            self.sim.cancel_blocking(c.id);
        }
        for (id, answer) in self.sim.resume_blocking() {
            if let Some(k) = self.blocking.iter().position(|c| c.id == id) {
                let _ = self.blocking.remove(k).reply.send(answer);
            }
        }
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
    fn end_blocking(&mut self) {
        self.sim.abort_blocking();
        for c in self.blocking.drain(..) {
            let _ = c.reply.send(Err(ended_error(c.f)));
        }
    }

    /// After something that may have started, paused or stopped the simulation (a
    /// control call, a script's `sim.stopSimulation()`, a called script function), given
    /// the state `before` it: the stepping clients follow a change, and only a change
    /// (a call made while stopped must not reset their levels).
    fn follow_state(&mut self, before: SimulationState) {
        let now = self.sim.state();
        if now == before {
            return;
        }
        match now {
            SimulationState::Stopped => {
                self.stepping.stopped();
                self.end_blocking();
            }
            SimulationState::Paused => self.stepping.release_waiters(),
            SimulationState::Running => self.pacing.restart(Instant::now()),
        }
    }

    /// Start (or resume), pause or stop, whoever asks: a remote client, the viewer, the
    /// command line. A stop runs the cleanup hooks, restores the initial scene and
    /// resets every client's stepping level (as CoppeliaSim's add-on does, so a stopped
    /// client cannot hold the next run), even when the simulation was stopped already.
    pub fn control(&mut self, c: Control) {
        self.tap_input(EngineInput::Control(LoopControl::Control(c)));
        self.control_untapped(c);
    }

    /// [`Engine::control`] without telling the tap (part of an input it was told of).
    fn control_untapped(&mut self, c: Control) {
        let before = self.sim.state();
        match c {
            Control::Start => self.sim.start(),
            Control::Pause => {
                self.sim.pause();
                self.stepping.release_waiters();
            }
            Control::Stop => {
                self.sim.stop();
                self.stepping.stopped();
            }
        }
        self.follow_state(before);
    }

    /// The viewer's and the command line's control, [`LoopControl::Step`] included (a
    /// step whatever the state: a stopped or paused simulation starts, steps once and
    /// pauses). Returns the state afterwards.
    pub fn loop_control(&mut self, action: LoopControl) -> SimulationState {
        self.tap_input(EngineInput::Control(action));
        match action {
            LoopControl::Control(c) => self.control_untapped(c),
            LoopControl::Step => {
                if self.sim.state() == SimulationState::Running {
                    self.step();
                } else {
                    self.control_untapped(Control::Start);
                    self.step();
                    self.control_untapped(Control::Pause);
                }
            }
        }
        self.sim.state()
    }

    /// A remote client's simulation control or stepping call.
    ///
    /// # Errors
    /// Nesting too deep, in CoppeliaSim's words with the function's name.
    pub fn remote(&mut self, client: ClientId, op: RemoteOp) -> Result<Vec<Value>, CallError> {
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

    /// `sim.step()` of `client`: `done` is answered once the simulation has taken the
    /// next step, at once if it is stopped or paused (see [`Stepping::request_step`]).
    pub fn request_step(&mut self, client: ClientId, done: oneshot::Sender<()>) {
        let advancing = self.sim.state() == SimulationState::Running;
        self.stepping.request_step(client, self.steps, advancing, done);
    }

    /// A client left or timed out: it can no longer hold the simulation.
    pub fn drop_client(&mut self, client: ClientId) {
        self.stepping.drop_client(client);
        let (gone, kept) = std::mem::take(&mut self.blocking)
            .into_iter()
            .partition(|c| c.client == Some(client));
        self.blocking = kept;
        for c in gone {
            self.sim.cancel_blocking(c.id);
        }
    }

    /// No front end is left to release a hold: forget every client's stepping state.
    pub fn release_all_clients(&mut self) {
        self.stepping.clear();
    }

    /// Calls a resolved function for a remote client. Script code it runs may start,
    /// pause or stop the simulation; the stepping clients follow.
    ///
    /// # Errors
    /// The function's error, with its qualified name.
    pub fn call(&mut self, target: &Target, args: &[Value]) -> Result<Vec<Value>, CallError> {
        self.tap_input(EngineInput::Call { target, args });
        let before = self.sim.state();
        let out = self.sim.call_target(target, args);
        self.follow_state(before);
        self.serve_recording_request();
        out
    }

    /// `sim.loadScene(path)` (`Some`) or `sim.closeScene()` (`None`): the running
    /// simulation stops (its cleanup hooks run) and the new scene waits, stopped, for a
    /// start. The debugger's link and the listeners move to the new scene (the debug
    /// client sets its breakpoints again per file). A file that does not load leaves
    /// the current scene as it was (a Lua state that cannot be created leaves it
    /// stopped).
    ///
    /// # Errors
    /// The scene does not load, in CoppeliaSim's words with the function's name.
    pub fn load_scene(&mut self, path: Option<&Path>) -> Result<(), CallError> {
        self.tap_input(EngineInput::LoadScene(path));
        let function = if path.is_some() {
            "sim.loadScene"
        } else {
            "sim.closeScene"
        };
        let refused = |e: &dyn std::fmt::Display| CallError::failed(function, SimError::refused(e.to_string()));
        let model = load_client_scene(path, &self.config.load_options).map_err(|e| refused(&e))?;
        let debug = self.sim.take_debug_link();
        // The old scene stops and its scripts release their ports before the new
        // scene's scripts bind theirs: a scene loaded again binds the same ones.
        self.control_untapped(Control::Stop);
        self.sim.close_sockets();
        let sim = Self::simulation(model, &self.config, debug).map_err(|e| refused(&e))?;
        self.end_blocking();
        self.sim = sim;
        Ok(())
    }

    /// A text packet to the scripts' `sysCall_packet(packet)`, between steps: the first
    /// running script that defines it answers (`None`: none does). Script code it runs
    /// may start, pause or stop the simulation; the stepping clients follow.
    ///
    /// # Errors
    /// The handling script raised an error, or the values did not convert.
    pub fn packet(&mut self, packet: &Value) -> Result<Option<Vec<Value>>, HookError> {
        self.tap_input(EngineInput::Packet(packet));
        let before = self.sim.state();
        let out = self
            .sim
            .call_hook_function("sysCall_packet", std::slice::from_ref(packet));
        self.follow_state(before);
        self.serve_recording_request();
        out
    }

    /// Starts or stops the recording a script asked for, if one did. A recording
    /// that cannot start is an error line in the log (the script's call has returned).
    fn serve_recording_request(&mut self) {
        let Some(req) = self.sim.take_recording_request() else {
            return;
        };
        match req {
            RecordingRequest::Stop => {
                if let Some(mut t) = self.tap.take() {
                    t.finish(&self.sim, self.steps);
                }
            }
            RecordingRequest::Start { path, rate_hz, images } => {
                let started = match &self.config.recorder {
                    Some(f) => f.start(&self.sim, self.steps, &path, rate_hz, &images),
                    None => Err("this front end cannot record".to_owned()),
                };
                match started {
                    Ok(tap) => {
                        if let Some(mut old) = self.tap.replace(tap) {
                            old.finish(&self.sim, self.steps);
                        }
                    }
                    Err(e) => {
                        let msg = format!("sim.startRecording: cannot record to {}: {e}", path.display());
                        tracing::error!("{msg}");
                        let mut core = self.sim.core_mut();
                        let t = core.world.time();
                        core.world.log.push(t, VERBOSITY_ERRORS, "recorder", &msg);
                    }
                }
            }
        }
    }

    /// What happens between steps with time: edited scripts reload (every
    /// [`RELOAD_PERIOD`]) and, while stopped, scripts' `sysCall_nonSimulation` runs
    /// (every [`NON_SIMULATION_PERIOD`]).
    pub fn tick(&mut self, now: Instant) {
        self.serve_recording_request();
        if now.saturating_duration_since(self.last_reload) >= RELOAD_PERIOD {
            self.last_reload = now;
            self.sim.reload_changed();
        }
        if self.sim.state() == SimulationState::Stopped
            && now.saturating_duration_since(self.last_idle) >= NON_SIMULATION_PERIOD
        {
            self.last_idle = now;
            self.sim.non_simulation();
        }
    }

    /// Ends the run: cleanup hooks run (once; a second call does nothing) and every
    /// parked client is answered.
    pub fn finish(&mut self) {
        self.sim.cleanup();
        self.stepping.stopped();
        if let Some(mut t) = self.tap.take() {
            t.finish(&self.sim, self.steps);
        }
        for o in &mut self.observers {
            o.finish(&self.sim, self.steps);
        }
    }
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

    #[test]
    fn a_stepping_client_holds_the_simulation_until_it_steps() {
        let mut e = engine(true);
        e.control(Control::Start);
        assert_eq!(e.due(Instant::now()), Due::Now);
        e.remote(ME, RemoteOp::SetStepping(true)).expect("stepping");
        assert_eq!(e.due(Instant::now()), Due::Held);
        let (done, mut rx) = oneshot::channel();
        e.request_step(ME, done);
        assert_eq!(e.due_steps(Instant::now()), 1);
        e.step();
        assert!(rx.try_recv().is_ok(), "the parked step is answered");
        assert_eq!(e.due(Instant::now()), Due::Held);
    }

    #[test]
    fn stop_resets_levels_and_pause_releases_waiters() {
        let mut e = engine(true);
        e.control(Control::Start);
        e.remote(ME, RemoteOp::SetStepping(true)).expect("stepping");
        let (done, mut rx) = oneshot::channel();
        e.request_step(ME, done);
        e.control(Control::Pause);
        assert!(rx.try_recv().is_ok());
        e.control(Control::Stop);
        e.control(Control::Start);
        // The level went back to 0 with the stop: the new run is not held.
        assert_eq!(e.due(Instant::now()), Due::Now);
    }

    #[test]
    fn free_running_follows_the_wall_clock() {
        let mut e = engine(true);
        e.control(Control::Start);
        let now = Instant::now();
        assert_eq!(e.due_steps(now), 1);
        e.step();
        match e.due(Instant::now()) {
            Due::At(t) => assert!(t > now),
            other => panic!("expected a later step, got {other:?}"),
        }
        let mut fast = engine(false);
        fast.control(Control::Start);
        fast.step();
        assert_eq!(fast.due(Instant::now()), Due::Now);
    }

    #[test]
    fn a_loop_step_from_stopped_starts_steps_and_pauses() {
        let mut e = engine(true);
        assert_eq!(e.loop_control(LoopControl::Step), SimulationState::Paused);
        assert_eq!(e.steps(), 1);
    }

    #[test]
    fn a_scene_that_does_not_load_leaves_the_current_one() {
        let mut e = engine(true);
        e.control(Control::Start);
        let err = e.load_scene(Some(Path::new("/nonexistent/scene.toml"))).unwrap_err();
        assert!(err.to_string().ends_with("(in function 'sim.loadScene')"), "{err}");
        assert_eq!(e.state(), SimulationState::Running);
        e.load_scene(None).expect("empty scene");
        assert_eq!(e.state(), SimulationState::Stopped);
    }

    #[test]
    fn loop_functions_are_not_scene_calls() {
        let mut e = engine(true);
        let err = e.call(&Target::FrontEnd(FrontEndFn::Step), &[]).unwrap_err();
        assert!(matches!(err, CallError::NoSuchFunction(_)), "{err}");
    }
}
