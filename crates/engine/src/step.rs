//! One simulation step in CoppeliaSim's order, and the points inside it where the front
//! end may serve requests.
//!
//! One step: the scripts' UI and ROS callbacks and threads ([`LuaHost::begin_step`]),
//! every script's `sysCall_actuation` (children before parents), the physics substeps
//! and proximity sensors (`Sim::step_dynamics`), vision sensors with their
//! `sysCall_vision`, every script's `sysCall_sensing`, then simulation time advances
//! (`Sim::finish_step`) and what scripts asked for (a stop, a removal, a model) is
//! carried out. Scripts see the step's start time throughout the step, as in
//! CoppeliaSim. Without a Lua host a step is the world's alone.

use std::time::Instant;

use gantry_lua::{HookError, LuaHost, SimCell, StepBoundary};
use gantry_sim_core::Value;
use gantry_sim_core::api::{CallError, Target};
use gantry_sim_core::sim::SimulationState;
use gantry_sim_core::{Sim, SimError};

use crate::engine::{Engine, call_core};
use crate::input::Input;
use crate::observer::{InputAt, Observer};

/// The simulation between two phases of a step, as [`Engine::step_with`] hands it to
/// the front end: the calls and packets served here are seen by the observers too.
pub struct MidStep<'a> {
    sim: &'a SimCell,
    host: Option<&'a mut LuaHost>,
    recorder: &'a mut Option<Box<dyn Observer>>,
    observers: &'a mut [Box<dyn Observer>],
    at: InputAt,
    boundary: StepBoundary,
}

impl MidStep<'_> {
    /// Which boundary of the step this is: 1 for the first (as [`InputAt::boundary`]).
    pub fn index(&self) -> u32 {
        self.at.boundary
    }

    /// Which boundary this is (what may be served here).
    pub fn boundary(&self) -> StepBoundary {
        self.boundary
    }

    /// The simulation, to read between phases.
    pub fn sim(&self) -> std::cell::Ref<'_, Sim> {
        self.sim.borrow()
    }

    fn observe(&mut self, input: &Input<'_>) {
        let sim = self.sim.borrow();
        for o in self.recorder.iter_mut().chain(self.observers.iter_mut()) {
            o.input(&sim, self.at, input);
        }
    }

    /// Calls a resolved function for a remote client, mid-step. The front end serves
    /// here only what may run at this boundary (`Target::step_safety`): a function of
    /// the Lua host runs script code, which waits for the end of the step.
    ///
    /// # Errors
    /// The function's error, with its qualified name.
    pub fn call(&mut self, target: &Target, args: &[Value]) -> Result<Vec<Value>, CallError> {
        self.observe(&Input::Call { target, args });
        match *target {
            Target::Core { function, .. } => call_core(self.sim, target, function, args),
            Target::ScriptHost(_) | Target::FrontEnd(_) => Err(CallError::failed(
                target.qualified(),
                SimError::refused("this function is served between steps, not inside one"),
            )),
        }
    }

    /// A text packet to the scripts' `sysCall_packet`, mid-step (at a phase boundary:
    /// no script runs there).
    ///
    /// # Errors
    /// The handling script raised an error, or the values did not convert.
    pub fn packet(&mut self, packet: &Value) -> Result<Option<Vec<Value>>, HookError> {
        self.observe(&Input::Packet(packet));
        match self.host.as_deref_mut() {
            Some(host) => host.call_hook_function("sysCall_packet", std::slice::from_ref(packet)),
            None => Ok(None),
        }
    }
}

impl Engine {
    /// Takes one step (scripts' hooks in CoppeliaSim's order) and does what follows
    /// from it: the schedule moves on, parked clients whose step it was are answered,
    /// blocking calls resume, and a start, pause or stop a script asked for is carried
    /// out with what follows for the stepping clients. A stopped simulation starts
    /// first; a paused one does not move.
    pub fn step(&mut self) {
        self.step_with(&mut |_| {});
    }

    /// [`Engine::step`], letting `between` serve requests at the step's phase
    /// boundaries: after actuation, after physics and proximity sensing, and for each
    /// vision sensor with a `sysCall_vision`, after its render and after its callback.
    /// No script runs at those points, as CoppeliaSim serves remote clients between its
    /// scripts; the [`MidStep::boundary`] says what may be observed there.
    pub fn step_with(&mut self, between: &mut dyn FnMut(&mut MidStep<'_>)) {
        if !self.observers.is_empty() {
            self.serve_observers_calls();
        }
        self.take_step(between);
        self.after_step();
    }

    /// The calls observers that also listen handed over ([`Observer::calls`]), served
    /// as any client's before the step. A failing call is the observer's to report; it
    /// is logged here at debug level, as a client would get it.
    fn serve_observers_calls(&mut self) {
        let calls: Vec<(Target, Vec<Value>)> = self.observers.iter_mut().flat_map(|o| o.calls()).collect();
        for (target, args) in calls {
            if let Err(e) = self
                .serve(Input::Call {
                    target: &target,
                    args: &args,
                })
                .into_values()
            {
                tracing::debug!("{e}");
            }
        }
    }

    fn take_step(&mut self, between: &mut dyn FnMut(&mut MidStep<'_>)) {
        match self.state() {
            SimulationState::Stopped => self.control(gantry_sim_core::sim::Control::Start),
            SimulationState::Paused => return,
            SimulationState::Running => {}
        }
        // A script's sysCall_init may have stopped or paused the simulation.
        if self.state() != SimulationState::Running {
            return;
        }
        let step = self.steps;
        let mut boundary = 0u32;
        let Engine {
            sim,
            host,
            recorder,
            observers,
            ..
        } = self;
        let mut serve = |host: Option<&mut LuaHost>, at: StepBoundary| {
            boundary += 1;
            let mut mid = MidStep {
                sim,
                host,
                recorder,
                observers,
                at: InputAt { step, boundary },
                boundary: at,
            };
            between(&mut mid);
        };
        if let Some(h) = host.as_mut() {
            h.begin_step();
            h.actuation();
        }
        serve(host.as_mut(), StepBoundary::Phase);
        sim.borrow_mut().step_dynamics();
        serve(host.as_mut(), StepBoundary::Phase);
        if let Some(h) = host.as_mut() {
            h.vision(&mut |h: &mut LuaHost, at| serve(Some(h), at));
            h.sensing();
        }
        sim.borrow_mut().finish_step();
        self.carry_out_requests();
    }

    fn after_step(&mut self) {
        self.steps += 1;
        {
            let sim = self.sim.borrow();
            for o in self.recorder.iter_mut().chain(self.observers.iter_mut()) {
                o.stepped(&sim, self.steps);
            }
        }
        self.serve_recording_request();
        // Without real time there is no schedule to keep (and no clock to read: a
        // step of a small scene costs less than a microsecond).
        if self.config.realtime {
            let now = Instant::now();
            if self.on_demand() {
                // Stepping on demand: real time resumes from the last step taken.
                self.restart_pacing(now);
            } else {
                self.pacing_taken(now);
            }
        }
        self.resume_blocking();
        self.stepping.stepped(self.steps);
    }
}
