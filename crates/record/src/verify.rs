//! `gantry verify run.mcap`: simulates a recorded run again and says whether it
//! comes out identical.
//!
//! The scene is loaded from the recording's attachments (every file the loader read at
//! the start, at the paths it read them), with the recorded time step and substeps. The
//! recorded inputs (`/gantry/input`: remote calls, text packets, start/pause/stop and
//! single steps, each with the step and the phase boundary it arrived at) are fed to a
//! fresh [`Engine`] at the same points, for as many steps as the run took, and the new
//! run is recorded into memory at the recording's rate. Then every message of the
//! state topics (`/tf`, `/tf_static`, `/joint_states`, `/proximity/...`,
//! `/graph/...`, `/signal/...`, `/vision/...`) is compared, byte for byte, with the recording's: the encoding is
//! deterministic, so equal bytes mean equal numbers, bit for bit.
//!
//! What a re-run cannot reproduce, and so reports as a difference: what scripts read
//! for themselves (their own sockets, files, the wall clock), scripts edited and
//! reloaded during the run, viewer key presses, and another scene loaded mid-run
//! (refused: the recording holds only the first scene's files).

use std::collections::{BTreeMap, HashMap};
use std::io::{Cursor, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError};

use gantry_engine::{Engine, EngineConfig, Input as EngineInput, LoopControl, MidStep};
use gantry_mcap::AttachedFile;
use gantry_ros::ImageStream;
use gantry_sim_core::Value;
use gantry_sim_core::api::Target;
use gantry_sim_core::scene::SceneModel;
use gantry_sim_core::sim::Control;

use crate::recorder::{RecordParams, Recorder, with_causes};
use crate::scene::scene_from_files;
use crate::tap::RecordTap;
use gantry_mcap::format::FORMAT_VERSION;
use gantry_mcap::input::{INPUT_TOPIC, Input};

/// The topics compared: the simulation's state. `/rosout` is not (log lines may hold
/// wall-clock times), nor `/gantry/input` (the inputs are what is fed in).
pub fn is_state_topic(topic: &str) -> bool {
    matches!(topic, "/tf" | "/tf_static" | "/joint_states")
        || ["/proximity/", "/graph/", "/signal/", "/vision/"]
            .iter()
            .any(|p| topic.starts_with(p))
}

/// Why a recording cannot be verified.
#[derive(Debug, thiserror::Error)]
pub enum VerifyError {
    /// The file cannot be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// Not a readable MCAP file with a summary.
    #[error("{0} (gantry verify needs a complete recording: one whose run ended normally)")]
    NotReadable(String),
    /// An MCAP file, but not a gantry recording.
    #[error("not a gantry recording: it has no `gantry` metadata record")]
    NotGantry,
    /// Written by a later gantry.
    #[error(
        "this recording is format version {found}, written by gantry {by}; this gantry reads up to version {FORMAT_VERSION}: use a newer gantry"
    )]
    Newer {
        /// The file's version.
        found: u32,
        /// The gantry version that wrote it.
        by: String,
    },
    /// Something the re-run needs is missing or malformed.
    #[error("this recording cannot be re-run: {0}")]
    Incomplete(String),
    /// The scene does not load from the attachments.
    #[error("the recorded scene does not load: {0}")]
    Scene(String),
    /// The recording began after the run's start.
    #[error("this recording began at step {0} (sim.startRecording); a re-run needs the run from its first step")]
    StartedMidRun(u64),
    /// The run loaded another scene.
    #[error(
        "the run loaded another scene at step {0} (sim.loadScene/closeScene); only the first scene's files are recorded, so it cannot be re-run"
    )]
    LoadsScene(u64),
}

/// A recording, read for a re-run: its metadata, files, inputs and state messages.
#[derive(Debug, Clone)]
pub struct RecordedRun {
    /// The `gantry` metadata record.
    pub metadata: BTreeMap<String, String>,
    /// Steps the run took (`gantry_end`).
    pub steps: u64,
    /// Snapshots the recorder dropped because its writer fell behind (`gantry_end`).
    pub dropped: u64,
    /// Every attached file, named by the path it was read at.
    pub files: Vec<AttachedFile>,
    /// The inputs, in the order they arrived.
    pub inputs: Vec<Input>,
    /// The state topics' messages `(log time ns, CDR bytes)`, by topic.
    pub state: BTreeMap<String, Vec<(u64, Vec<u8>)>>,
}

/// What a re-run showed.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// Every state message equal.
    Identical {
        /// Steps re-simulated.
        steps: u64,
        /// State messages compared.
        messages: u64,
    },
    /// The runs part.
    Differs {
        /// The first step after which the state differs (the engine's step count).
        step: u64,
        /// Recording time of the first differing message, s.
        time_s: f64,
        /// Its topic.
        topic: String,
        /// What differs.
        detail: String,
    },
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Verdict::Identical { steps, messages } => {
                write!(
                    f,
                    "identical: {steps} steps re-simulated, {messages} state messages equal"
                )
            }
            Verdict::Differs {
                step,
                time_s,
                topic,
                detail,
            } => write!(
                f,
                "the runs part at step {step} (t = {time_s:.6} s of the recording): {topic}: {detail}"
            ),
        }
    }
}

impl RecordedRun {
    /// Reads the recording at `path`.
    ///
    /// # Errors
    /// The file cannot be read, or is not a complete gantry recording this version
    /// can re-run.
    pub fn open(path: &Path) -> Result<Self, VerifyError> {
        let bytes = std::fs::read(path).map_err(|source| VerifyError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_bytes(&bytes)
    }

    /// Reads a recording from its bytes.
    ///
    /// # Errors
    /// As [`RecordedRun::open`].
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, VerifyError> {
        let unreadable = |e: mcap::McapError| VerifyError::NotReadable(format!("not a readable MCAP file: {e}"));
        let summary = mcap::Summary::read(bytes)
            .map_err(unreadable)?
            .ok_or_else(|| VerifyError::NotReadable("the MCAP file has no summary (cut short?)".to_owned()))?;
        let mut records: HashMap<String, BTreeMap<String, String>> = HashMap::new();
        for index in &summary.metadata_indexes {
            let m = mcap::read::metadata(bytes, index).map_err(unreadable)?;
            records.insert(m.name, m.metadata);
        }
        let metadata = records.remove("gantry").ok_or(VerifyError::NotGantry)?;
        let version = match metadata.get("format_version") {
            Some(v) => v
                .parse::<u32>()
                .map_err(|_| VerifyError::Incomplete(format!("format_version {v:?} is not a number")))?,
            None => 1,
        };
        if version > FORMAT_VERSION {
            return Err(VerifyError::Newer {
                found: version,
                by: metadata
                    .get("gantry_version")
                    .cloned()
                    .unwrap_or_else(|| "?".to_owned()),
            });
        }
        let steps = records
            .get("gantry_end")
            .and_then(|m| m.get("steps"))
            .and_then(|s| s.parse().ok())
            .ok_or_else(|| VerifyError::Incomplete("the end of the run is not recorded (`gantry_end`)".to_owned()))?;
        let dropped = records
            .get("gantry_end")
            .and_then(|m| m.get("dropped_snapshots"))
            .and_then(|s| s.parse().ok())
            .unwrap_or(0);
        let mut files = Vec::new();
        for index in &summary.attachment_indexes {
            let a = mcap::read::attachment(bytes, index).map_err(unreadable)?;
            files.push(AttachedFile {
                name: a.name,
                media_type: a.media_type,
                data: a.data.into_owned(),
            });
        }
        let mut inputs = Vec::new();
        let mut state: BTreeMap<String, Vec<(u64, Vec<u8>)>> = BTreeMap::new();
        for m in mcap::MessageStream::new(bytes).map_err(unreadable)? {
            let m = m.map_err(unreadable)?;
            if m.channel.topic == INPUT_TOPIC {
                let i = Input::decode(&m.data)
                    .map_err(|e| VerifyError::Incomplete(format!("an input at {} ns: {e}", m.log_time)))?;
                inputs.push(i);
            } else if is_state_topic(&m.channel.topic) {
                state
                    .entry(m.channel.topic.clone())
                    .or_default()
                    .push((m.log_time, m.data.into_owned()));
            }
        }
        Ok(Self {
            metadata,
            steps,
            dropped,
            files,
            inputs,
            state,
        })
    }

    /// The recorded scene, loaded from the attachments as the run loaded it
    /// ([`scene_from_files`], which `gantry replay` uses too).
    ///
    /// # Errors
    /// The scene file is not attached, or does not load.
    pub fn scene_model(&self) -> Result<SceneModel, VerifyError> {
        scene_from_files(Path::new("(recording)"), &self.metadata, &self.files)
            .map_err(|e| VerifyError::Scene(with_causes(&e)))
    }

    /// Snapshots per simulated second the run was recorded at (`None`: every step).
    fn rate_hz(&self) -> Option<f64> {
        self.metadata.get("record_rate_hz").and_then(|r| r.parse().ok())
    }

    /// The image streams the run recorded (metadata `images`: `sensor=rate` lines).
    fn image_streams(&self) -> Vec<ImageStream> {
        let lines = self.metadata.get("images").map(String::as_str).unwrap_or_default();
        lines
            .lines()
            .filter_map(|l| {
                let (sensor, rate) = l.rsplit_once('=')?;
                Some(ImageStream {
                    sensor: sensor.to_owned(),
                    rate_hz: rate.parse().ok()?,
                })
            })
            .collect()
    }

    /// Simulates the run again with the recorded inputs and compares the state.
    ///
    /// # Errors
    /// The scene does not load, or the run did something a re-run cannot repeat.
    pub fn verify(&self) -> Result<Verdict, VerifyError> {
        let started = self
            .metadata
            .get("started_at_step")
            .and_then(|s| s.parse().ok())
            .unwrap_or(0);
        if started > 0 {
            return Err(VerifyError::StartedMidRun(started));
        }
        if self.dropped > 0 {
            return Err(VerifyError::Incomplete(format!(
                "{} snapshots were dropped while recording (the writer fell behind), so the recorded states \
                 cannot be matched step for step; record with a lower --record-rate",
                self.dropped
            )));
        }
        let model = self.scene_model()?;
        let config = EngineConfig {
            realtime: false,
            ..EngineConfig::default()
        };
        let mut engine = Engine::new(model, config, None).map_err(|e| VerifyError::Scene(e.to_string()))?;
        let buf = SharedBuf::default();
        let params = RecordParams {
            path: PathBuf::from("(re-run)"),
            rate_hz: self.rate_hz(),
            ..RecordParams::default()
        }
        .with_images(self.image_streams());
        let recorder =
            Recorder::with_writer(buf.clone(), params).map_err(|e| VerifyError::Incomplete(e.to_string()))?;
        let snapshot_steps = Arc::new(Mutex::new(Vec::new()));
        let tap = RecordTap::new(recorder, &engine.sim()).counting_steps(snapshot_steps.clone());
        engine.set_recorder(Box::new(tap));

        let mut next = 0;
        while engine.steps() < self.steps {
            let k = engine.steps();
            while let Some(i) = self.inputs.get(next).filter(|i| i.step == k && i.boundary == 0) {
                next += 1;
                apply(&mut engine, i)?;
                if engine.steps() != k {
                    break;
                }
            }
            if engine.steps() != k {
                continue;
            }
            let mid: Vec<&Input> = self.inputs[next..]
                .iter()
                .take_while(|i| i.step == k && i.boundary > 0)
                .collect();
            next += mid.len();
            engine.step_with(&mut |m: &mut MidStep<'_>| {
                let here = m.index();
                for i in mid.iter().filter(|i| i.boundary == here) {
                    apply_mid_step(m, i);
                }
            });
        }
        // Inputs after the last step (a stop, a last call).
        for i in &self.inputs[next..] {
            apply(&mut engine, i)?;
        }
        engine.finish();
        let rerun = Self::from_bytes(&buf.bytes())?;
        let steps = snapshot_steps.lock().unwrap_or_else(PoisonError::into_inner).clone();
        Ok(self.compare(&rerun, &steps))
    }

    /// The first state message that differs between `self` and `rerun`, or identical.
    /// `snapshot_steps[n]` is the step count at the re-run's `n`-th `/tf` message.
    fn compare(&self, rerun: &Self, snapshot_steps: &[u64]) -> Verdict {
        let mut first: Option<(u64, String, String)> = None;
        let mut messages = 0u64;
        let topics: std::collections::BTreeSet<&String> = self.state.keys().chain(rerun.state.keys()).collect();
        let empty = Vec::new();
        for topic in topics {
            let a = self.state.get(topic).unwrap_or(&empty);
            let b = rerun.state.get(topic).unwrap_or(&empty);
            let diff = a.iter().zip(b).position(|(x, y)| x != y);
            messages += diff.unwrap_or(a.len().min(b.len())) as u64;
            let found = match diff {
                Some(n) => {
                    let (ta, da) = &a[n];
                    let (tb, _) = &b[n];
                    let detail = if ta == tb {
                        format!("message {n} differs ({} bytes recorded)", da.len())
                    } else {
                        format!("message {n} is at {} ns in the recording, {} ns in the re-run", ta, tb)
                    };
                    Some(((*ta).min(*tb), detail))
                }
                None if a.len() != b.len() => {
                    let n = a.len().min(b.len());
                    let t = a.get(n).or_else(|| b.get(n)).map_or(0, |m| m.0);
                    Some((t, format!("{} messages recorded, {} in the re-run", a.len(), b.len())))
                }
                None => None,
            };
            if let Some((t, detail)) = found
                && first.as_ref().is_none_or(|(ft, _, _)| t < *ft)
            {
                first = Some((t, topic.clone(), detail));
            }
        }
        match first {
            None => Verdict::Identical {
                steps: self.steps,
                messages,
            },
            Some((t, topic, detail)) => {
                // The step of the last re-run snapshot at or before t.
                let tf = rerun.state.get("/tf").map(Vec::as_slice).unwrap_or_default();
                let n = tf.partition_point(|(lt, _)| *lt <= t);
                let step = n
                    .checked_sub(1)
                    .and_then(|i| snapshot_steps.get(i))
                    .copied()
                    .unwrap_or(0);
                Verdict::Differs {
                    step,
                    time_s: t as f64 * 1e-9,
                    topic,
                    detail,
                }
            }
        }
    }
}

/// Feeds one recorded input to the engine, between steps.
fn apply(engine: &mut Engine, i: &Input) -> Result<(), VerifyError> {
    match (i.kind.as_str(), i.name.as_str()) {
        ("call", name) => {
            // A function this gantry does not know failed in the run as it fails now.
            if let Ok(target) = Target::resolve_or_error(name) {
                engine.serve(EngineInput::Call {
                    target: &target,
                    args: &i.args,
                });
            }
        }
        ("packet", _) => {
            engine.serve(EngineInput::Packet(i.args.first().unwrap_or(&Value::Nil)));
        }
        ("control", name @ ("start" | "pause" | "stop" | "step")) => {
            let action = match name {
                "start" => LoopControl::Control(Control::Start),
                "pause" => LoopControl::Control(Control::Pause),
                "stop" => LoopControl::Control(Control::Stop),
                _ => LoopControl::Step,
            };
            engine.serve(EngineInput::Control(action));
        }
        ("edit", label) => {
            let mut calls = Vec::with_capacity(i.args.len());
            for c in &i.args {
                let pair = match c {
                    Value::Array(p) => p.as_slice(),
                    _ => &[],
                };
                let [Value::Str(name), Value::Array(args)] = pair else {
                    return Err(VerifyError::Incomplete(format!(
                        "an edit at step {} whose calls are not {{name, args}} pairs",
                        i.step
                    )));
                };
                calls.push((name.clone(), args.clone()));
            }
            engine.serve(EngineInput::Edit { label, calls: &calls });
        }
        ("undo" | "redo", _) => {
            engine.serve(EngineInput::Undo(i.kind == "undo"));
        }
        ("load_scene" | "close_scene", _) => return Err(VerifyError::LoadsScene(i.step)),
        (kind, name) => {
            return Err(VerifyError::Incomplete(format!(
                "an input of unknown kind {kind:?} ({name:?}) at step {}",
                i.step
            )));
        }
    }
    Ok(())
}

/// Feeds one recorded input to the engine at a boundary inside a step (only calls
/// and packets are served there).
fn apply_mid_step(m: &mut MidStep<'_>, i: &Input) {
    match i.kind.as_str() {
        "call" => {
            if let Ok(target) = Target::resolve_or_error(&i.name) {
                let _ = m.call(&target, &i.args);
            }
        }
        "packet" => {
            let _ = m.packet(i.args.first().unwrap_or(&Value::Nil));
        }
        _ => {}
    }
}

/// An in-memory file the re-run is recorded into, shared with the writer thread.
#[derive(Clone, Default)]
struct SharedBuf(Arc<Mutex<Cursor<Vec<u8>>>>);

impl SharedBuf {
    fn bytes(&self) -> Vec<u8> {
        self.0.lock().unwrap_or_else(PoisonError::into_inner).get_ref().clone()
    }
}

impl Write for SharedBuf {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.lock().unwrap_or_else(PoisonError::into_inner).write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl Seek for SharedBuf {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        self.0.lock().unwrap_or_else(PoisonError::into_inner).seek(pos)
    }
}
