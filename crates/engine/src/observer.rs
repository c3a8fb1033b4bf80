//! Observers of the engine: everything that watches a simulation from outside it (the
//! recorder, the ROS 2 graph's publisher, the viewer's frames) through one trait over
//! `&Sim`. An observer only looks; it cannot change what the engine does.
//!
//! The recorder (`gantry_record::RecordTap`) sees each input with the step and phase
//! boundary it was served at, and each step: with the inputs at the steps they arrived,
//! a recorded run can be simulated again (`gantry verify`). The ROS 2 graph publishes
//! after each step; the viewer's frame publisher after each step and, while nothing
//! steps, at the front end's idle ticks.

use std::path::Path;

use gantry_sim_core::api::Target;
use gantry_sim_core::{Sim, Value};

use crate::input::Input;

/// Where an input was served.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InputAt {
    /// Steps the engine had taken.
    pub step: u64,
    /// 0 between steps; `k > 0` at the `k`-th phase boundary inside the next step.
    pub boundary: u32,
}

/// Watches the engine's inputs and steps (see the module docs). Every method but
/// [`Observer::stepped`] does nothing by default. Observers run on the simulation
/// thread, so each must be cheap and decide quickly when it has nothing to do.
pub trait Observer {
    /// An input, before the engine carries it out.
    fn input(&mut self, _sim: &Sim, _at: InputAt, _input: &Input<'_>) {}
    /// A step was taken; `steps` counts the engine's steps (never reset by a stop).
    fn stepped(&mut self, sim: &Sim, steps: u64);
    /// The front end served requests or waited without stepping (the paused or
    /// stopped simulation still changes: a viewer moves an object, a script's
    /// `sysCall_nonSimulation` runs).
    fn idle(&mut self, _sim: &Sim, _steps: u64) {}
    /// The run ended (its cleanup hooks ran).
    fn finish(&mut self, _sim: &Sim, _steps: u64) {}
    /// Calls this observer asks the engine to carry out before the next step, as a
    /// front end's: an observer that also listens (the ROS 2 graph's joint command
    /// topics) hands its inputs over here rather than changing the simulation itself,
    /// so they are served, and recorded, like any client's.
    fn calls(&mut self) -> Vec<(Target, Vec<Value>)> {
        Vec::new()
    }
}

/// Starts the recordings scripts ask for (`sim.startRecording`): the front end's,
/// which knows the scene's files and where recordings may go.
pub trait RecorderFactory: Send + Sync + std::fmt::Debug {
    /// An observer recording into `path` from now on (the engine has taken `steps`
    /// steps).
    ///
    /// # Errors
    /// Why the recording cannot start (the file cannot be created...).
    fn start(
        &self,
        sim: &Sim,
        steps: u64,
        path: &Path,
        rate_hz: Option<f64>,
        images: &[(String, f64)],
    ) -> Result<Box<dyn Observer>, RecordingRefused>;
}

/// Why a recording a script asked for did not start: the text goes to the log.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct RecordingRefused(pub String);
