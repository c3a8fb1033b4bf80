//! The recorder: a [`Sampler`] on the simulation thread, an [`McapSink`] on a writer
//! thread of its own, and a bounded queue between them.
//!
//! The simulation thread never waits for the disk. [`Recorder::record`] takes a
//! snapshot (plain numbers) and, every [`BATCH`] snapshots, offers the batch to the
//! queue; when the queue is full the batch is dropped and its snapshots counted, and
//! the count is reported at the end. When a
//! write fails (disk full, a file system gone read-only), the writer logs the error
//! once, tries to end the file properly and stops; the recorder then stops sampling
//! and the simulation goes on.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, SyncSender, TrySendError};
use std::thread::JoinHandle;

use gantry_ros::{ImageStream, LogSample, Sampler, Snapshot};
use gantry_sim_core::Sim;

use crate::writer::McapSink;
use gantry_mcap::format::{AttachedFile, FORMAT_VERSION};
use gantry_mcap::input::Input;

/// Batches waiting for the writer by default: a few seconds of a busy scene.
pub const DEFAULT_QUEUE: usize = 64;

/// Snapshots sent to the writer together. Waking the writer thread costs more than
/// encoding a snapshot (tens of microseconds on a loaded virtual machine), so it is
/// woken once per batch; a batch is at most a second of a 16 Hz recording.
pub const BATCH: usize = 16;

/// Longest wall-clock time a snapshot waits on the simulation thread for its batch
/// to fill, and a written message waits in the writer's open chunk: what a process
/// killed mid-run (power cut, SIGKILL) loses at most, since the chunks before it are
/// complete on disk and readable without the summary.
pub const FLUSH_EVERY: std::time::Duration = std::time::Duration::from_secs(1);

/// What to record and where.
#[derive(Debug, Clone, Default)]
pub struct RecordParams {
    /// The MCAP file to write (created, or truncated).
    pub path: PathBuf,
    /// Snapshots per simulated second (`None`: one per step).
    pub rate_hz: Option<f64>,
    /// Batches of [`BATCH`] snapshots that may wait for the writer before new ones
    /// are dropped (0: [`DEFAULT_QUEUE`]).
    pub queue: usize,
    /// Entries of the `gantry` metadata record (version, command line, dt...).
    pub metadata: BTreeMap<String, String>,
    /// Files attached at the start (the scene, its scripts).
    pub attachments: Vec<AttachedFile>,
    /// Vision sensors whose images are recorded, each at its rate.
    pub images: Vec<ImageStream>,
}

/// The run a recording holds, for its metadata and attachments.
#[derive(Debug, Clone, Default)]
pub struct RunDescription {
    /// The scene's name.
    pub scene_name: String,
    /// The path the scene was loaded from, as the loader read it (`/embedded/...`
    /// for a bundled scene): an attachment's name.
    pub scene_path: PathBuf,
    /// Every file the loader read (see `gantry_sim_core::scene::LoggedFiles`), by
    /// the path it was read at.
    pub files: Vec<(PathBuf, Vec<u8>)>,
    /// Where `package://` URIs were looked for.
    pub package_paths: Vec<PathBuf>,
    /// Whether URDF bases were left free.
    pub free_base: bool,
    /// Whether the scene's scripts ran (the Python client's `scripts=False` leaves
    /// them out).
    pub scripts: bool,
    /// The time step, s, and physics substeps per step (after command-line overrides).
    pub dt: f64,
    /// Physics substeps per step.
    pub substeps: u32,
    /// The seed of the run's pseudo-random numbers (scripts' `math.random`).
    pub seed: i64,
    /// The command line (or the Python call) that started the run.
    pub command_line: String,
}

impl RecordParams {
    /// What to record for `run` into `path`, at most `rate_hz` snapshots per simulated
    /// second: the `gantry` metadata record and every file the scene was loaded from.
    pub fn for_run(path: PathBuf, rate_hz: Option<f64>, run: RunDescription) -> Self {
        let package_paths: Vec<String> = run.package_paths.iter().map(|p| p.display().to_string()).collect();
        let metadata = [
            ("format_version", FORMAT_VERSION.to_string()),
            ("gantry_version", env!("CARGO_PKG_VERSION").to_owned()),
            ("command_line", run.command_line),
            ("scene", run.scene_name),
            ("scene_path", run.scene_path.display().to_string()),
            ("package_paths", package_paths.join("\n")),
            ("free_base", run.free_base.to_string()),
            // A recording a script starts later says at which step (see RunRecorder).
            ("started_at_step", "0".to_owned()),
            ("scripts", run.scripts.to_string()),
            ("dt", run.dt.to_string()),
            ("substeps", run.substeps.to_string()),
            ("seed", run.seed.to_string()),
            (
                "record_rate_hz",
                rate_hz.map_or_else(|| "every step".to_owned(), |r| r.to_string()),
            ),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_owned(), v))
        .collect();
        let attachments = run
            .files
            .into_iter()
            .map(|(p, data)| AttachedFile {
                media_type: media_type(&p).to_owned(),
                name: p.display().to_string(),
                data,
            })
            .collect();
        Self {
            path,
            rate_hz,
            queue: 0,
            metadata,
            attachments,
            images: Vec::new(),
        }
    }
}

impl RecordParams {
    /// Also records the images of `streams` (noted in the metadata as `images`, one
    /// `sensor=rate` per line, so that `gantry verify` records the same).
    #[must_use]
    pub fn with_images(mut self, streams: Vec<ImageStream>) -> Self {
        let text: Vec<String> = streams.iter().map(|s| format!("{}={}", s.sensor, s.rate_hz)).collect();
        self.metadata.insert("images".to_owned(), text.join("\n"));
        self.images = streams;
        self
    }
}

/// The media type of an attached file, from its extension.
fn media_type(p: &Path) -> &'static str {
    match p
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("toml") => "application/toml",
        Some("urdf" | "xml" | "sdf") => "application/xml",
        Some("lua") => "text/x-lua",
        Some("stl") => "model/stl",
        Some("obj") => "model/obj",
        Some("dae") => "model/vnd.collada+xml",
        Some("ttt" | "ttm") => "application/x-coppeliasim",
        _ => "application/octet-stream",
    }
}

/// Why recording could not start.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// The file could not be created.
    #[error("cannot record to {path} (check that the folder exists and is writable)")]
    Create {
        /// The file.
        path: PathBuf,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// The MCAP header could not be written.
    #[error("cannot record to {path}: the MCAP header could not be written")]
    Start {
        /// The file.
        path: PathBuf,
        /// What the MCAP writer said.
        #[source]
        source: mcap::McapError,
    },
    /// The writer thread could not be started.
    #[error("cannot start the recording thread: {0}")]
    Thread(#[source] std::io::Error),
}

/// How a recording went, from [`Recorder::finish`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecordReport {
    /// The file.
    pub path: PathBuf,
    /// Snapshots taken (written or dropped).
    pub snapshots: u64,
    /// Snapshots dropped because the writer had fallen behind (queue full).
    pub dropped: u64,
    /// Messages written.
    pub messages: u64,
    /// The write error that stopped the recording, if one did.
    pub error: Option<String>,
}

/// What goes through the queue.
enum Item {
    /// Snapshots of consecutive steps, and the inputs that arrived since the last
    /// batch, each with its recording time.
    Batch(Vec<Snapshot>, Vec<(u64, Input)>),
    /// Log lines after the last step (cleanup hooks).
    Logs(Vec<LogSample>),
    /// The `gantry_end` metadata record (steps taken, snapshots dropped).
    End(BTreeMap<String, String>),
}

/// What the writer thread ends with.
struct WriterOutcome {
    messages: u64,
    error: Option<String>,
}

/// Records a simulation into an MCAP file (see the module docs).
pub struct Recorder {
    path: PathBuf,
    sampler: Sampler,
    /// Snapshots go to the writer thread here; `None` once it stopped (an error) or
    /// the recording finished. Only the recorder sends; dropping it ends the file.
    tx: Option<SyncSender<Item>>,
    /// The writer thread, joined by [`Recorder::finish`].
    thread: Option<JoinHandle<WriterOutcome>>,
    /// Snapshots not sent yet: the batch being filled.
    pending: Vec<Snapshot>,
    /// When the last batch was offered.
    last_offer: std::time::Instant,
    /// Inputs not sent yet. Unlike snapshots they are never dropped (a re-run needs
    /// every one): a batch that does not fit leaves its inputs for the next.
    inputs: Vec<(u64, Input)>,
    snapshots: u64,
    dropped: u64,
}

impl Recorder {
    /// Creates `params.path` and starts the writer thread.
    ///
    /// # Errors
    /// The file cannot be created, or the thread cannot start.
    pub fn create(params: RecordParams) -> Result<Self, RecordError> {
        let file = File::create(&params.path).map_err(|source| RecordError::Create {
            path: params.path.clone(),
            source,
        })?;
        Self::with_writer(BufWriter::with_capacity(1 << 16, file), params)
    }

    /// [`Recorder::create`] writing to `w` instead of a file (`params.path` only names
    /// it in messages).
    ///
    /// # Errors
    /// The MCAP header cannot be written, or the thread cannot start.
    pub fn with_writer<W: Write + Seek + Send + 'static>(w: W, params: RecordParams) -> Result<Self, RecordError> {
        let path = params.path.clone();
        let sink = McapSink::new(w).map_err(|source| RecordError::Start {
            path: path.clone(),
            source,
        })?;
        let queue = if params.queue == 0 { DEFAULT_QUEUE } else { params.queue };
        let (tx, rx) = mpsc::sync_channel(queue);
        let thread_path = path.clone();
        let rate_hz = params.rate_hz;
        let sampler = Sampler::new(rate_hz).with_images(&params.images);
        let thread = std::thread::Builder::new()
            .name("gantry-record".into())
            .spawn(move || write_loop(sink, rx, &params, &thread_path))
            .map_err(RecordError::Thread)?;
        Ok(Self {
            path,
            sampler,
            tx: Some(tx),
            thread: Some(thread),
            pending: Vec::with_capacity(BATCH),
            last_offer: std::time::Instant::now(),
            inputs: Vec::new(),
            snapshots: 0,
            dropped: 0,
        })
    }

    /// Records `sim` as it is now, if a snapshot is due (after a step; see
    /// [`Sampler::sample`]); returns whether one was taken. Never blocks.
    pub fn record(&mut self, sim: &Sim) -> bool {
        if self.tx.is_none() {
            return false;
        }
        let Some(s) = self.sampler.sample(sim) else {
            return false;
        };
        self.snapshots += 1;
        self.pending.push(s);
        if self.pending.len() >= BATCH || self.last_offer.elapsed() >= FLUSH_EVERY {
            let batch = std::mem::replace(&mut self.pending, Vec::with_capacity(BATCH));
            self.offer(batch);
        }
        true
    }

    /// Records an input that reached the simulation now (see [`crate::input`]). It
    /// is written with the next batch of snapshots.
    pub fn input(&mut self, sim: &Sim, input: Input) {
        if self.tx.is_some() {
            self.inputs.push((self.sampler.log_time_now(sim), input));
        }
    }

    /// Queues a batch with the pending inputs, or counts its snapshots dropped (the
    /// inputs wait for the next batch).
    fn offer(&mut self, batch: Vec<Snapshot>) {
        self.last_offer = std::time::Instant::now();
        let Some(tx) = &self.tx else { return };
        let inputs = std::mem::take(&mut self.inputs);
        match tx.try_send(Item::Batch(batch, inputs)) {
            Ok(()) => {}
            Err(TrySendError::Full(Item::Batch(b, inputs))) => {
                self.dropped += b.len() as u64;
                self.inputs = inputs;
            }
            Err(TrySendError::Full(_)) => {}
            // The writer stopped on an error (it said so): stop sampling.
            Err(TrySendError::Disconnected(_)) => self.tx = None,
        }
    }

    /// Whether the recording still writes (no write error so far).
    pub fn is_writing(&self) -> bool {
        self.tx.is_some()
    }

    /// Records the log lines `sim` added since the last snapshot (the cleanup hooks'),
    /// then the `gantry_end` metadata record with `end` and the count of dropped
    /// snapshots, ends the file and waits for the writer thread.
    pub fn finish(mut self, sim: Option<&Sim>, mut end: BTreeMap<String, String>) -> RecordReport {
        // The end of the run may wait for the writer: nothing is simulated now.
        let pending = std::mem::take(&mut self.pending);
        let inputs = std::mem::take(&mut self.inputs);
        if (!pending.is_empty() || !inputs.is_empty())
            && let Some(tx) = &self.tx
            && tx.send(Item::Batch(pending, inputs)).is_err()
        {
            self.tx = None;
        }
        if let Some(sim) = sim
            && let Some(tx) = &self.tx
        {
            let logs = self.sampler.sample_logs(sim);
            if !logs.is_empty() && tx.send(Item::Logs(logs)).is_err() {
                self.tx = None;
            }
        }
        end.insert("snapshots".to_owned(), self.snapshots.to_string());
        end.insert("dropped_snapshots".to_owned(), self.dropped.to_string());
        if let Some(tx) = &self.tx
            && tx.send(Item::End(end)).is_err()
        {
            self.tx = None;
        }
        self.tx = None;
        let outcome = self.thread.take().map(|t| {
            t.join().unwrap_or_else(|_| WriterOutcome {
                messages: 0,
                error: Some("the recording thread panicked".to_owned()),
            })
        });
        let (messages, error) = outcome.map_or((0, None), |o| (o.messages, o.error));
        RecordReport {
            path: self.path.clone(),
            snapshots: self.snapshots,
            dropped: self.dropped,
            messages,
            error,
        }
    }
}

impl Drop for Recorder {
    /// A recorder dropped without [`Recorder::finish`] still ends its file.
    fn drop(&mut self) {
        let pending = std::mem::take(&mut self.pending);
        let inputs = std::mem::take(&mut self.inputs);
        if (!pending.is_empty() || !inputs.is_empty())
            && let Some(tx) = &self.tx
        {
            let _ = tx.try_send(Item::Batch(pending, inputs));
        }
        self.tx = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The writer thread: metadata and attachments, then every queued item, then the
/// summary. Stops at the first write error, after logging it and trying to end the
/// file so that what was written stays readable.
fn write_loop<W: Write + Seek>(
    mut sink: McapSink<W>,
    rx: Receiver<Item>,
    params: &RecordParams,
    path: &Path,
) -> WriterOutcome {
    let mut run = || -> Result<(), mcap::McapError> {
        sink.metadata(&params.metadata)?;
        for a in &params.attachments {
            sink.attach(a)?;
        }
        let mut last_flush = std::time::Instant::now();
        while let Ok(item) = rx.recv() {
            if last_flush.elapsed() >= FLUSH_EVERY {
                // Ends the open chunk: what was recorded so far survives a kill.
                sink.flush()?;
                last_flush = std::time::Instant::now();
            }
            match item {
                Item::Batch(batch, inputs) => {
                    // In time order: an input at a snapshot's time arrived after that
                    // snapshot (between its step and the next).
                    let mut rest = inputs.as_slice();
                    for s in &batch {
                        let n = rest.partition_point(|(t, _)| *t < s.log_time_ns);
                        sink.inputs(&rest[..n])?;
                        rest = &rest[n..];
                        sink.snapshot(s)?;
                    }
                    sink.inputs(rest)?;
                }
                Item::Logs(l) => sink.logs(&l)?,
                Item::End(end) => sink.metadata_named("gantry_end", &end)?,
            }
        }
        sink.finish()
    };
    let result = run();
    // Closing the queue tells the simulation thread to stop sampling.
    drop(rx);
    let error = match result {
        Ok(()) => None,
        Err(e) => {
            let e = with_causes(&e);
            tracing::error!(
                "recording to {} stopped: {e}; the simulation goes on, and the file keeps what was written before",
                path.display()
            );
            // Best effort: a summary makes the file indexed again; on a full disk it fails too.
            let _ = sink.finish();
            Some(e)
        }
    };
    WriterOutcome {
        messages: sink.messages(),
        error,
    }
}

/// `e` followed by its causes: the MCAP writer's errors name the operation, their
/// source the OS error ("No space left on device").
pub(crate) fn with_causes(e: &dyn std::error::Error) -> String {
    let mut out = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        let text = c.to_string();
        if !out.contains(&text) {
            out.push_str(": ");
            out.push_str(&text);
        }
        cause = c.source();
    }
    out
}
