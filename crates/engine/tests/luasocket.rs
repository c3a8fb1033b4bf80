//! LuaSocket in scene scripts: `require` hands it out, a blocking `accept` outlives the
//! time budget without the script being interrupted, and a reloaded script finds its
//! port free again. (The socket calls themselves are tested in `src/luasocket/tests.rs`.)

use crate::util;

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::Duration;

use gantry_lua::{NetworkParams, ScriptLimits, ScriptState};
use gantry_sim_core::Value;
use gantry_test_support::text;
use util::Scene;

const SCENE: &str = r#"
[[object]]
name = "server"
kind = "dummy"
script = "server.lua"
"#;

/// A server script in the paper's style: one blocking accept per actuation, echo.
const SERVER: &str = r#"
local socket = require 'socket'
local core = require('socket.core')
function same_module() return tostring(socket == core and socket == _ENV.socket) end
server = assert(socket.bind('*', 6000))

function port() return tostring(select(2, server:getsockname())) end

function sysCall_actuation()
    local c = server:accept()
    c:settimeout(10)
    local line, err = c:receive()
    -- Enough Lua after the wait for the budget hook (every 4096 instructions) to look.
    local n = 0
    for i = 1, 100000 do n = n + i end
    if not err then c:send(line .. '\n') end
    c:close()
end
"#;

fn limits() -> ScriptLimits {
    ScriptLimits {
        time_budget: Duration::from_millis(100),
        network: NetworkParams {
            port_map: vec![(6000, 0)],
            ..NetworkParams::default()
        },
        ..ScriptLimits::default()
    }
}

fn port(sc: &mut Scene) -> u16 {
    text(&sc.call("port", &[])[0]).parse().expect("a port number")
}

#[test]
fn require_socket_and_socket_core_give_the_same_module() {
    let mut sc = Scene::new("require", SCENE, &[("server.lua", SERVER)], limits());
    assert_eq!(sc.sim.scripts()[0].2, ScriptState::Running, "{:?}", sc.sim.scripts());
    assert_eq!(sc.call("same_module", &[]), [Value::Str("true".into())]);
    assert_ne!(port(&mut sc), 6000, "6000 is mapped to a free port");
}

#[test]
fn a_client_arriving_after_the_budget_does_not_interrupt_the_script() {
    let mut sc = Scene::new("late", SCENE, &[("server.lua", SERVER)], limits());
    let addr = SocketAddr::from(([127, 0, 0, 1], port(&mut sc)));
    let client = std::thread::spawn(move || {
        // Three budgets' worth of waiting in `accept` before the client comes.
        std::thread::sleep(Duration::from_millis(300));
        let mut s = TcpStream::connect(addr).expect("connect");
        // A server script interrupted mid-exchange never closes: fail, do not hang.
        s.set_read_timeout(Some(Duration::from_secs(10))).expect("read timeout");
        s.write_all(b"late\r\n").expect("write");
        let mut reply = String::new();
        s.read_to_string(&mut reply).expect("read");
        reply
    });
    sc.sim.step();
    assert_eq!(client.join().expect("client"), "late\n");
    assert_eq!(
        sc.sim.scripts()[0].2,
        ScriptState::Running,
        "the wait was not counted as running Lua"
    );
}

#[test]
fn a_reloaded_script_binds_its_port_again() {
    let port_limits = || {
        let free = std::net::TcpListener::bind("127.0.0.1:0")
            .and_then(|l| l.local_addr())
            .expect("a free port")
            .port();
        ScriptLimits {
            network: NetworkParams {
                port_map: vec![(6000, free)],
                ..NetworkParams::default()
            },
            ..ScriptLimits::default()
        }
    };
    let mut sc = Scene::new("reload", SCENE, &[("server.lua", SERVER)], port_limits());
    let before = sc.sim.script_listeners();
    assert_eq!(before.len(), 1);
    // The same text, saved again: the old version's socket must go before the new binds.
    sc.sim.reload(0);
    assert_eq!(sc.sim.scripts()[0].2, ScriptState::Running, "{:?}", sc.sim.scripts());
    assert_eq!(sc.sim.script_listeners(), before);
}
