//! `gantry`: a robot simulator in one binary.
//!
//! `gantry` (or `gantry run`) runs the embedded `showroom` scene in real time until
//! Ctrl-C; `gantry run SCENE` runs a `.toml` scene or a bare `.urdf`; `gantry check SCENE`
//! validates a scene without running it; `gantry convert SCENE DIR` writes any scene it
//! loads (a CoppeliaSim `.ttt`/`.ttm`, a URDF) as a TOML scene with its meshes and
//! scripts as files. `gantry run --record run.mcap` records the run and `gantry replay
//! run.mcap` plays it back in the viewer (docs/recording.md).
//! On exit `run` prints one machine-readable line:
//! `steps=N sim_time=S wall_s=W steps_per_s=R rtf=X`.

mod replay_cmd;

use std::net::{IpAddr, Ipv4Addr};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};
use gantry_lua::{NetworkParams, ScriptLimits, check_syntax, uses_luasocket};
use gantry_record::{ImageStream, RecordParams, RecordedRun, RunDescription, RunRecorder, Verdict};
use gantry_server::http::HttpConfig;
use gantry_server::{AccessToken, ServeConfig, Shutdown, SimConfig, TextConfig};
use gantry_sim_core::scene::{
    DiskFiles, EmbeddedFiles, Files, LoadOptions, LoggedFiles, SceneModel, bundled_files, load_bundled, load_scene,
    normalize_path, write_scene,
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
    Run(Box<RunArgs>),
    /// Load and validate a scene (files, URDFs, meshes, scripts' syntax) without running it.
    Check {
        /// Scene file (.toml) or robot (.urdf).
        scene: PathBuf,
        /// Extra folder for package:// mesh references (repeatable).
        #[arg(long = "package-path")]
        package_paths: Vec<PathBuf>,
    },
    /// Write a scene (.ttt, .ttm, .urdf, .toml) as a TOML scene in DIR: DIR/NAME.toml (NAME: the file name without its extension),
    /// its meshes as OBJ files in DIR/meshes and its scripts as Lua files in DIR/scripts.
    Convert {
        /// The scene to convert.
        scene: PathBuf,
        /// Output folder (created if missing).
        dir: PathBuf,
        /// Overwrite files that already exist.
        #[arg(long)]
        force: bool,
        /// Extra folder for package:// mesh references (repeatable).
        #[arg(long = "package-path")]
        package_paths: Vec<PathBuf>,
    },
    /// Play a recording (`gantry run --record FILE`) in the browser viewer, without
    /// simulating: a timeline to play, pause, scrub and step, the recorded graphs, log and
    /// images.
    Replay(replay_cmd::ReplayArgs),
    /// Simulate a recorded run (`run --record`) again, with its recorded inputs, and
    /// say whether every pose, joint state and sensor reading comes out identical:
    /// exit 0 when identical, 2 when the runs part (the step is printed), 1 when the
    /// file cannot be re-run.
    Verify {
        /// The recording (.mcap).
        recording: PathBuf,
    },
    /// Send text packets to a running gantry and print the replies; exits non-zero on
    /// an <ERR#...> reply or a failed connection.
    Send {
        /// Address of the text channel.
        #[arg(long, default_value = "127.0.0.1:6000")]
        addr: String,
        /// Seconds to wait for each reply.
        #[arg(long, default_value_t = 5.0)]
        timeout: f64,
        /// Access token of a gantry started with --token (default: $GANTRY_TOKEN); sent
        /// as <AUTH#TOKEN> before the packets.
        #[arg(long)]
        token: Option<String>,
        /// Packets, e.g. '<FK#J1=0.5,J2=0,J3=0,J4=0,J5=-1.57,J6=0>'.
        #[arg(required = true)]
        packets: Vec<String>,
    },
}

#[derive(Args, Clone)]
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
    /// Override the scene's random seed (scripts' math.random, sim.floatparam_rand;
    /// default the scene's `[simulation] seed`, else 0): runs with one seed repeat.
    #[arg(long)]
    seed: Option<i64>,
    /// Extra folder for package:// mesh references (repeatable).
    #[arg(long = "package-path")]
    package_paths: Vec<PathBuf>,
    /// For a bare URDF: let the base move instead of fixing it (PyBullet's useFixedBase=False).
    #[arg(long)]
    free_base: bool,
    /// Address the listeners bind (default 127.0.0.1; anything else prints a warning).
    #[arg(long)]
    bind: Option<String>,
    /// Require this access token on the text channel and the viewer (default:
    /// $GANTRY_TOKEN, which other users cannot read in the process list). 8 to 256
    /// letters, digits, '-', '_', '.', '~'; e.g. `openssl rand -hex 16`.
    #[arg(long)]
    token: Option<String>,
    /// With --token and a non-loopback --bind, expose the ZMQ remote API on --bind too,
    /// although it has no authentication (by default it then stays on loopback).
    #[arg(long)]
    expose_zmq: bool,
    /// Text command channel port (default 6000; 0 = any free port).
    #[arg(long)]
    text_port: Option<u16>,
    /// ZMQ remote API port (default 23000; 0 = any free port).
    #[arg(long)]
    zmq_port: Option<u16>,
    /// Browser viewer port: open http://127.0.0.1:PORT/ (default 8080; 0 = any free port).
    #[arg(long)]
    http_port: Option<u16>,
    /// Also serve CoppeliaSim's legacy remote API (`simx*` clients: remoteApi.so with
    /// sim.py or vrep.py) on PORT, as CoppeliaSim's server on 19997 (0 = any free port).
    /// Scripts can start more with simRemoteApi.start. See docs/legacy-remote-api.md.
    #[arg(long, value_name = "PORT")]
    legacy_port: Option<u16>,
    /// Open no network listener at all (headless batch runs); scripts may not listen
    /// either. The run ends when a script stops the simulation, since nothing could
    /// start it again.
    #[arg(long)]
    no_listen: bool,
    /// Let scripts open outgoing TCP connections (LuaSocket's `socket.connect`); by
    /// default they may only listen, on --bind's address or loopback.
    #[arg(long)]
    allow_script_connect: bool,
    /// Let scripts start PROGRAM with `sim.launchExecutable` (repeatable; a name looked
    /// up on PATH, or a path). Started directly, never through a shell, and ended when the
    /// simulation stops. By default scripts start nothing.
    #[arg(long = "allow-launch", value_name = "PROGRAM")]
    allow_launch: Vec<std::path::PathBuf>,
    /// Let scripts `require` their own Lua modules from DIR too (repeatable), after the
    /// scene's folder: `require 'utils'` loads DIR/utils.lua or DIR/utils/init.lua, as
    /// Lua source in the requiring script's sandbox.
    #[arg(long = "lua-path", value_name = "DIR")]
    lua_path: Vec<std::path::PathBuf>,
    /// Let scripts read and write files in DIR with `io.open` (repeatable). Without it
    /// scripts may only read files in the scene's folder.
    #[arg(long = "allow-files", value_name = "DIR")]
    allow_files: Vec<std::path::PathBuf>,
    /// A script that binds or connects to port ASKED gets port USED instead, e.g.
    /// `--script-port 6000=6001` to run two scenes that both hard-code 6000 (USED 0 = any
    /// free port; repeatable).
    #[arg(long = "script-port", value_name = "ASKED=USED", value_parser = parse_port_pair)]
    script_ports: Vec<(u16, u16)>,
    /// Debug the scene's scripts from an editor: serve the Debug Adapter Protocol on
    /// 127.0.0.1:PORT (default 4711; 0 = any free port). See docs/debugging.md.
    #[arg(long, value_name = "PORT", num_args = 0..=1, default_missing_value = "4711", require_equals = true)]
    debug: Option<u16>,
    /// Most simultaneous text-channel connections.
    #[arg(long, default_value_t = 256)]
    max_connections: usize,
    /// When the run ends, write every graph stream as CSV into DIR (one file per graph).
    #[arg(long, value_name = "DIR")]
    export_graphs: Option<PathBuf>,
    /// Record the run into an MCAP file (ROS 2 messages: /tf, /tf_static,
    /// /joint_states, /rosout, graph streams, proximity sensors, signals; the inputs
    /// `gantry verify` needs; the scene's files attached). See docs/recording.md.
    #[arg(long, value_name = "FILE.mcap")]
    record: Option<PathBuf>,
    /// With --record: snapshots per simulated second (default: every step).
    #[arg(long, value_name = "HZ", requires = "record")]
    record_rate: Option<f64>,
    /// With --record: also record this vision sensor's RGB images (its path, e.g.
    /// /showroom/camera, or alias), at most HZ per simulated second (default 10).
    /// Repeatable.
    #[arg(long = "record-image", value_name = "SENSOR[=HZ]", requires = "record", value_parser = parse_image_stream)]
    record_images: Vec<ImageStream>,
    /// Join the ROS 2 graph (no ROS install needed): /clock, /tf, /tf_static,
    /// /joint_states and each vision sensor's image, depth and camera info. Domain and
    /// range from ROS_DOMAIN_ID and ROS_AUTOMATIC_DISCOVERY_RANGE (or
    /// ROS_LOCALHOST_ONLY); this host only unless they say SUBNET. Scripts' simROS2
    /// works without it. See docs/ros2.md.
    #[arg(long)]
    ros2: bool,
    /// With --ros2: images per simulated second of each vision sensor, at most (0: no
    /// camera topics).
    #[arg(long, value_name = "HZ", requires = "ros2", default_value_t = 30.0)]
    ros2_camera_rate: f64,
}

/// The ROS 2 network scripts' `simROS2` uses, started on first use; with `--ros2`,
/// started now (a domain that cannot be joined fails the run) and with the graph's
/// topics.
fn ros2_setup(args: &RunArgs) -> anyhow::Result<gantry_ros2::RosSetup> {
    let rate = args.ros2_camera_rate;
    if !(rate.is_finite() && rate >= 0.0) {
        anyhow::bail!("--ros2-camera-rate {rate}: images per simulated second must be 0 or more");
    }
    let graph = args.ros2.then_some(gantry_ros2::GraphOptions { camera_rate_hz: rate });
    gantry_ros2::RosSetup::from_env(graph).map_err(|e| anyhow::anyhow!("--ros2: {e}"))
}

/// `SENSOR[=HZ]` of `--record-image`.
fn parse_image_stream(s: &str) -> Result<ImageStream, String> {
    let (sensor, rate_hz) = match s.rsplit_once('=') {
        Some((sensor, hz)) => {
            let hz: f64 = hz.parse().map_err(|_| format!("{hz:?} is not a rate in Hz"))?;
            (sensor, hz)
        }
        None => (s, 10.0),
    };
    if sensor.is_empty() {
        return Err("name the vision sensor: --record-image /path/to/sensor[=HZ]".to_owned());
    }
    if !(rate_hz.is_finite() && rate_hz > 0.0) {
        return Err(format!(
            "{rate_hz}: images per simulated second must be a positive number"
        ));
    }
    Ok(ImageStream {
        sensor: sensor.to_owned(),
        rate_hz,
    })
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let level = match (cli.quiet, cli.verbose) {
        (true, _) => "error",
        // RustDDS reports routine network conditions (a multicast group it cannot
        // leave at exit, peers without locators) as warnings and errors: noise for a
        // simulator user. RUST_LOG=rustdds=debug shows them.
        (false, 0) => "warn,gantry=info,rustdds=off",
        (false, 1) => "info",
        (false, _) => "debug",
    };
    tracing_subscriber::fmt()
        .with_env_filter(tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| level.into()))
        .with_writer(std::io::stderr)
        .init();
    let result = match cli.command {
        Some(Command::Run(args)) => run(&args),
        Some(Command::Check { scene, package_paths }) => check(&scene, package_paths),
        Some(Command::Convert {
            scene,
            dir,
            force,
            package_paths,
        }) => convert(&scene, &dir, force, package_paths),
        Some(Command::Send {
            addr,
            timeout,
            token,
            packets,
        }) => access_token(token.as_deref()).and_then(|t| send(&addr, timeout, t.as_ref(), &packets)),
        Some(Command::Replay(args)) => access_token(args.token.as_deref()).and_then(|t| replay_cmd::run(&args, t)),
        Some(Command::Verify { recording }) => match verify(&recording) {
            Ok(true) => Ok(()),
            Ok(false) => return ExitCode::from(2),
            Err(e) => Err(e),
        },
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
        Some(path) => load_scene(&DiskFiles, path, opts).with_context(|| format!("cannot load {}", path.display())),
        None => load_bundled("showroom", opts)
            .context("the showroom is bundled")?
            .context("the embedded showroom scene does not load (a build problem)"),
    }
}

/// The path a scene was read at, and every file read for it (path, bytes).
type LoadedFiles = (PathBuf, Vec<(PathBuf, Vec<u8>)>);

/// [`load`], keeping a copy of every file read: the scene's path as read and the
/// files, for a recording's attachments.
fn load_logged(scene: Option<&PathBuf>, opts: &LoadOptions) -> Result<(SceneModel, LoadedFiles)> {
    let bundled = bundled_files();
    let (source, path): (&dyn Files, PathBuf) = match scene {
        Some(p) => (&DiskFiles, p.clone()),
        None => (&bundled, EmbeddedFiles::path("assets/scenes/showroom.toml")),
    };
    let logged = LoggedFiles::new(source);
    let model = load_scene(&logged, &path, opts).with_context(|| format!("cannot load {}", path.display()))?;
    Ok((model, (normalize_path(&path), logged.into_read())))
}

/// `gantry verify`: prints the verdict; true when identical.
fn verify(recording: &std::path::Path) -> Result<bool> {
    let run = RecordedRun::open(recording)?;
    let verdict = run
        .verify()
        .with_context(|| format!("cannot re-run {}", recording.display()))?;
    println!("{}: {verdict}", recording.display());
    Ok(matches!(verdict, Verdict::Identical { .. }))
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

fn convert(scene: &PathBuf, dir: &std::path::Path, force: bool, package_paths: Vec<PathBuf>) -> Result<()> {
    let model = load(
        Some(scene),
        &LoadOptions {
            package_paths,
            free_base: false,
        },
    )?;
    let stem = scene.file_stem().and_then(|s| s.to_str()).unwrap_or("scene");
    let source = scene.file_name().and_then(|s| s.to_str()).unwrap_or(stem);
    let written = write_scene(&model, stem, source).with_context(|| format!("cannot convert {}", scene.display()))?;
    // Check every file before writing any, so that a refusal leaves DIR as it was.
    if !force {
        let existing: Vec<String> = written
            .files
            .iter()
            .map(|(rel, _)| dir.join(rel))
            .filter(|p| p.exists())
            .map(|p| p.display().to_string())
            .collect();
        anyhow::ensure!(
            existing.is_empty(),
            "{} already exist(s); pass --force to overwrite",
            existing.join(", ")
        );
    }
    for (rel, bytes) in &written.files {
        let path = dir.join(rel);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).with_context(|| format!("cannot create {}", parent.display()))?;
        }
        std::fs::write(&path, bytes).with_context(|| format!("cannot write {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    for w in &model.warnings {
        eprintln!("warning: {w}");
    }
    for n in &written.notes {
        eprintln!("warning: not converted: {n}");
    }
    println!(
        "{}: converted to {} ({} objects, {} files)",
        scene.display(),
        dir.join(&written.files[0].0).display(),
        model.objects.len(),
        written.files.len()
    );
    Ok(())
}

fn run(args: &RunArgs) -> Result<()> {
    let opts = LoadOptions {
        package_paths: args.package_paths.clone(),
        free_base: args.free_base,
    };
    // A recording (--record, or a script's sim.startRecording) attaches every file
    // the scene was read from, so it is read through a log of those files.
    let (mut model, (scene_path, files)) = load_logged(args.scene.as_ref(), &opts)?;
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
    if let Some(seed) = args.seed {
        model.settings.seed = seed;
    }
    for w in &model.warnings {
        tracing::warn!("{w}");
    }
    tracing::info!(
        scene = %model.name,
        objects = model.objects.len(),
        scripts = model.scripts.len(),
        dt = model.settings.dt,
        substeps = model.settings.substeps,
        "loaded"
    );
    // Precedence: command line, then the scene's [server] section, then the defaults.
    let scene_server = model.server.clone();
    let bind: IpAddr = match args.bind.as_deref().or(scene_server.bind.as_deref()) {
        Some(b) => b.parse().with_context(|| format!("--bind {b}: not an IP address"))?,
        None => IpAddr::V4(Ipv4Addr::LOCALHOST),
    };
    let port = |flag: Option<u16>, scene: Option<u16>, default: u16| {
        if args.no_listen {
            None
        } else {
            Some(flag.or(scene).unwrap_or(default))
        }
    };
    let token = access_token(args.token.as_deref())?;
    let text_port = text_port(args, &model, port(args.text_port, scene_server.text_port, 6000));
    let serve = ServeConfig {
        bind,
        token: token.clone(),
        expose_zmq: args.expose_zmq,
        text_port,
        zmq_port: port(args.zmq_port, scene_server.zmq_port, 23000),
        legacy_port: args.legacy_port.filter(|_| !args.no_listen),
        http_port: port(args.http_port, scene_server.http_port, 8080),
        dap_port: args.debug,
        text: TextConfig {
            max_connections: args.max_connections,
            ..TextConfig::default()
        },
        http: HttpConfig {
            // Only the default port may be busy without failing the run (see HttpConfig).
            optional: args.http_port.is_none() && scene_server.http_port.is_none(),
            ..HttpConfig::default()
        },
    };
    let run = RunDescription {
        scene_name: model.name.clone(),
        scene_path,
        files,
        package_paths: opts.package_paths.clone(),
        free_base: opts.free_base,
        scripts: true,
        dt: model.settings.dt,
        substeps: model.settings.substeps,
        seed: model.settings.seed,
        command_line: std::env::args().collect::<Vec<_>>().join(" "),
    };
    let sim = SimConfig {
        steps: args.steps,
        fast: args.fast,
        limits: ScriptLimits {
            network: NetworkParams {
                listen: (!args.no_listen).then_some(bind),
                allow_connect: args.allow_script_connect,
                port_map: args.script_ports.clone(),
                ..NetworkParams::default()
            },
            allow_launch: args.allow_launch.clone(),
            lua_path: args.lua_path.clone(),
            allow_files: args.allow_files.clone(),
            ..ScriptLimits::default()
        },
        autostart: true,
        quit_when_stopped: args.no_listen,
        export_graphs: args.export_graphs.clone(),
        load_options: opts.clone(),
        listeners: None,
        // The viewer's pose stream: the server sets it when the viewer listens.
        frames: None,
        record: args
            .record
            .as_ref()
            .map(|path| record_params(path, args, run.clone()))
            .transpose()?,
        recorder_factory: Some(Arc::new(RunRecorder::new(run))),
        ros2: Some(ros2_setup(args)?),
    };
    let summary = gantry_server::run(model, sim, serve, Shutdown::default(), |bound| {
        // One machine-readable line per listener on stderr, for scripts that start
        // gantry with port 0 and need the chosen port.
        if let Some(a) = bound.text {
            eprintln!("listening text={a}");
        }
        if let Some(a) = bound.zmq {
            eprintln!("listening zmq={a}");
        }
        if let Some(a) = bound.dap {
            eprintln!("listening dap={a}");
        }
        if let Some(a) = bound.legacy {
            eprintln!("listening legacy={a}");
        }
        if let Some(a) = bound.http {
            eprintln!("listening http={a}");
            // The one place the token is shown: the address for the user to open.
            if let Some(t) = &token {
                eprintln!("viewer url=http://{a}/?token={}", t.reveal());
            }
        }
    })?;
    println!("{}", summary.line());
    Ok(())
}

/// The text channel's port, `default` unless the scene's scripts serve TCP themselves:
/// the paper's `Blue Robot.ttt` binds port 6000 with LuaSocket, the text channel's
/// default. Then the text channel stays off unless its port was asked for (`--text-port`
/// or the scene's `[server]`; `--text-port 6000` after `--script-port 6000=P` gets it
/// back on 6000). LuaSocket use is read from the scripts' text (see
/// [`uses_luasocket`]), not from the ports they bind, which only running them tells.
fn text_port(args: &RunArgs, model: &SceneModel, default: Option<u16>) -> Option<u16> {
    let asked = args.text_port.is_some() || model.server.text_port.is_some();
    if default != Some(6000) || asked || !model.scripts.iter().any(|s| uses_luasocket(&s.source)) {
        return default;
    }
    tracing::info!(
        "text channel not started: this scene's scripts run their own TCP server (LuaSocket), \
         like the paper's on port 6000, the text channel's default; pass --text-port P to have it on port P"
    );
    None
}

/// What `--record` writes: the metadata record and, as attachments, every file the
/// scene was read from (see [`load_logged`]).
fn record_params(path: &std::path::Path, args: &RunArgs, run: RunDescription) -> Result<RecordParams> {
    if let Some(r) = args.record_rate {
        anyhow::ensure!(
            r.is_finite() && r > 0.0,
            "--record-rate {r}: snapshots per simulated second must be a positive number"
        );
    }
    Ok(RecordParams::for_run(path.to_path_buf(), args.record_rate, run).with_images(args.record_images.clone()))
}

/// `ASKED=USED` of `--script-port`.
fn parse_port_pair(s: &str) -> Result<(u16, u16), String> {
    let (a, u) = s
        .split_once('=')
        .ok_or_else(|| format!("'{s}': expected ASKED=USED, e.g. 6000=6001"))?;
    let port = |p: &str| p.trim().parse::<u16>().map_err(|e| format!("'{p}' in '{s}': {e}"));
    Ok((port(a)?, port(u)?))
}

/// The access token from `--token` or, without it, a non-empty `GANTRY_TOKEN`.
fn access_token(flag: Option<&str>) -> Result<Option<AccessToken>> {
    let value = match flag {
        Some(t) => Some(t.to_owned()),
        None => std::env::var("GANTRY_TOKEN").ok().filter(|t| !t.is_empty()),
    };
    // The error names the rule and at most one offending character, never the token.
    value
        .map(|t| AccessToken::new(&t).context("--token (or GANTRY_TOKEN)"))
        .transpose()
}

/// The smallest text-channel client: one persistent connection, one line per packet,
/// after `<AUTH#TOKEN>` when a token is given.
fn send(addr: &str, timeout: f64, token: Option<&AccessToken>, packets: &[String]) -> Result<()> {
    use std::io::{BufRead, BufReader, Write};
    anyhow::ensure!(
        timeout.is_finite() && timeout > 0.0,
        "--timeout must be a positive number of seconds"
    );
    let stream = std::net::TcpStream::connect(addr)
        .with_context(|| format!("cannot connect to {addr} (is gantry running with its text channel?)"))?;
    stream.set_read_timeout(Some(std::time::Duration::from_secs_f64(timeout)))?;
    stream.set_nodelay(true)?;
    let mut writer = stream.try_clone()?;
    let mut reader = BufReader::new(stream);
    if let Some(t) = token {
        writer.write_all(format!("<AUTH#{}>\n", t.reveal()).as_bytes())?;
        let mut line = String::new();
        reader
            .read_line(&mut line)
            .with_context(|| format!("no reply to the access token within {timeout} s"))?;
        let line = line.trim_end_matches(['\r', '\n']);
        anyhow::ensure!(
            line == gantry_server::text::AUTH_OK,
            "the access token was not accepted: {}",
            if line.is_empty() {
                "the server closed the connection"
            } else {
                line
            }
        );
    }
    let mut failed = 0;
    for p in packets {
        writer.write_all(p.trim_end().as_bytes())?;
        writer.write_all(b"\n")?;
        let mut line = String::new();
        let n = reader
            .read_line(&mut line)
            .with_context(|| format!("no reply to {p} within {timeout} s"))?;
        anyhow::ensure!(n > 0, "the server closed the connection after {p}");
        let line = line.trim_end_matches(['\r', '\n']);
        println!("{line}");
        if line.starts_with("<ERR#") {
            failed += 1;
        }
    }
    anyhow::ensure!(failed == 0, "{failed} packet(s) got an error reply");
    Ok(())
}
