//! A tap on the engine: what reached the simulation from outside, and each step taken,
//! as the engine carries them out. The recorder is one (`gantry_record::RecordTap`):
//! with the inputs at the steps they arrived, a recorded run can be simulated again
//! (`gantry verify`). The tap only looks; it cannot change what the engine does.

use std::path::Path;

use gantry_lua::{HookError, Simulation, StepBoundary};
use gantry_sim_core::Value;
use gantry_sim_core::api::{CallError, Target};

use crate::host_call::LoopControl;

/// One input, as the engine carried it out.
#[derive(Debug, Clone, Copy)]
pub enum EngineInput<'a> {
    /// A remote client's call of a core or script-host function.
    Call {
        /// The function.
        target: &'a Target,
        /// Its arguments.
        args: &'a [Value],
    },
    /// A text packet to the scripts' `sysCall_packet`.
    Packet(&'a Value),
    /// Start, pause, stop or a single step (the viewer, the command line, a remote
    /// client's `sim.startSimulation()`...).
    Control(LoopControl),
    /// `sim.loadScene(path)` or `sim.closeScene()`.
    LoadScene(Option<&'a Path>),
}

/// Where an input was served.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InputAt {
    /// Steps the engine had taken.
    pub step: u64,
    /// 0 between steps; `k > 0` at the `k`-th phase boundary inside the next step.
    pub boundary: u32,
}

/// Looks at the engine's inputs and steps (see the module docs).
pub trait Tap: Send {
    /// An input, before the engine carries it out.
    fn input(&mut self, sim: &Simulation, at: InputAt, input: EngineInput<'_>);
    /// A step was taken; `steps` counts the engine's steps.
    fn stepped(&mut self, sim: &Simulation, steps: u64);
    /// The run ended (its cleanup hooks ran).
    fn finish(&mut self, sim: &Simulation, steps: u64);
}

/// Starts the recordings scripts ask for (`sim.startRecording`): the front end's,
/// which knows the scene's files and where recordings may go.
pub trait RecorderFactory: Send + Sync + std::fmt::Debug {
    /// A tap recording into `path` from now on (the engine has taken `steps` steps).
    ///
    /// # Errors
    /// Why the recording cannot start (the file cannot be created...).
    fn start(
        &self,
        sim: &Simulation,
        steps: u64,
        path: &Path,
        rate_hz: Option<f64>,
        images: &[(String, f64)],
    ) -> Result<Box<dyn Tap>, String>;
}

/// The simulation between two phases of a step, as [`crate::Engine::step_with`] hands
/// it to the front end: calls and packets served here go through the tap too.
pub struct MidStep<'a> {
    pub(crate) sim: &'a mut Simulation,
    pub(crate) tap: Option<&'a mut (dyn Tap + 'static)>,
    pub(crate) at: InputAt,
    pub(crate) boundary: StepBoundary,
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

    /// Calls a resolved function for a remote client, mid-step.
    ///
    /// # Errors
    /// The function's error, with its qualified name.
    pub fn call(&mut self, target: &Target, args: &[Value]) -> Result<Vec<Value>, CallError> {
        if let Some(t) = self.tap.as_deref_mut() {
            t.input(self.sim, self.at, EngineInput::Call { target, args });
        }
        self.sim.call_target(target, args)
    }

    /// A text packet to the scripts' `sysCall_packet`, mid-step (see
    /// [`crate::Engine::packet`]).
    ///
    /// # Errors
    /// The handling script raised an error, or the values did not convert.
    pub fn packet(&mut self, packet: &Value) -> Result<Option<Vec<Value>>, HookError> {
        if let Some(t) = self.tap.as_deref_mut() {
            t.input(self.sim, self.at, EngineInput::Packet(packet));
        }
        self.sim
            .call_hook_function("sysCall_packet", std::slice::from_ref(packet))
    }
}
