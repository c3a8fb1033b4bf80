//! LuaSocket's TCP subset, for the CoppeliaSim scenes whose scripts are TCP servers
//! (the seed paper's `Blue Robot.ttt`: `require("socket")`, `socket.bind("*", 6000)`,
//! a blocking `server:accept()` in every `sysCall_actuation`, `receive`, `send`,
//! `close`).
//!
//! `require 'socket'` (or `'socket.core'`, and the global `socket` that LuaSocket 2
//! left behind) gives `bind`, `tcp`, `connect`, `gettime` and `sleep`, and TCP objects
//! with `accept`, `receive` (`"*l"`, `"*a"`, a byte count, a prefix), `send`,
//! `settimeout`, `close`, `shutdown`, `getsockname`, `getpeername`, `setoption`,
//! `bind`, `listen` and `connect`, returning what LuaSocket 3 returns, errors
//! included (see [`tcp`]). Not served: UDP, `socket.select`, DNS helpers and the
//! Lua-side helpers (`socket.try`, `socket.protect`, the `http`/`smtp` modules).
//!
//! The sandbox (see [`crate::limits::NetworkParams`]):
//! * scripts listen only where gantry's own listeners do: `bind('*')` binds gantry's
//!   bind address (127.0.0.1 unless `--bind`), and loopback is always allowed;
//! * outgoing connections are refused unless the user allowed them;
//! * a port can be mapped to another (`--script-port 6000=6001`);
//! * every socket closes when its script goes (stop, reload, removal) and with the
//!   Lua state, so a stop and a start bind the same port again.
//!
//! Blocking calls wait as CoppeliaSim's do, the whole simulation with them (a
//! non-threaded script blocked in `accept` holds the step, as in CoppeliaSim; threaded
//! scripts are coroutines here, as in CoppeliaSim 4.2+, and hold it too), but give up
//! when the process is stopping or a client asked to stop the simulation, and do not
//! count against the time budget (see [`wait`]).

mod sockets;
mod tcp;
mod wait;

use std::time::{Duration, SystemTime, UNIX_EPOCH};

use mlua::{IntoLuaMulti, Lua, MultiValue, ObjectLike, Value as LuaValue};

use sockets::OpenSocket;
pub(crate) use sockets::Sockets;
use tcp::{Kind, TcpObject};
use wait::{Waited, wait_for};

/// Creates the global `socket` table (the sandbox's `require` returns it for
/// `'socket'` and `'socket.core'`). The [`Sockets`] state must be installed.
pub(crate) fn install(lua: &Lua) -> mlua::Result<()> {
    let socket = lua.create_table()?;
    socket.set("_VERSION", "LuaSocket 3.0 (gantry's TCP subset)")?;

    socket.set(
        "tcp",
        lua.create_function(|lua, ()| lua.create_userdata(TcpObject::open(lua, Kind::Master(None))))?,
    )?;

    // bind(host, port[, backlog]): a server, or `nil, err`. The backlog is the OS's.
    socket.set(
        "bind",
        lua.create_function(|lua, (host, port, _backlog): (String, u16, Option<i64>)| {
            let server = lua.create_userdata(TcpObject::open(lua, Kind::Master(None)))?;
            for (method, args) in [
                ("bind", (host.clone(), port).into_lua_multi(lua)?),
                ("listen", MultiValue::new()),
            ] {
                let r: MultiValue = server.call_method(method, args)?;
                if matches!(r.front(), None | Some(LuaValue::Nil)) {
                    server.borrow::<TcpObject>()?.0.borrow_mut().close();
                    return Ok(r);
                }
            }
            Ok(MultiValue::from_iter([LuaValue::UserData(server)]))
        })?,
    )?;

    // connect(host, port): a client, or `nil, err` (refused by default: see `Sockets`).
    socket.set(
        "connect",
        lua.create_function(|lua, (host, port): (String, u16)| {
            let client = lua.create_userdata(TcpObject::open(lua, Kind::Master(None)))?;
            let r: MultiValue = client.call_method("connect", (host, port))?;
            if matches!(r.front(), None | Some(LuaValue::Nil)) {
                client.borrow::<TcpObject>()?.0.borrow_mut().close();
                return Ok(r);
            }
            Ok(MultiValue::from_iter([LuaValue::UserData(client)]))
        })?,
    )?;

    // gettime(): wall-clock seconds since the Unix epoch, as LuaSocket's.
    socket.set(
        "gettime",
        lua.create_function(|_, ()| {
            Ok(SystemTime::now()
                .duration_since(UNIX_EPOCH)
                .map_or(0.0, |d| d.as_secs_f64()))
        })?,
    )?;

    // sleep(seconds): waits like a blocking call (stops early when gantry stops, and
    // not against the time budget).
    socket.set(
        "sleep",
        lua.create_function(|lua, s: f64| {
            if s > 0.0 && s.is_finite() {
                let d = Duration::from_secs_f64(s.min(1e6));
                match wait_for(lua, Some(d), || Ok(None::<()>)) {
                    Ok(Waited::Ready(()) | Waited::TimedOut | Waited::Stopping(_)) | Err(_) => {}
                }
            }
            Ok(())
        })?,
    )?;

    for missing in ["udp", "udp4", "udp6", "select"] {
        socket.set(
            missing,
            lua.create_function(move |_, _: MultiValue| -> mlua::Result<()> {
                Err(mlua::Error::runtime(format!(
                    "socket.{missing} is not available in gantry: scripts get LuaSocket's TCP subset \
                     (bind, tcp, connect, gettime, sleep)"
                )))
            })?,
        )?;
    }
    lua.globals().set("socket", socket)
}

/// Whether a script's text uses LuaSocket: it requires `socket` (or `socket.core`) or
/// calls `socket.bind`/`socket.tcp`/`socket.connect`. Read from the text, without
/// running it: the binary decides before the scene starts whether gantry's text channel
/// may take port 6000, which the paper's server script binds.
pub fn uses_luasocket(source: &str) -> bool {
    if ["socket.bind(", "socket.tcp(", "socket.connect("]
        .iter()
        .any(|call| source.contains(call))
    {
        return true;
    }
    // require 'socket', require("socket"), require [[socket.core]], ...
    source.match_indices("require").any(|(at, _)| {
        let rest = source[at + "require".len()..].trim_start();
        let rest = rest.strip_prefix('(').unwrap_or(rest).trim_start();
        let rest = rest
            .strip_prefix('"')
            .or_else(|| rest.strip_prefix('\''))
            .or_else(|| rest.strip_prefix("[["));
        rest.is_some_and(|r| {
            r.strip_prefix("socket")
                .is_some_and(|after| after.starts_with(['"', '\'', ']']) || after.starts_with(".core"))
        })
    })
}

#[cfg(test)]
mod tests;
