//! Shared helper for the server's end-to-end tests: a real `gantry_server::run` on a
//! shipped scene, in this process, on free ports; stopped when dropped.

use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::Duration;

use gantry_lua::ScriptLimits;
use gantry_server::{BoundAddrs, RunSummary, ServeConfig, ServerError, Shutdown, SimConfig};
use gantry_sim_core::scene::SceneModel;
use gantry_test_support::{load, repo};

/// A running server; the simulation steps as fast as it can (`--fast`).
pub struct InProcess {
    /// Where the listeners bound.
    pub bound: BoundAddrs,
    shutdown: Shutdown,
    thread: Option<JoinHandle<Result<RunSummary, ServerError>>>,
}

impl InProcess {
    /// Runs `assets/scenes/<scene>.toml` with the listeners of `serve`.
    pub fn start(scene: &str, serve: ServeConfig) -> Self {
        Self::start_model(load(&repo(&format!("assets/scenes/{scene}.toml"))), serve)
    }

    /// Runs a loaded scene (e.g. one a test wrote) with the listeners of `serve`.
    pub fn start_model(model: SceneModel, serve: ServeConfig) -> Self {
        let shutdown = Shutdown::default();
        let (tx, rx) = mpsc::channel();
        let sd = shutdown.clone();
        let thread = std::thread::spawn(move || {
            let sim = SimConfig {
                fast: true,
                limits: ScriptLimits::default(),
                autostart: true,
                ..SimConfig::default()
            };
            gantry_server::run(model, sim, serve, sd, |bound| {
                let _ = tx.send(bound.clone());
            })
        });
        let bound = rx.recv_timeout(Duration::from_secs(30)).expect("server ready");
        Self {
            bound,
            shutdown,
            thread: Some(thread),
        }
    }
}

impl Drop for InProcess {
    fn drop(&mut self) {
        self.shutdown.trigger();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
