//! `gantry run --record`: the recorder as an [`Observer`] of the simulation thread.
//!
//! After each step the recorder takes a snapshot of the world and hands it to its own
//! writer thread (see `gantry_record`); at the end of the run it takes the cleanup
//! hooks' log lines, ends the file and says how it went: a warning with the count when
//! snapshots had to be dropped, an error when a write failed.

use gantry_record::{RecordReport, Recorder};
use gantry_script::Simulation;

use crate::sim_thread::Observer;

/// Records the run (see the module docs).
pub struct RecordObserver {
    /// `None` once finished.
    recorder: Option<Recorder>,
}

impl RecordObserver {
    /// Observes with `recorder`.
    pub fn new(recorder: Recorder) -> Self {
        Self {
            recorder: Some(recorder),
        }
    }
}

impl Observer for RecordObserver {
    fn observe(&mut self, sim: &Simulation, _run_steps: u64) {
        if let Some(r) = &mut self.recorder
            && r.is_writing()
        {
            r.record(&sim.core());
        }
    }

    fn finish(&mut self, sim: &Simulation) {
        if let Some(r) = self.recorder.take() {
            report(&r.finish(Some(&sim.core())));
        }
    }
}

/// Logs how a recording went.
fn report(r: &RecordReport) {
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
