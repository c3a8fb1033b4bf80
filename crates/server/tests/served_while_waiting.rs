//! While a script holds the step in a blocking LuaSocket `accept` (the paper's
//! `Blue Robot.ttt` waits for its GUI inside `sysCall_actuation`), the simulation
//! thread still answers what needs no step to finish: the viewer's reads (scene,
//! status, panels) and its frames. Calls that need the step wait for it, in order, and
//! a stop ends the wait. Before this, the viewer showed an empty grid until a client
//! connected.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use gantry_lua::{NetworkParams, ScriptLimits};
use gantry_server::http::frame_channel;
use gantry_server::{LoopControl, Request, ServeConfig, Shutdown, Signals, SimConfig, SimHandle, start};
use gantry_sim_core::Value;
use gantry_sim_core::api::Target;
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene};
use gantry_sim_core::sim::{Control, SimulationState};
use gantry_test_support::{TempDir, free_port};
use tokio::sync::oneshot;

/// Counts its steps in a signal, then waits in `accept` in every actuation.
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

const SCENE: &str = r#"
[[object]]
name = "server"
kind = "dummy"
script = "server.lua"

[[object]]
name = "marker"
kind = "dummy"
position = [1.0, 2.0, 3.0]
"#;

/// One line to the script's server and its echo.
fn exchange(port: u16, packet: &str) -> String {
    let mut s = TcpStream::connect(("127.0.0.1", port)).expect("the script listens");
    s.set_read_timeout(Some(Duration::from_secs(20))).expect("timeout");
    s.write_all(packet.as_bytes()).expect("write");
    let mut reply = String::new();
    s.read_to_string(&mut reply).expect("the echo, then the server closes");
    reply
}

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
    let scene = dir.write("scene.toml", SCENE);
    dir.write("server.lua", SERVER);
    let model = load_scene(&DiskFiles, &scene, &LoadOptions::default()).expect("scene loads");

    let port = free_port();
    let frames = frame_channel();
    let mut viewer = frames.subscribe();
    let config = SimConfig {
        autostart: true,
        frames: Some(frames),
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
