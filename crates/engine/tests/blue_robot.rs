//! The seed paper's scene, `Blue Robot.ttt`, run unmodified with its own embedded TCP
//! server script (LuaSocket: `socket.bind("*", 6000)`, one blocking `accept` per
//! `sysCall_actuation`, `receive`, echo, `close`), driven the way the paper's C# client
//! drives it: one connection per packet, the packet written byte by byte, `\r\n` at the
//! end. Checks the echo and the joints through the API.
//!
//! The scene is read from `$GANTRY_COPPELIA_FILES` or `../shared/coppelia-files` (it is
//! not part of the repository); where that folder is absent the test prints a line and
//! passes. The script's port 6000 is mapped to a free port (`NetworkParams::port_map`,
//! `--script-port` on the command line), so the test runs beside a gantry on 6000.

use crate::util;
use util::Drive;

use std::f64::consts::{PI, TAU};
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};

use gantry_engine::Engine;
use gantry_lua::{NetworkParams, ScriptLimits, ScriptState};
use gantry_sim_core::Value;
use gantry_test_support::{assert_close, coppelia_files, floats, free_port, int, load, num};

/// One exchange as the C# client does it: connect, write the packet one byte per
/// write, read the reply until the server closes.
fn send_packet(addr: SocketAddr, packet: &'static str) -> std::thread::JoinHandle<String> {
    std::thread::spawn(move || {
        let mut s = TcpStream::connect(addr).expect("connect to the scene's server");
        // A script that fails mid-exchange never closes: fail, do not hang.
        s.set_read_timeout(Some(std::time::Duration::from_secs(10)))
            .expect("read timeout");
        for b in packet.as_bytes() {
            s.write_all(std::slice::from_ref(b)).expect("write");
        }
        let mut reply = String::new();
        s.read_to_string(&mut reply).expect("read the echo");
        reply
    })
}

/// Sends `packet`, takes the one step whose actuation serves it, returns the reply.
fn exchange(sim: &mut Engine, addr: SocketAddr, packet: &'static str) -> String {
    let client = send_packet(addr, packet);
    sim.step();
    client.join().expect("client thread")
}

fn handle(sim: &mut Engine, name: &str) -> i64 {
    let r = sim
        .call("getObjectHandle", &[Value::Str(name.to_owned())])
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    int(&r[0])
}

fn joints(sim: &mut Engine) -> Vec<f64> {
    (1..=6)
        .map(|i| {
            let h = handle(sim, &format!("RobotB_joint{i}"));
            num(&sim
                .call("getJointPosition", &[Value::Int(h)])
                .expect("getJointPosition")[0])
        })
        .collect()
}

#[test]
fn blue_robot_serves_the_papers_packets_and_moves_its_joints() {
    let path = coppelia_files().join("paper__Blue_Robot.ttt");
    if !path.is_file() {
        println!(
            "paper__Blue_Robot.ttt not found in {}; skipped (set GANTRY_COPPELIA_FILES)",
            coppelia_files().display()
        );
        return;
    }
    let port = free_port();
    let limits = ScriptLimits {
        network: NetworkParams {
            port_map: vec![(6000, port)],
            ..NetworkParams::default()
        },
        ..ScriptLimits::default()
    };
    // The script binds when it loads, as CoppeliaSim runs its top-level code.
    let mut sim = util::engine(load(&path), limits).expect("the scene's simulation");
    let addr = SocketAddr::from(([127, 0, 0, 1], port));
    assert_eq!(
        sim.script_listeners(),
        [addr],
        "the server script binds '*' = 127.0.0.1"
    );

    // §1.8 of the API reference: limits in degrees, J1, J4, J6 cyclic. J3's -90° is
    // below its -50° limit and is clamped; J4 and J6 beyond ±180° wrap.
    let deg = PI / 180.0;
    let cases: [(&str, [f64; 6]); 3] = [
        (
            "<FK#J1=0.785398163397448,J2=0,J3=-1.5707963267949,J4=0,J5=0,J6=0>\r\n",
            [PI / 4.0, 0.0, -50.0 * deg, 0.0, 0.0, 0.0],
        ),
        (
            "<FK#J1=-0.5,J2=0.3,J3=0.2,J4=3.5,J5=1,J6=-3.5>\r\n",
            [-0.5, 0.3, 0.2, 3.5 - TAU, 1.0, TAU - 3.5],
        ),
        (
            "<FK#J1=0,J2=2,J3=0,J4=0,J5=-2.5,J6=0>\r\n",
            [0.0, 90.0 * deg, 0.0, 0.0, -120.0 * deg, 0.0],
        ),
    ];
    for (packet, expected) in cases {
        let reply = exchange(&mut sim, addr, packet);
        assert_eq!(reply, format!("{}\n", packet.trim_end()), "the paper's echo");
        assert_close(&joints(&mut sim), &expected, 1e-5);
    }

    // IK: the damped group moves the tip onto (TX, TY, TZ), in metres, world frame.
    let target = [0.45, 1.05, 0.6];
    let packet = "<IK#TX=0.45,TY=1.05,TZ=0.6,RX=0,RY=0,RZ=0>\r\n";
    assert_eq!(exchange(&mut sim, addr, packet), format!("{}\n", packet.trim_end()));
    let tip = handle(&mut sim, "RobotB_tip");
    let at = floats(
        &sim.call("getObjectPosition", &[Value::Int(tip), Value::Int(-1)])
            .expect("tip")[0],
    );
    assert_close(&at, &target, 1e-3);

    for (file, _, state) in sim.scripts() {
        assert_eq!(state, ScriptState::Running, "{}", file.display());
    }

    // A stop closes the script's server and the rebuilt script binds the same port.
    sim.stop();
    assert_eq!(sim.script_listeners(), [addr], "rebound after the stop");
    let packet = "<FK#J1=0.1,J2=0,J3=0,J4=0,J5=0,J6=0>\r\n";
    assert_eq!(exchange(&mut sim, addr, packet), format!("{}\n", packet.trim_end()));
    assert_close(&joints(&mut sim), &[0.1, 0.0, 0.0, 0.0, 0.0, 0.0], 1e-5);
}
