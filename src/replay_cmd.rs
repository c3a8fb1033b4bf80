//! `gantry replay FILE`: plays a recording in the browser viewer, without simulating
//! (docs/recording.md, "Replaying in the viewer").

use std::net::{IpAddr, Ipv4Addr};
use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use gantry_record::{RecordedScene, Recording};
use gantry_server::http::HttpConfig;
use gantry_server::replay::{ReplayConfig, replay};
use gantry_server::{AccessToken, Shutdown};

/// The `replay` subcommand's arguments.
#[derive(Args, Clone)]
pub struct ReplayArgs {
    /// The recording (`gantry run --record FILE.mcap`).
    pub file: PathBuf,
    /// Browser viewer port: open http://127.0.0.1:PORT/ (default 8080; 0 = any free port).
    #[arg(long, default_value_t = 8080)]
    pub http_port: u16,
    /// Address the viewer binds (default 127.0.0.1; anything else prints a warning).
    #[arg(long)]
    pub bind: Option<String>,
    /// Require this access token on the viewer (default: $GANTRY_TOKEN), as for `gantry run`.
    #[arg(long)]
    pub token: Option<String>,
}

/// Reads the recording and its scene, then serves the viewer until Ctrl-C.
///
/// # Errors
/// The file is not a readable gantry recording, its scene does not load, or the viewer
/// cannot listen.
pub fn run(args: &ReplayArgs, token: Option<AccessToken>) -> Result<()> {
    let rec = Recording::open(&args.file)?;
    for w in rec.warnings() {
        tracing::warn!("{}: {w}", args.file.display());
    }
    let model = rec.scene_model()?;
    for w in &model.warnings {
        tracing::warn!("{w}");
    }
    let bind: IpAddr = match args.bind.as_deref() {
        Some(b) => b.parse().with_context(|| format!("--bind {b}: not an IP address"))?,
        None => IpAddr::V4(Ipv4Addr::LOCALHOST),
    };
    tracing::info!(
        file = %args.file.display(),
        scene = %model.name,
        start_s = rec.start_ns() as f64 * 1e-9,
        end_s = rec.end_ns() as f64 * 1e-9,
        snapshots = rec.snapshot_times().len(),
        "replaying"
    );
    let cfg = ReplayConfig {
        bind,
        http_port: args.http_port,
        token: token.clone(),
        http: HttpConfig::default(),
    };
    replay(rec, model, cfg, Shutdown::default(), |addr| {
        // The same machine-readable line as `gantry run`, for scripts on port 0.
        eprintln!("listening http={addr}");
        if let Some(t) = &token {
            eprintln!("viewer url=http://{addr}/?token={}", t.reveal());
        }
    })?;
    Ok(())
}
