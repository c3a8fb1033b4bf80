//! The recorder on the engine: a [`Tap`] that snapshots the world after each step and
//! writes down every input with the step it arrived at, for the server's simulation
//! thread (`gantry run --record`) and the in-process Python client alike.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, PoisonError};

use gantry_engine::{EngineInput, InputAt, LoopControl, Tap};
use gantry_script::Simulation;
use gantry_sim_core::Value;
use gantry_sim_core::sim::Control;

use crate::input::Input;
use crate::recorder::{RecordReport, Recorder};

/// Records a run through the engine (see the module docs).
pub struct RecordTap {
    /// `None` once finished.
    recorder: Option<Recorder>,
    /// Whether the end of the recording is logged (not for `gantry verify`'s re-run).
    logged: bool,
    /// The engine's step count at each snapshot, when asked for (`gantry verify`
    /// names the step where two runs part).
    snapshot_steps: Option<Arc<Mutex<Vec<u64>>>>,
}

impl RecordTap {
    /// Taps with `recorder`; the state the simulation is in now is its first snapshot.
    pub fn new(recorder: Recorder, sim: &Simulation) -> Self {
        let mut recorder = recorder;
        recorder.record(&sim.core());
        Self {
            recorder: Some(recorder),
            logged: true,
            snapshot_steps: None,
        }
    }

    /// For a re-run (`gantry verify`): notes the engine's step count at each
    /// snapshot into `steps` (the first snapshot, taken by [`RecordTap::new`], is at
    /// step 0), and does not log the end of the recording.
    #[must_use]
    pub fn counting_steps(self, steps: Arc<Mutex<Vec<u64>>>) -> Self {
        steps.lock().unwrap_or_else(PoisonError::into_inner).push(0);
        Self {
            snapshot_steps: Some(steps),
            logged: false,
            ..self
        }
    }
}

impl Tap for RecordTap {
    fn input(&mut self, sim: &Simulation, at: InputAt, input: EngineInput<'_>) {
        if let Some(r) = &mut self.recorder {
            r.input(&sim.core(), to_input(at, input));
        }
    }

    fn stepped(&mut self, sim: &Simulation, steps: u64) {
        if let Some(r) = &mut self.recorder
            && r.is_writing()
            && r.record(&sim.core())
            && let Some(s) = &self.snapshot_steps
        {
            s.lock().unwrap_or_else(PoisonError::into_inner).push(steps);
        }
    }

    fn finish(&mut self, sim: &Simulation, steps: u64) {
        if let Some(r) = self.recorder.take() {
            let end = BTreeMap::from([("steps".to_owned(), steps.to_string())]);
            let r = r.finish(Some(&sim.core()), end);
            if self.logged {
                report(&r);
            }
        }
    }
}

/// The name of a start, pause, stop or single step on `/gantry/input`.
pub fn control_name(c: LoopControl) -> &'static str {
    match c {
        LoopControl::Control(Control::Start) => "start",
        LoopControl::Control(Control::Pause) => "pause",
        LoopControl::Control(Control::Stop) => "stop",
        LoopControl::Step => "step",
    }
}

/// An engine input as it is recorded.
fn to_input(at: InputAt, input: EngineInput<'_>) -> Input {
    let (kind, name, args) = match input {
        EngineInput::Call { target, args } => ("call", target.qualified(), args.to_vec()),
        EngineInput::Packet(p) => ("packet", String::new(), vec![p.clone()]),
        EngineInput::Control(c) => ("control", control_name(c).to_owned(), Vec::new()),
        EngineInput::LoadScene(Some(p)) => ("load_scene", p.display().to_string(), Vec::<Value>::new()),
        EngineInput::LoadScene(None) => ("close_scene", String::new(), Vec::new()),
    };
    Input {
        step: at.step,
        boundary: at.boundary,
        kind: kind.to_owned(),
        name,
        client: 0,
        args,
    }
}

/// Logs how a recording went: a warning with the count when snapshots were dropped,
/// an error when a write failed.
pub fn report(r: &RecordReport) {
    let path = r.path.display();
    if r.dropped > 0 {
        tracing::warn!(
            "recording {path}: {} of {} snapshots were dropped because the writer fell behind (queue full); \
             the file misses those steps (a lower --record-rate records fewer)",
            r.dropped,
            r.snapshots
        );
    }
    match &r.error {
        Some(e) => tracing::error!(
            "recording {path} stopped early: {e}; it holds what was written before ({} messages)",
            r.messages
        ),
        None => tracing::info!("recorded {} messages ({} snapshots) to {path}", r.messages, r.snapshots),
    }
}
