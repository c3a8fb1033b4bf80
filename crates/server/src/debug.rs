//! The transports' handle on the script debugger (`gantry run --debug`): what the DAP
//! listener and the viewer share to send debugger requests and to hear where a script
//! is stopped.
//!
//! Requests go through the debugger's own channel, not the simulation's request queue,
//! because a stopped script holds the simulation thread inside Lua: it reads that
//! channel itself while everything else waits in the queue. When no script is stopped,
//! a no-op request on the queue wakes the thread so the debugger's request is served
//! between steps without delay.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use gantry_lua::{DebugCommand, DebugEvent, DebugLink, DebugReply, DebugRequest, DebuggerError};
use tokio::sync::{broadcast, oneshot, watch};

use crate::sim_thread::{Request, SimHandle};

/// Events buffered for a slow client before it misses some.
const EVENT_BUFFER: usize = 1024;

/// Where a script is stopped, for the viewer's banner.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PausedAt {
    /// The script file's name.
    pub script: String,
    /// Its line.
    pub line: u32,
    /// `breakpoint`, `step`, `pause` or `exception`.
    pub reason: &'static str,
}

/// A cloneable handle on the debugger.
#[derive(Clone)]
pub struct DebugHub {
    commands: std::sync::mpsc::Sender<DebugCommand>,
    sim: SimHandle,
    paused: watch::Receiver<Option<PausedAt>>,
    events: broadcast::Sender<DebugEvent>,
    /// Whether a DAP client is attached (one at a time).
    client: Arc<AtomicBool>,
}

impl DebugHub {
    /// The hub for transports and the link for [`gantry_engine::Engine::new`].
    /// `release` is the process's shutdown flag: once set, a stopped script resumes
    /// and nothing stops again, so the simulation thread can clean up and end.
    pub fn new(sim: SimHandle, release: Arc<AtomicBool>) -> (Self, DebugLink) {
        let (commands, rx) = std::sync::mpsc::channel();
        let (paused_tx, paused) = watch::channel(None);
        let (events, _) = broadcast::channel(EVENT_BUFFER);
        let forward = events.clone();
        let link = DebugLink {
            commands: rx,
            events: Box::new(move |e: DebugEvent| {
                match &e {
                    DebugEvent::Stopped { reason, path, line, .. } => {
                        let _ = paused_tx.send(Some(PausedAt {
                            script: display_name(path),
                            line: *line,
                            reason: reason.as_str(),
                        }));
                    }
                    DebugEvent::Continued => {
                        let _ = paused_tx.send(None);
                    }
                    DebugEvent::Output { .. } => {}
                }
                let _ = forward.send(e);
            }),
            release,
        };
        let hub = Self {
            commands,
            sim,
            paused,
            events,
            client: Arc::new(AtomicBool::new(false)),
        };
        (hub, link)
    }

    /// Sends a request and awaits the answer.
    ///
    /// # Errors
    /// The debugger's refusal, or [`DebugError::Ended`].
    pub async fn request(&self, request: DebugRequest) -> Result<DebugReply, DebugError> {
        let (tx, rx) = oneshot::channel();
        self.commands
            .send(DebugCommand {
                request,
                reply: Box::new(move |r| {
                    let _ = tx.send(r);
                }),
            })
            .map_err(|_| DebugError::Ended)?;
        // Wakes the loop if no script is stopped; a full queue means it is awake anyway.
        let _ = self.sim.send(Request::With(Box::new(|sim| sim.debug_poll())));
        Ok(rx.await.map_err(|_| DebugError::Ended)??)
    }

    /// Where a script is stopped (`None`: running), updated as it changes.
    pub fn paused(&self) -> watch::Receiver<Option<PausedAt>> {
        self.paused.clone()
    }

    /// Every debugger event from now on.
    pub fn subscribe(&self) -> broadcast::Receiver<DebugEvent> {
        self.events.subscribe()
    }

    /// Claims the one DAP client slot; false if a client holds it.
    pub(crate) fn claim_client(&self) -> bool {
        !self.client.swap(true, Ordering::SeqCst)
    }

    /// Frees the DAP client slot.
    pub(crate) fn release_client(&self) {
        self.client.store(false, Ordering::SeqCst);
    }
}

/// Why a debugger request got no answer.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DebugError {
    /// The simulation thread is gone, and the debugger with it.
    #[error("the simulation has ended")]
    Ended,
    /// The debugger refused the request.
    #[error(transparent)]
    Debugger(#[from] DebuggerError),
}

/// A script's file name, as the viewer's banner and the editor's stop message show it.
pub(crate) fn display_name(path: &std::path::Path) -> String {
    path.file_name()
        .map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned())
}
