//! `simRemoteApi`: servers of CoppeliaSim's legacy remote API (the `simx*` clients)
//! that scripts start, as CoppeliaSim's legacy remote API plugin lets them.
//!
//! The Lua host owns no sockets: whoever runs the simulation with its transports (the
//! `gantry` binary's server) gives it a [`Listeners`], and `simRemoteApi.start(port)`
//! asks that front end to listen. Without one (the Python package in-process, tests),
//! the functions fail with a message saying so. As in CoppeliaSim, a server a script
//! starts while the simulation runs ends when the simulation stops; one started while
//! it is stopped (from `sysCall_nonSimulation` or an add-on) stays until the run ends.

use std::cell::RefCell;
use std::rc::Rc;
use std::sync::Arc;

use mlua::{Function, Lua, MultiValue, Table, Value as LuaValue};

/// What a legacy remote API server reports to `simRemoteApi.status`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ListenerStatus {
    /// Whether a client is connected now.
    pub connected: bool,
    /// The protocol version the client sent (0 before its first message).
    pub client_version: u8,
    /// The connected client's address, empty when none.
    pub client_ip: String,
    /// The protocol version the server speaks.
    pub server_version: u8,
}

/// Why a legacy remote API server could not be started or stopped. `simRemoteApi`
/// logs the text and returns 0, as CoppeliaSim prints the reason.
#[derive(Debug, thiserror::Error)]
pub enum ListenerError {
    /// A server of this front end already runs on the port.
    #[error("a legacy remote API server already runs on port {0}")]
    AlreadyRunning(u16),
    /// No server runs on the port.
    #[error("no legacy remote API server runs on port {0}")]
    NotRunning(u16),
    /// A script asked for port 0 (any free port), which no client could find.
    #[error("port 0: scripts name the port their clients connect to")]
    PortZero,
    /// The operating system refused the listening socket (the port is in use, ...).
    #[error("cannot listen on {address}: {source}")]
    Listen {
        /// The address, as `IP:PORT`.
        address: String,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// A thread panicked while holding the table of servers.
    #[error("the server table is poisoned")]
    Poisoned,
}

/// Why a `simRemoteApi` port argument is refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
enum PortArgError {
    /// An integer outside 1..=65535.
    #[error("argument 1: port {0} is not between 1 and 65535")]
    OutOfRange(i64),
    /// Not an integer: the Lua type name of what was passed.
    #[error("argument 1: expected a port number, got {0}")]
    NotAPort(&'static str),
}

/// The front end's side of `simRemoteApi`: it opens and closes listeners.
pub trait Listeners: Send + Sync + std::fmt::Debug {
    /// Starts a legacy remote API server on `port` (on the front end's bind address).
    ///
    /// # Errors
    /// Why it cannot (the port is in use, a server already runs there).
    fn start_legacy(&self, port: u16) -> Result<(), ListenerError>;
    /// Stops the server on `port` and drops its client.
    ///
    /// # Errors
    /// No server runs on `port`.
    fn stop_legacy(&self, port: u16) -> Result<(), ListenerError>;
    /// The server on `port`, if one runs.
    fn legacy_status(&self, port: u16) -> Option<ListenerStatus>;
}

/// The functions of module `simRemoteApi`, sorted (the registry lists the same names;
/// a test checks the two agree).
pub const FUNCTIONS: &[&str] = &["reset", "start", "status", "stop"];

/// The host's state for `simRemoteApi`.
#[derive(Default)]
pub(crate) struct ListenerState {
    /// The front end, when the simulation runs with transports.
    pub(crate) front_end: Option<Arc<dyn Listeners>>,
    /// Ports of servers started while the simulation ran: stopped with it.
    pub(crate) for_this_run: Vec<u16>,
}

impl ListenerState {
    /// The simulation stopped: end the servers started during the run.
    pub(crate) fn simulation_ended(&mut self) {
        let ports = std::mem::take(&mut self.for_this_run);
        if let Some(f) = &self.front_end {
            for port in ports {
                if let Err(e) = f.stop_legacy(port) {
                    tracing::debug!("legacy remote API server on port {port}: {e}");
                }
            }
        }
    }
}

const NO_FRONT_END: &str = "no legacy remote API in this embedding: run the scene with `gantry run` \
     (or pass --legacy-port to start a server without a script)";

fn port_arg(v: Option<&LuaValue>) -> Result<u16, PortArgError> {
    let n = match v {
        Some(LuaValue::Integer(i)) => Some(*i),
        Some(LuaValue::Number(n)) if n.fract() == 0.0 => Some(*n as i64),
        _ => None,
    };
    match n {
        Some(p) if (1..=65535).contains(&p) => Ok(p as u16),
        Some(p) => Err(PortArgError::OutOfRange(p)),
        None => Err(PortArgError::NotAPort(v.map_or("no value", LuaValue::type_name))),
    }
}

/// Creates the `simRemoteApi` table. `running` says whether the simulation runs (a
/// server started then ends with the run). Each function reports failure as
/// `(false, message)` for the API's error wrapper `wrap`.
pub(crate) fn install(
    lua: &Lua,
    state: &Rc<RefCell<ListenerState>>,
    running: Rc<dyn Fn() -> bool>,
    wrap: &Function,
) -> mlua::Result<Table> {
    let table = lua.create_table()?;
    let fail = |lua: &Lua, name: &str, e: &dyn std::fmt::Display| -> mlua::Result<MultiValue> {
        Ok(MultiValue::from_iter([
            LuaValue::Boolean(false),
            LuaValue::String(lua.create_string(format!("{e} (in function 'simRemoteApi.{name}')"))?),
        ]))
    };
    let ok = |values: Vec<LuaValue>| -> mlua::Result<MultiValue> {
        let mut out = MultiValue::from_iter(values);
        out.push_front(LuaValue::Boolean(true));
        Ok(out)
    };

    // start(port, maxPacketSize=1300, debug=false, preEnableTrigger=false): 1 when the
    // server listens, 0 when it cannot (the reason is logged, as CoppeliaSim prints it).
    // Packets are always at most 1300 bytes and the trigger is always allowed, so the
    // optional arguments change nothing.
    let st = state.clone();
    table.set(
        "start",
        wrap.call::<Function>(lua.create_function(move |lua, args: MultiValue| {
            let port = match port_arg(args.front()) {
                Ok(p) => p,
                Err(e) => return fail(lua, "start", &e),
            };
            let Some(front) = st.borrow().front_end.clone() else {
                return fail(lua, "start", &NO_FRONT_END);
            };
            match front.start_legacy(port) {
                Ok(()) => {
                    if running() {
                        st.borrow_mut().for_this_run.push(port);
                    }
                    ok(vec![LuaValue::Integer(1)])
                }
                Err(e) => {
                    tracing::warn!("simRemoteApi.start({port}): {e}");
                    ok(vec![LuaValue::Integer(0)])
                }
            }
        })?)?,
    )?;
    let st = state.clone();
    table.set(
        "stop",
        wrap.call::<Function>(lua.create_function(move |lua, args: MultiValue| {
            let port = match port_arg(args.front()) {
                Ok(p) => p,
                Err(e) => return fail(lua, "stop", &e),
            };
            let Some(front) = st.borrow().front_end.clone() else {
                return fail(lua, "stop", &NO_FRONT_END);
            };
            st.borrow_mut().for_this_run.retain(|&p| p != port);
            match front.stop_legacy(port) {
                Ok(()) => ok(vec![LuaValue::Integer(1)]),
                Err(e) => {
                    tracing::warn!("simRemoteApi.stop({port}): {e}");
                    ok(vec![LuaValue::Integer(0)])
                }
            }
        })?)?,
    )?;
    // reset(port): CoppeliaSim drops the client and forgets its streaming commands; the
    // server here keeps no state beyond its client, so a restart does the same.
    let st = state.clone();
    table.set(
        "reset",
        wrap.call::<Function>(lua.create_function(move |lua, args: MultiValue| {
            let port = match port_arg(args.front()) {
                Ok(p) => p,
                Err(e) => return fail(lua, "reset", &e),
            };
            let Some(front) = st.borrow().front_end.clone() else {
                return fail(lua, "reset", &NO_FRONT_END);
            };
            let restarted = front.stop_legacy(port).and_then(|()| front.start_legacy(port));
            match restarted {
                Ok(()) => ok(vec![LuaValue::Integer(1)]),
                Err(e) => {
                    tracing::warn!("simRemoteApi.reset({port}): {e}");
                    ok(vec![LuaValue::Integer(0)])
                }
            }
        })?)?,
    )?;
    // status(port): status (-1 no server, 0 waiting for a client, 1 connected), info
    // (the client's address or a description), server version, client version, client IP.
    let st = state.clone();
    table.set(
        "status",
        wrap.call::<Function>(lua.create_function(move |lua, args: MultiValue| {
            let port = match port_arg(args.front()) {
                Ok(p) => p,
                Err(e) => return fail(lua, "status", &e),
            };
            let status = st.borrow().front_end.as_ref().and_then(|f| f.legacy_status(port));
            match status {
                None => ok(vec![
                    LuaValue::Integer(-1),
                    LuaValue::String(lua.create_string("no server on this port")?),
                    LuaValue::Integer(0),
                    LuaValue::Integer(0),
                    LuaValue::String(lua.create_string("")?),
                ]),
                Some(s) => ok(vec![
                    LuaValue::Integer(i64::from(s.connected)),
                    LuaValue::String(lua.create_string(if s.connected {
                        "connected"
                    } else {
                        "waiting for a client"
                    })?),
                    LuaValue::Integer(i64::from(s.server_version)),
                    LuaValue::Integer(i64::from(s.client_version)),
                    LuaValue::String(lua.create_string(&s.client_ip)?),
                ]),
            }
        })?)?,
    )?;
    Ok(table)
}
