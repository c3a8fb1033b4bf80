//! The recorder on the engine: an [`Observer`] that snapshots the world after each step and
//! writes down every input with the step it arrived at, for the server's simulation
//! thread (`gantry run --record`) and the in-process Python client alike.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, PoisonError};

use std::path::Path;

use gantry_engine::{
    Input as EngineInput, InputAt, LoopControl, Observer, RecorderFactory, RecordingRefused, RemoteOp,
};
use gantry_ros::ImageStream;
use gantry_sim_core::api::Target;
use gantry_sim_core::sim::Control;
use gantry_sim_core::{Sim, Value};

use crate::recorder::{RecordParams, RecordReport, Recorder, RunDescription, with_causes};
use gantry_mcap::input::Input;

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
    pub fn new(recorder: Recorder, sim: &Sim) -> Self {
        let mut recorder = recorder;
        recorder.record(sim);
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

impl Observer for RecordTap {
    fn input(&mut self, sim: &Sim, at: InputAt, input: &EngineInput<'_>) {
        if let Some(r) = &mut self.recorder
            && let Some(input) = to_input(at, input)
        {
            r.input(sim, input);
        }
    }

    fn stepped(&mut self, sim: &Sim, steps: u64) {
        if let Some(r) = &mut self.recorder
            && r.is_writing()
            && r.record(sim)
            && let Some(s) = &self.snapshot_steps
        {
            s.lock().unwrap_or_else(PoisonError::into_inner).push(steps);
        }
    }

    fn finish(&mut self, sim: &Sim, steps: u64) {
        if let Some(r) = self.recorder.take() {
            let end = BTreeMap::from([("steps".to_owned(), steps.to_string())]);
            let r = r.finish(Some(sim), end);
            if self.logged {
                report(&r);
            }
        }
    }
}

/// Starts the recordings scripts ask for (`sim.startRecording`), of the run `run`
/// describes (its scene's files are attached to each).
#[derive(Clone)]
pub struct RunRecorder {
    run: RunDescription,
}

impl std::fmt::Debug for RunRecorder {
    /// The scene and the count of its files, not their bytes.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RunRecorder")
            .field("scene", &self.run.scene_name)
            .field("files", &self.run.files.len())
            .finish_non_exhaustive()
    }
}

impl RunRecorder {
    /// Recordings of `run`.
    pub fn new(run: RunDescription) -> Self {
        Self { run }
    }
}

impl RecorderFactory for RunRecorder {
    fn start(
        &self,
        sim: &Sim,
        steps: u64,
        path: &Path,
        rate_hz: Option<f64>,
        images: &[(String, f64)],
    ) -> Result<Box<dyn Observer>, RecordingRefused> {
        let images = images
            .iter()
            .map(|(sensor, rate_hz)| ImageStream {
                sensor: sensor.clone(),
                rate_hz: *rate_hz,
            })
            .collect();
        let mut params = RecordParams::for_run(path.to_path_buf(), rate_hz, self.run.clone()).with_images(images);
        params.metadata.insert("started_at_step".to_owned(), steps.to_string());
        let recorder = Recorder::create(params).map_err(|e| RecordingRefused(with_causes(&e)))?;
        tracing::info!("recording to {} (sim.startRecording at step {steps})", path.display());
        Ok(Box::new(RecordTap::new(recorder, sim)))
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

/// An engine input as it is recorded: what a re-run must carry out at the same point
/// (`gantry verify`). A blocking call is recorded as the call it is; stepping levels,
/// locks, `sim.step()` and clients leaving change no simulation state by themselves
/// and are not recorded.
fn to_input(at: InputAt, input: &EngineInput<'_>) -> Option<Input> {
    let (kind, name, args) = match *input {
        EngineInput::Call { target, args } => ("call", target.qualified(), args.to_vec()),
        EngineInput::Blocking { f, args, .. } => ("call", Target::ScriptHost(f).qualified(), args.to_vec()),
        EngineInput::Packet(p) => ("packet", String::new(), vec![p.clone()]),
        EngineInput::Control(c) => ("control", control_name(c).to_owned(), Vec::new()),
        EngineInput::Remote {
            op: RemoteOp::Control(c),
            ..
        } => ("control", control_name(LoopControl::Control(c)).to_owned(), Vec::new()),
        EngineInput::LoadScene(Some(p)) => ("load_scene", p.display().to_string(), Vec::<Value>::new()),
        EngineInput::LoadScene(None) => ("close_scene", String::new(), Vec::new()),
        EngineInput::Remote { .. } | EngineInput::Step { .. } | EngineInput::DropClient(_) => return None,
        // An edit's calls as a list of {name, args} pairs, so that a re-run makes them
        // again as one edit.
        EngineInput::Edit { label, calls } => (
            "edit",
            label.to_owned(),
            calls
                .iter()
                .map(|(name, args)| Value::Array(vec![Value::Str(name.clone()), Value::Array(args.clone())]))
                .collect(),
        ),
        EngineInput::Undo(undo) => (if undo { "undo" } else { "redo" }, String::new(), Vec::new()),
    };
    Some(Input {
        step: at.step,
        boundary: at.boundary,
        kind: kind.to_owned(),
        name,
        client: 0,
        args,
    })
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
