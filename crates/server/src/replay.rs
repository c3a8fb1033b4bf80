//! `gantry replay FILE`: serves the viewer over a recording, with nothing simulated.
//!
//! The scene is the one the recording carries
//! ([`RecordedScene::scene_model`](gantry_record::RecordedScene::scene_model)), built on a
//! simulation thread of its own that is never started: its scripts are removed before
//! the world is built, so none of them runs, and nothing steps. The only listener is
//! the viewer's ([`crate::http::serve_replay`]); the replay's clock and what it shows are
//! [`crate::http::replay`]'s.

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::sync::Arc;
use std::time::Duration;

use gantry_record::Recording;
use gantry_sim_core::scene::SceneModel;
use tokio::net::TcpListener;
use tokio::sync::watch;

use crate::auth::AccessToken;
use crate::http::replay::ReplayHub;
use crate::http::{Frame, FrameSender, HttpConfig};
use crate::runner::{ServerError, Shutdown};
use crate::sim_thread::{SimConfig, channel, run_sim_thread_observed};

/// Where and how the replay's viewer listens.
#[derive(Debug, Clone)]
pub struct ReplayConfig {
    /// Address the viewer binds (default 127.0.0.1).
    pub bind: IpAddr,
    /// Its port (0: any free port).
    pub http_port: u16,
    /// Access token the page must present, as for `gantry run`.
    pub token: Option<AccessToken>,
    /// The viewer's limits.
    pub http: HttpConfig,
}

impl Default for ReplayConfig {
    fn default() -> Self {
        Self {
            bind: IpAddr::V4(Ipv4Addr::LOCALHOST),
            http_port: 8080,
            token: None,
            http: HttpConfig::default(),
        }
    }
}

/// Serves `recording` (whose scene is `model`) in the viewer until `shutdown` triggers
/// (Ctrl-C and SIGTERM trigger it). `on_ready` gets the viewer's address once it
/// listens.
///
/// # Errors
/// The viewer cannot bind its port, or the runtime or the simulation cannot start.
pub fn replay(
    recording: Recording,
    mut model: SceneModel,
    cfg: ReplayConfig,
    shutdown: Shutdown,
    on_ready: impl FnOnce(SocketAddr),
) -> Result<(), ServerError> {
    // A replay shows what happened; the scripts would make something else happen.
    model.scripts.clear();
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(ServerError::Runtime)?;
    let (handle, rx) = channel();
    let sim_shutdown = shutdown.clone();
    let sim_thread = std::thread::Builder::new()
        .name("gantry-sim".into())
        .spawn(move || {
            let config = SimConfig {
                // Never started: the world stays as the replay sets it.
                autostart: false,
                fast: true,
                ..SimConfig::default()
            };
            run_sim_thread_observed(model, config, rx, || sim_shutdown.is_triggered(), Vec::new())
        })
        .map_err(ServerError::Runtime)?;
    let (stop_tx, stop_rx) = watch::channel(false);
    let frames: FrameSender = Arc::new(watch::channel(Arc::new(Frame::default())).0);
    let rec = Arc::new(recording);
    let served = rt.block_on(async {
        let addr = SocketAddr::new(cfg.bind, cfg.http_port);
        let listener = TcpListener::bind(addr)
            .await
            .map_err(|source| ServerError::Bind { addr, source })?;
        let local = listener
            .local_addr()
            .map_err(|source| ServerError::Bind { addr, source })?;
        let hub = ReplayHub::start(rec.clone(), handle.clone(), frames.clone())
            .await
            .map_err(|e| ServerError::Panic(format!("the replay's simulation thread did not start: {e}")))?;
        tokio::spawn(crate::http::serve_replay(
            listener,
            handle.clone(),
            frames,
            hub,
            cfg.http.clone(),
            cfg.token.clone(),
            stop_rx,
        ));
        tracing::info!("replaying {} at http://{local}/", rec.path().display());
        Ok::<_, ServerError>(local)
    });
    let local = match served {
        Ok(l) => l,
        Err(e) => {
            shutdown.trigger();
            let _ = sim_thread.join();
            return Err(e);
        }
    };
    if !cfg.bind.is_loopback() {
        tracing::warn!(
            "viewer listening on {} (not loopback): anyone who can reach this machine can watch the recording{}",
            cfg.bind,
            if cfg.token.is_some() {
                " with the access token"
            } else {
                " (--token TOKEN requires an access token)"
            }
        );
    }
    on_ready(local);
    rt.block_on(async {
        let stop = shutdown.clone();
        tokio::select! {
            () = signals() => stop.trigger(),
            () = async {
                while !stop.is_triggered() {
                    tokio::time::sleep(Duration::from_millis(100)).await;
                }
            } => {}
        }
    });
    shutdown.trigger();
    let _ = stop_tx.send(true);
    drop(handle);
    let result = sim_thread.join();
    rt.shutdown_timeout(Duration::from_secs(2));
    match result {
        Ok(r) => r.map(|_| ()).map_err(ServerError::from),
        Err(_) => Err(ServerError::Panic("the replay's simulation thread panicked".into())),
    }
}

/// Ctrl-C or SIGTERM.
async fn signals() {
    #[cfg(unix)]
    {
        use tokio::signal::unix::{SignalKind, signal};
        match (signal(SignalKind::interrupt()), signal(SignalKind::terminate())) {
            (Ok(mut int), Ok(mut term)) => {
                tokio::select! {
                    _ = int.recv() => {}
                    _ = term.recv() => {}
                }
            }
            _ => std::future::pending().await,
        }
    }
    #[cfg(not(unix))]
    if tokio::signal::ctrl_c().await.is_err() {
        std::future::pending::<()>().await;
    }
}
