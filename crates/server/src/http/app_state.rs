//! What every request handler and viewer session shares: the simulation's handle, the
//! frame stream, the viewer permits, the limits, the shutdown signal, the debugger and,
//! in a replay, the recording's clock.

use std::sync::Arc;

use tokio::sync::{Semaphore, watch};

use super::config::HttpConfig;
use super::frame::FrameSender;
use super::replay::ReplayHub;
use crate::debug::DebugHub;
use crate::sim_thread::SimHandle;

/// What every request handler shares.
#[derive(Clone)]
pub(super) struct AppState {
    pub(super) sim: SimHandle,
    pub(super) frames: FrameSender,
    /// One permit per connected viewer page.
    pub(super) viewers: Arc<Semaphore>,
    pub(super) cfg: HttpConfig,
    /// Turns true when gantry shuts down; sessions close their sockets then.
    pub(super) shutdown: watch::Receiver<bool>,
    /// With `--debug`: the script debugger, for the "paused in SCRIPT:LINE" banner.
    pub(super) debug: Option<DebugHub>,
    /// With `gantry replay`: the recording and its clock; the page is in replay mode.
    pub(super) replay: Option<ReplayHub>,
    /// The ROS 2 network, for the page's list of topics.
    pub(super) ros2: Option<Arc<gantry_ros2::DdsNetwork>>,
}
