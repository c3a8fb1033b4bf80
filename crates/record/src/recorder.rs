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

use gantry_sim_core::Sim;

use crate::snapshot::{LogSample, Sampler, Snapshot};
use crate::writer::{AttachedFile, McapSink};

/// Batches waiting for the writer by default: a few seconds of a busy scene.
pub const DEFAULT_QUEUE: usize = 64;

/// Snapshots sent to the writer together. Waking the writer thread costs more than
/// encoding a snapshot (tens of microseconds on a loaded virtual machine), so it is
/// woken once per batch; a batch is at most a second of a 16 Hz recording.
pub const BATCH: usize = 16;

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
    /// Snapshots of consecutive steps.
    Snapshots(Vec<Snapshot>),
    /// Log lines after the last step (cleanup hooks).
    Logs(Vec<LogSample>),
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
        let thread = std::thread::Builder::new()
            .name("gantry-record".into())
            .spawn(move || write_loop(sink, rx, &params, &thread_path))
            .map_err(RecordError::Thread)?;
        Ok(Self {
            path,
            sampler: Sampler::new(rate_hz),
            tx: Some(tx),
            thread: Some(thread),
            pending: Vec::with_capacity(BATCH),
            snapshots: 0,
            dropped: 0,
        })
    }

    /// Records `sim` as it is now, if a snapshot is due (after a step; see
    /// [`Sampler::sample`]). Never blocks.
    pub fn record(&mut self, sim: &Sim) {
        if self.tx.is_none() {
            return;
        }
        if let Some(s) = self.sampler.sample(sim) {
            self.snapshots += 1;
            self.pending.push(s);
            if self.pending.len() >= BATCH {
                let batch = std::mem::replace(&mut self.pending, Vec::with_capacity(BATCH));
                self.offer(batch);
            }
        }
    }

    /// Queues a batch, or counts its snapshots dropped.
    fn offer(&mut self, batch: Vec<Snapshot>) {
        let Some(tx) = &self.tx else { return };
        match tx.try_send(Item::Snapshots(batch)) {
            Ok(()) => {}
            Err(TrySendError::Full(Item::Snapshots(b))) => self.dropped += b.len() as u64,
            Err(TrySendError::Full(Item::Logs(_))) => {}
            // The writer stopped on an error (it said so): stop sampling.
            Err(TrySendError::Disconnected(_)) => self.tx = None,
        }
    }

    /// Whether the recording still writes (no write error so far).
    pub fn is_writing(&self) -> bool {
        self.tx.is_some()
    }

    /// Records the log lines `sim` added since the last snapshot (the cleanup hooks'),
    /// ends the file and waits for the writer thread.
    pub fn finish(mut self, sim: Option<&Sim>) -> RecordReport {
        // The end of the run may wait for the writer: nothing is simulated now.
        let pending = std::mem::take(&mut self.pending);
        if !pending.is_empty()
            && let Some(tx) = &self.tx
            && tx.send(Item::Snapshots(pending)).is_err()
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
        if !pending.is_empty()
            && let Some(tx) = &self.tx
        {
            let _ = tx.try_send(Item::Snapshots(pending));
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
        while let Ok(item) = rx.recv() {
            match item {
                Item::Snapshots(batch) => {
                    for s in &batch {
                        sink.snapshot(s)?;
                    }
                }
                Item::Logs(l) => sink.logs(&l)?,
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
fn with_causes(e: &dyn std::error::Error) -> String {
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
