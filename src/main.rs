//! `gantry`: a robot simulator in one binary.
//!
//! `gantry` (or `gantry run`) runs the embedded `showroom` scene in real time until
//! Ctrl-C; `gantry run SCENE` runs a `.toml` scene or a bare `.urdf`; `gantry check SCENE`
//! validates a scene without running it. On exit `run` prints one machine-readable line:
//! `steps=N sim_time=S wall_s=W steps_per_s=R rtf=X`.

mod embedded;

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};
use gantry_script::{ScriptLimits, Simulation, check_syntax};
use gantry_sim_core::scene::{
    DiskFiles, EmbeddedFiles, Files, LoadOptions, SceneModel, load_scene,
};

#[derive(Parser)]
#[command(
    name = "gantry",
    version,
    about = "A robot simulator in one binary: rapier physics, CoppeliaSim-style Lua scripts"
)]
struct Cli {
    /// More log output (-v info from scripts and loading, -vv debug).
    #[arg(short, long, action = clap::ArgAction::Count, global = true)]
    verbose: u8,
    /// Only errors.
    #[arg(short, long, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    run: RunArgs,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene (default: the embedded showroom).
    Run(RunArgs),
    /// Load and validate a scene (files, URDFs, meshes, scripts' syntax) without running it.
    Check {
        /// Scene file (.toml) or robot (.urdf).
        scene: PathBuf,
        /// Extra folder for package:// mesh references (repeatable).
        #[arg(long = "package-path")]
        package_paths: Vec<PathBuf>,
    },
}

#[derive(Args, Clone, Default)]
struct RunArgs {
    /// Scene file (.toml) or robot (.urdf); default: the embedded showroom.
    scene: Option<PathBuf>,
    /// Run this many steps, then exit 0.
    #[arg(long)]
    steps: Option<u64>,
    /// Run as fast as possible instead of pacing to wall-clock time.
    #[arg(long)]
    fast: bool,
    /// Override the scene's time step, seconds.
    #[arg(long)]
    dt: Option<f64>,
    /// Override the scene's physics substeps per step.
    #[arg(long)]
    substeps: Option<u32>,
    /// Extra folder for package:// mesh references (repeatable).
    #[arg(long = "package-path")]
    package_paths: Vec<PathBuf>,
    /// For a bare URDF: let the base move instead of fixing it (PyBullet's useFixedBase=False).
    #[arg(long)]
    free_base: bool,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let level = match (cli.quiet, cli.verbose) {
        (true, _) => "error",
        (false, 0) => "warn,gantry=info",
        (false, 1) => "info",
        (false, _) => "debug",
    };
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| level.into()),
        )
        .with_writer(std::io::stderr)
        .init();
    let result = match cli.command {
        Some(Command::Run(args)) => run(&args),
        Some(Command::Check {
            scene,
            package_paths,
        }) => check(&scene, package_paths),
        None => run(&cli.run),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn load(scene: Option<&PathBuf>, opts: &LoadOptions) -> Result<SceneModel> {
    match scene {
        Some(path) => load_scene(&DiskFiles, path, opts)
            .with_context(|| format!("cannot load {}", path.display())),
        None => {
            let files = embedded::files();
            load_scene(
                &files as &dyn Files,
                &EmbeddedFiles::path(embedded::SHOWROOM),
                opts,
            )
            .context("the embedded showroom scene does not load (a build problem)")
        }
    }
}

fn check(scene: &PathBuf, package_paths: Vec<PathBuf>) -> Result<()> {
    let model = load(
        Some(scene),
        &LoadOptions {
            package_paths,
            free_base: false,
        },
    )?;
    for w in &model.warnings {
        eprintln!("warning: {w}");
    }
    let errors = check_syntax(&model);
    for e in &errors {
        eprintln!("error: {e}");
    }
    if !errors.is_empty() {
        anyhow::bail!("{} script(s) do not compile", errors.len());
    }
    println!(
        "{}: ok ({} objects, {} scripts, {} warnings)",
        scene.display(),
        model.objects.len(),
        model.scripts.len(),
        model.warnings.len()
    );
    Ok(())
}

fn run(args: &RunArgs) -> Result<()> {
    let opts = LoadOptions {
        package_paths: args.package_paths.clone(),
        free_base: args.free_base,
    };
    let mut model = load(args.scene.as_ref(), &opts)?;
    if let Some(dt) = args.dt {
        anyhow::ensure!(
            dt.is_finite() && dt > 0.0 && dt <= 1.0,
            "--dt {dt}: the time step must be in (0, 1] s"
        );
        model.settings.dt = dt;
    }
    if let Some(n) = args.substeps {
        anyhow::ensure!((1..=1000).contains(&n), "--substeps {n}: use 1 to 1000");
        model.settings.substeps = n;
    }
    for w in &model.warnings {
        tracing::warn!("{w}");
    }
    let dt = model.settings.dt;
    tracing::info!(scene = %model.name, objects = model.objects.len(), scripts = model.scripts.len(), dt, "loaded");
    let mut sim = Simulation::new(model, ScriptLimits::default())?;

    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst))
            .context("cannot install the Ctrl-C handler")?;
    }
    sim.start();
    let start = Instant::now();
    let mut last_reload_check = start;
    let mut steps = 0u64;
    while !stop.load(Ordering::SeqCst) && args.steps.is_none_or(|n| steps < n) {
        sim.step();
        steps += 1;
        if !args.fast {
            // Pace to wall-clock time from a fixed origin so errors do not accumulate.
            let due = start + Duration::from_secs_f64(steps as f64 * dt);
            let now = Instant::now();
            if due > now {
                std::thread::sleep(due - now);
            }
        }
        if last_reload_check.elapsed() > Duration::from_millis(500) {
            last_reload_check = Instant::now();
            sim.reload_changed();
        }
    }
    sim.cleanup();
    let wall = start.elapsed().as_secs_f64();
    let sim_time = sim.world().time();
    println!(
        "steps={steps} sim_time={sim_time:.6} wall_s={wall:.6} steps_per_s={:.1} rtf={:.3}",
        steps as f64 / wall.max(1e-9),
        sim_time / wall.max(1e-9)
    );
    Ok(())
}
