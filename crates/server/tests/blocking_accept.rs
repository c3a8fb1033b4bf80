//! A script that waits in a blocking LuaSocket `accept` inside `sysCall_actuation` (the
//! paper's server style: one blocking accept per actuation, as `Blue Robot.ttt` does)
//! holds the step, as in CoppeliaSim, and gantry keeps serving around it:
//! - a stop is served: the wait gives up, the simulation stops, and at the next start
//!   the rebuilt script binds the same port; the same for the scene loaded again
//!   (`sim.loadScene`). Without the interrupt the stop would wait for a client that
//!   never comes;
//! - what needs no step to finish is answered during the wait: the viewer's reads
//!   (scene, status, panels) and its frames. Calls that need the step wait for it, in
//!   order. Before, the viewer showed an empty grid until a client connected.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use gantry_lua::{NetworkParams, ScriptLimits};
use gantry_server::http::{FrameSender, frame_channel};
use gantry_server::runner::Running;
use gantry_server::{LoopControl, Request, ServeConfig, Shutdown, Signals, SimConfig, SimHandle, start};
use gantry_sim_core::Value;
use gantry_sim_core::api::Target;
use gantry_sim_core::sim::{Control, SimulationState};
use gantry_test_support::{TempDir, free_port, load};
use tokio::sync::oneshot;

const SERVER: &str = r#"
local socket = require('socket')
local server = assert(socket.bind('*', 6000))

function sysCall_actuation()
    local c = server:accept()
    c:settimeout(10)
    local line, err = c:receive()
    if not err then c:send(line .. '\n') end
    c:close()
end
"#;

fn exchange(port: u16, packet: &str) -> String {
    let started = Instant::now();
    let mut s = loop {
        match TcpStream::connect(("127.0.0.1", port)) {
            Ok(s) => break s,
            Err(e) => {
                assert!(
                    started.elapsed() < Duration::from_secs(30),
                    "the script never listened: {e}"
                );
                std::thread::sleep(Duration::from_millis(20));
            }
        }
    };
    s.set_read_timeout(Some(Duration::from_secs(20))).expect("timeout");
    s.write_all(packet.as_bytes()).expect("write");
    let mut reply = String::new();
    s.read_to_string(&mut reply).expect("the echo, then the server closes");
    reply
}

/// Sends a control action and waits for the resulting state, failing (not hanging)
/// when it is never served.
fn control(sim: &SimHandle, action: LoopControl) -> SimulationState {
    let (reply, rx) = oneshot::channel();
    sim.send(Request::Control { action, reply }).expect("queued");
    let (tx, done) = mpsc::channel();
    std::thread::spawn(move || tx.send(rx.blocking_recv()));
    done.recv_timeout(Duration::from_secs(30))
        .expect("the control request is served while the script waits in accept")
        .expect("a reply")
}

/// Runs `dir`'s `scene.toml`, started, with the script's port 6000 mapped to a free one
/// (returned), and the viewer's pose stream on `frames` when given.
fn serve_scene(dir: &TempDir, frames: Option<FrameSender>) -> (Running, u16) {
    let model = load(&dir.path().join("scene.toml"));
    let port = free_port();
    let config = SimConfig {
        autostart: true,
        frames,
        limits: ScriptLimits {
            network: NetworkParams {
                port_map: vec![(6000, port)],
                ..NetworkParams::default()
            },
            ..ScriptLimits::default()
        },
        ..SimConfig::default()
    };
    let running = start(
        model,
        config,
        ServeConfig::default(),
        Shutdown::default(),
        Signals::Leave,
    )
    .expect("starts");
    (running, port)
}

#[test]
fn a_stop_ends_a_blocking_accept_and_the_next_run_binds_the_port_again() {
    let dir = TempDir::new("luasocket-stop");
    dir.write(
        "scene.toml",
        "[[object]]\nname = \"server\"\nkind = \"dummy\"\nscript = \"server.lua\"\n",
    );
    dir.write("server.lua", SERVER);
    let (running, port) = serve_scene(&dir, None);
    let sim = running.handle();
    assert_eq!(exchange(port, "first\r\n"), "first\n");

    // The next step begins within one 50 ms time step and blocks in accept; the pause
    // only lets it begin (the stop must be served either way).
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(
        control(&sim, LoopControl::Control(Control::Stop)),
        SimulationState::Stopped
    );

    assert_eq!(
        control(&sim, LoopControl::Control(Control::Start)),
        SimulationState::Running
    );
    assert_eq!(exchange(port, "second\r\n"), "second\n");

    // The same scene loaded again while the script waits: the wait ends, the old
    // scene's socket closes before the new scene's script binds the same port.
    std::thread::sleep(Duration::from_millis(300));
    let (reply, rx) = oneshot::channel();
    sim.send(Request::LoadScene {
        path: Some(dir.path().join("scene.toml")),
        reply,
    })
    .expect("queued");
    let (tx, done) = mpsc::channel();
    std::thread::spawn(move || tx.send(rx.blocking_recv()));
    done.recv_timeout(Duration::from_secs(30))
        .expect("the scene load is served while the script waits in accept")
        .expect("a reply")
        .expect("the scene loads");
    assert_eq!(
        control(&sim, LoopControl::Control(Control::Start)),
        SimulationState::Running
    );
    assert_eq!(exchange(port, "third\r\n"), "third\n");

    running.stop();
    // The simulation thread notices the shutdown in its blocked accept too.
    running.wait().expect("a clean end");
}

/// The server and a marker at a known place, for the viewer to read.
const WITH_MARKER: &str = r#"
[[object]]
name = "server"
kind = "dummy"
script = "server.lua"

[[object]]
name = "marker"
kind = "dummy"
position = [1.0, 2.0, 3.0]
"#;

/// The answer of `rx` within `within`, or `None`.
fn answer_within<T: Send + 'static>(rx: oneshot::Receiver<T>, within: Duration) -> Option<T> {
    let (tx, done) = mpsc::channel();
    std::thread::spawn(move || tx.send(rx.blocking_recv()));
    done.recv_timeout(within).ok().and_then(Result::ok)
}

/// What a viewer reads of the scene: the number of objects, whether the scripts were
/// available (not while a script holds the step), and the marker's position.
fn read_scene(sim: &SimHandle) -> oneshot::Receiver<(usize, bool, [f64; 3])> {
    let (reply, rx) = oneshot::channel();
    sim.send(Request::Read(Box::new(move |v| {
        let w = &v.sim.world;
        let marker = w.find("/marker", None, 0).expect("the marker");
        let p = w.object(marker).expect("the marker").world.translation.vector;
        let _ = reply.send((w.handles().len(), v.scripts.is_some(), [p.x, p.y, p.z]));
    })))
    .expect("queued");
    rx
}

#[test]
fn the_viewer_is_served_while_a_script_waits_in_accept() {
    let dir = TempDir::new("served-while-waiting");
    dir.write("scene.toml", WITH_MARKER);
    dir.write("server.lua", SERVER);
    let frames = frame_channel();
    let mut viewer = frames.subscribe();
    let (running, port) = serve_scene(&dir, Some(frames));
    let sim = running.handle();
    // The first step begins at once and blocks in accept (no client yet).
    std::thread::sleep(Duration::from_millis(300));

    // The viewer's read is answered inside the wait: without the scripts (the Lua host
    // is running one), with the scene as loaded.
    let (objects, scripts, marker) =
        answer_within(read_scene(&sim), Duration::from_secs(10)).expect("a read is served while the script waits");
    assert!(!scripts, "served inside the step, not after it");
    assert_eq!(objects, 2);
    assert_eq!(marker, [1.0, 2.0, 3.0]);

    // Its frames go out too: a watching viewer gets the marker's pose.
    let started = Instant::now();
    loop {
        if viewer.has_changed().unwrap_or(false) {
            let f = viewer.borrow_and_update().clone();
            if f.poses.len() == 2 {
                assert!(f.poses.iter().any(|p| p[..3] == [1.0, 2.0, 3.0]), "{:?}", f.poses);
                break;
            }
        }
        assert!(
            started.elapsed() < Duration::from_secs(10),
            "no frame while the script waits"
        );
        std::thread::sleep(Duration::from_millis(20));
    }

    // A call that needs the step waits for it, and is answered once the client came.
    let target = Target::resolve("sim.getSimulationTime").expect("resolves");
    let (reply, call) = oneshot::channel();
    sim.send(Request::Call {
        target,
        args: Vec::new(),
        reply,
    })
    .expect("queued");
    let (tx, answered) = mpsc::channel();
    std::thread::spawn(move || tx.send(call.blocking_recv()));
    assert!(
        answered.recv_timeout(Duration::from_millis(300)).is_err(),
        "a call waits for the step the script holds"
    );
    assert_eq!(exchange(port, "hello\r\n"), "hello\n");
    let time = answered
        .recv_timeout(Duration::from_secs(10))
        .expect("answered after the step")
        .expect("a reply")
        .expect("the call succeeds");
    assert_eq!(time.len(), 1);
    assert!(matches!(time[0], Value::Float(_)), "{time:?}");

    // A stop ends the next wait and is served.
    std::thread::sleep(Duration::from_millis(300));
    let (reply, state) = oneshot::channel();
    sim.send(Request::Control {
        action: LoopControl::Control(Control::Stop),
        reply,
    })
    .expect("queued");
    assert_eq!(
        answer_within(state, Duration::from_secs(10)),
        Some(SimulationState::Stopped)
    );

    running.stop();
    running.wait().expect("a clean end");
}
