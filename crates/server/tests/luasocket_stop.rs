//! A stop asked for while a script waits in a blocking LuaSocket `accept` (the paper's
//! server style: one blocking accept per actuation) is served: the wait gives up, the
//! simulation stops, and at the next start the rebuilt script binds the same port; the
//! same for the scene loaded again (`sim.loadScene`).
//! Without the interrupt the stop request would wait for a client that never comes.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use gantry_lua::{NetworkParams, ScriptLimits};
use gantry_server::{LoopControl, Request, ServeConfig, Shutdown, Signals, SimConfig, SimHandle, start};
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

#[test]
fn a_stop_ends_a_blocking_accept_and_the_next_run_binds_the_port_again() {
    let dir = TempDir::new("luasocket-stop");
    dir.write(
        "scene.toml",
        "[[object]]\nname = \"server\"\nkind = \"dummy\"\nscript = \"server.lua\"\n",
    );
    dir.write("server.lua", SERVER);
    let model = load(&dir.path().join("scene.toml"));

    let port = free_port();
    let config = SimConfig {
        autostart: true,
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
