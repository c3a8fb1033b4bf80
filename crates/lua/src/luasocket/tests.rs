//! The LuaSocket subset against real loopback sockets: peers are plain std sockets on
//! threads, ports are the OS's free ones.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use mlua::{Lua, MultiValue, Value as LuaValue};

use super::{Sockets, install, uses_luasocket};
use crate::app_state::{self, state};
use crate::limits::NetworkParams;
use crate::running::Running;

fn lua_with(params: NetworkParams) -> Lua {
    let lua = Lua::new();
    app_state::install(&lua, Running::new(Duration::from_secs(1)));
    app_state::install(&lua, Sockets::new(params));
    app_state::install(&lua, crate::waiting::Waiting::default());
    install(&lua).expect("install the socket table");
    lua
}

fn lua() -> Lua {
    lua_with(NetworkParams::default())
}

/// Runs `chunk` with `args` as `...` and returns its results as strings (`nil` for nil).
fn run(lua: &Lua, chunk: &str, args: impl mlua::IntoLuaMulti) -> Vec<String> {
    let out: MultiValue = lua.load(chunk).call(args).unwrap_or_else(|e| panic!("{chunk}: {e}"));
    out.iter()
        .map(|v| match v {
            LuaValue::Nil => "nil".to_owned(),
            LuaValue::String(s) => s.to_string_lossy(),
            LuaValue::Integer(i) => i.to_string(),
            LuaValue::Number(n) => n.to_string(),
            LuaValue::Boolean(b) => b.to_string(),
            other => other.type_name().to_owned(),
        })
        .collect()
}

/// Binds a server with the subset, stores it as global `server`, returns its address.
fn serve(lua: &Lua) -> SocketAddr {
    let r = run(
        lua,
        "server = assert(socket.bind('*', 0)); local ip, port = server:getsockname(); return ip, port",
        (),
    );
    SocketAddr::new(r[0].parse().expect("an IP"), r[1].parse().expect("a port"))
}

/// A peer that connects to `addr`, writes `bytes`, then reads until the server closes
/// and returns what it read (or closes at once after writing with `close_after`).
fn peer(addr: SocketAddr, bytes: &'static [u8], close_after: bool) -> JoinHandle<Vec<u8>> {
    std::thread::spawn(move || {
        let mut s = TcpStream::connect(addr).expect("connect to the script's server");
        s.write_all(bytes).expect("write");
        let mut got = Vec::new();
        if !close_after {
            s.read_to_end(&mut got).expect("read the reply");
        }
        got
    })
}

#[test]
fn a_line_with_crlf_comes_without_cr_and_the_echo_goes_back() {
    let lua = lua();
    let addr = serve(&lua);
    assert_eq!(addr.ip().to_string(), "127.0.0.1", "'*' is gantry's bind address");
    assert_ne!(addr.port(), 0);
    let client = peer(addr, b"<FK#J1=0.5,J2=0>\r\nsecond\n", false);
    let r = run(
        &lua,
        r#"
        local c = server:accept()
        c:settimeout(10)
        local a, err = c:receive()
        local b = c:receive('*l')
        local sent = c:send(a .. "\n")
        c:close()
        return a, tostring(err), b, sent
        "#,
        (),
    );
    assert_eq!(r, ["<FK#J1=0.5,J2=0>", "nil", "second", "17"]);
    assert_eq!(client.join().expect("peer"), b"<FK#J1=0.5,J2=0>\n");
}

#[test]
fn receive_by_count_with_prefix_and_all_until_closed() {
    let lua = lua();
    let addr = serve(&lua);
    let client = peer(addr, b"12345rest of it", true);
    let r = run(
        &lua,
        "local c = server:accept(); return c:receive(3), c:receive(2, 'x'), c:receive('*a')",
        (),
    );
    client.join().expect("peer");
    assert_eq!(r, ["123", "x45", "rest of it"]);
}

#[test]
fn a_line_cut_by_close_returns_closed_and_the_partial_line() {
    let lua = lua();
    let addr = serve(&lua);
    let client = peer(addr, b"par\rtial", true);
    let r = run(
        &lua,
        "local c = server:accept(); local l, e, p = c:receive(); return l, e, p, select(2, c:receive())",
        (),
    );
    client.join().expect("peer");
    assert_eq!(r, ["nil", "closed", "partial", "closed"]);
}

#[test]
fn timeouts_give_timeout_and_what_came() {
    let lua = lua();
    let addr = serve(&lua);
    // No client yet: a non-blocking accept.
    let r = run(&lua, "server:settimeout(0); return server:accept()", ());
    assert_eq!(r, ["nil", "timeout"]);
    let (tx, rx) = std::sync::mpsc::channel::<()>();
    let client = std::thread::spawn(move || {
        let mut s = TcpStream::connect(addr).expect("connect");
        s.write_all(b"no end of line").expect("write");
        // Keep the connection open until the server has timed out.
        rx.recv().ok();
    });
    let r = run(
        &lua,
        "server:settimeout(nil); local c = server:accept(); c:settimeout(0.05); return c:receive()",
        (),
    );
    tx.send(()).expect("the peer waits");
    client.join().expect("peer");
    assert_eq!(r, ["nil", "timeout", "no end of line"]);
}

#[test]
fn send_returns_the_index_of_the_last_byte_sent() {
    let lua = lua();
    let addr = serve(&lua);
    let client = peer(addr, b"", false);
    let r = run(
        &lua,
        "local c = server:accept(); local a = c:send('hello'); local b = c:send('hello', 2, 4); c:close(); \
         return a, b, c:send('x')",
        (),
    );
    assert_eq!(r, ["5", "4", "nil", "closed"]);
    assert_eq!(client.join().expect("peer"), b"helloell");
}

#[test]
fn outgoing_connections_are_refused_unless_allowed() {
    let target = TcpListener::bind("127.0.0.1:0").expect("a listener");
    let port = target.local_addr().expect("its address").port();
    let r = run(&lua(), "return socket.connect('127.0.0.1', ...)", port);
    assert_eq!(r[0], "nil");
    assert!(
        r[1].starts_with("connection refused") && r[1].contains("--allow-script-connect"),
        "{}",
        r[1]
    );
    let allowed = lua_with(NetworkParams {
        allow_connect: true,
        ..NetworkParams::default()
    });
    let r = run(
        &allowed,
        "local c = assert(socket.connect('127.0.0.1', ...)); local ip, p = c:getpeername(); \
         return c:send('hi'), p",
        port,
    );
    assert_eq!(r, ["2", port.to_string().as_str()]);
    let (mut s, _) = target.accept().expect("the script's connection");
    let mut got = [0u8; 2];
    s.read_exact(&mut got).expect("read");
    assert_eq!(&got, b"hi");
}

#[test]
fn scripts_listen_only_where_gantry_listens() {
    let r = run(&lua(), "return socket.bind('192.0.2.7', 0)", ());
    assert_eq!(r[0], "nil");
    assert!(
        r[1].starts_with("permission denied") && r[1].contains("127.0.0.1"),
        "{}",
        r[1]
    );
    // Loopback by name is fine.
    assert_eq!(
        run(&lua(), "return tostring(socket.bind('localhost', 0))", ())[0]
            .split(':')
            .next(),
        Some("tcp{server}")
    );
    // With --bind 0.0.0.0, '*' is every interface.
    let wide = lua_with(NetworkParams {
        listen: Some("0.0.0.0".parse().expect("an IP")),
        ..NetworkParams::default()
    });
    assert_eq!(
        run(&wide, "return assert(socket.bind('*', 0)):getsockname()", ())[0],
        "0.0.0.0"
    );
    // With --no-listen, nowhere.
    let none = lua_with(NetworkParams {
        listen: None,
        ..NetworkParams::default()
    });
    let r = run(&none, "return socket.bind('*', 0)", ());
    assert!(r[0] == "nil" && r[1].contains("--no-listen"), "{r:?}");
}

#[test]
fn a_port_taken_by_gantry_is_named_in_the_error() {
    let taken = TcpListener::bind("127.0.0.1:0").expect("a listener");
    let port = taken.local_addr().expect("its address").port();
    let lua = lua_with(NetworkParams {
        gantry_ports: vec![(port, "text channel (--text-port)".into())],
        ..NetworkParams::default()
    });
    let r = run(&lua, "return socket.bind('*', ...)", port);
    assert_eq!(r[0], "nil");
    assert!(
        r[1].starts_with("address already in use") && r[1].contains("text channel") && r[1].contains("--script-port"),
        "{}",
        r[1]
    );
}

#[test]
fn mapped_ports_and_close_all_free_the_port() {
    let lua = lua_with(NetworkParams {
        port_map: vec![(6000, 0)],
        ..NetworkParams::default()
    });
    let r = run(
        &lua,
        "server = assert(socket.bind('*', 6000)); return select(2, server:getsockname())",
        (),
    );
    let port: u16 = r[0].parse().expect("a port");
    assert_ne!(port, 6000, "6000 is mapped to a free port");
    assert_eq!(
        state::<Sockets>(&lua).listening(),
        [SocketAddr::from(([127, 0, 0, 1], port))]
    );
    // The script still holds `server`; a stop closes it anyway.
    state::<Sockets>(&lua).close_all();
    TcpListener::bind(("127.0.0.1", port)).expect("the port is free after close_all");
    assert_eq!(run(&lua, "return server:accept()", ()), ["nil", "closed"]);
}

#[test]
fn a_blocked_accept_gives_up_when_gantry_stops() {
    let lua = lua_with(NetworkParams {
        stop: Some(Arc::new(AtomicBool::new(true))),
        ..NetworkParams::default()
    });
    serve(&lua);
    let e = lua
        .load("server:accept()")
        .exec()
        .expect_err("no client, and gantry is stopping");
    assert!(e.to_string().contains("gantry is stopping"), "{e}");
}

#[test]
fn a_blocked_accept_gives_up_for_a_stop_request_until_it_is_served() {
    let lua = lua_with(NetworkParams {
        interrupt: Some(Arc::new(AtomicBool::new(true))),
        ..NetworkParams::default()
    });
    serve(&lua);
    let e = lua.load("server:accept()").exec().expect_err("a stop is pending");
    assert!(e.to_string().contains("the simulation is stopping"), "{e}");
    // The stop was served: waits wait again.
    state::<Sockets>(&lua).clear_interrupt();
    assert_eq!(
        run(&lua, "server:settimeout(0); return server:accept()", ()),
        ["nil", "timeout"]
    );
}

#[test]
fn time_spent_waiting_is_given_back_to_the_budget() {
    let lua = lua();
    serve(&lua);
    let running = state::<Running>(&lua);
    running.restart_budget();
    let before = running.deadline.get();
    drop(running);
    let started = Instant::now();
    assert_eq!(
        run(&lua, "server:settimeout(0.2); return server:accept()", ()),
        ["nil", "timeout"]
    );
    let waited = started.elapsed();
    let moved = state::<Running>(&lua).deadline.get() - before;
    assert!(
        moved >= Duration::from_millis(200),
        "deadline moved by {moved:?} after waiting {waited:?}"
    );
}

#[test]
fn a_wait_spends_its_slices_in_the_front_ends_service() {
    let lua = lua();
    serve(&lua);
    let slices = std::rc::Rc::new(std::cell::Cell::new(Duration::ZERO));
    let seen = slices.clone();
    let service: crate::waiting::WaitService = std::rc::Rc::new(move |slice| {
        seen.set(seen.get() + slice);
        std::thread::sleep(slice);
    });
    state::<crate::waiting::Waiting>(&lua).set(Some(service));
    assert_eq!(
        run(&lua, "server:settimeout(0.1); return server:accept()", ()),
        ["nil", "timeout"]
    );
    // Every slice of the 0.1 s wait went to the service (the last one may be cut).
    assert!(slices.get() >= Duration::from_millis(90), "{:?}", slices.get());
}

#[test]
fn wrong_objects_and_missing_parts_raise_clear_errors() {
    let lua = lua();
    let e = lua
        .load("socket.tcp():accept()")
        .exec()
        .expect_err("a master cannot accept");
    assert!(e.to_string().contains("tcp{server} expected, got tcp{master}"), "{e}");
    let e = lua.load("socket.udp()").exec().expect_err("no UDP");
    assert!(e.to_string().contains("TCP subset"), "{e}");
    assert_eq!(run(&lua, "return socket.tcp():setoption('reuseaddr', true)", ()), ["1"]);
    assert_eq!(run(&lua, "return type(socket.gettime())", ()), ["number"]);
}

#[test]
fn luasocket_use_is_seen_in_the_script_text() {
    for yes in [
        "local socket = require(\"socket\")",
        "local s = require 'socket'",
        "local core = require('socket.core')",
        "local s = require [[socket]]",
        "server = socket.bind('*', 6000)",
    ] {
        assert!(uses_luasocket(yes), "{yes}");
    }
    for no in [
        "sim = require 'sim'",
        "local sockets = require('sockets')",
        "-- a socket of the arm\nsim.getObject('/socket')",
    ] {
        assert!(!uses_luasocket(no), "{no}");
    }
}
