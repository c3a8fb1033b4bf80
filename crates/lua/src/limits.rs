//! How long a script may run, how much memory Lua may use, and what it may do on the
//! network.

use std::net::{IpAddr, Ipv4Addr};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

/// Limits that keep a script from stalling or exhausting the simulator, or from
/// reaching further on the network than gantry itself does.
#[derive(Debug, Clone)]
pub struct ScriptLimits {
    /// Longest a single hook call may run before it is interrupted. Time a script
    /// spends blocked in a LuaSocket call (waiting for a client or for bytes) is not
    /// counted: a CoppeliaSim server script legitimately waits in `accept` for as long
    /// as no client comes.
    pub time_budget: Duration,
    /// Memory of the shared Lua state, bytes.
    pub memory: usize,
    /// What scripts may do with LuaSocket.
    pub network: NetworkParams,
    /// Programs `sim.launchExecutable` may start (`gantry run --allow-launch`); none by
    /// default.
    pub allow_launch: Vec<std::path::PathBuf>,
    /// Folders `require` searches for the user's modules after the scene's folder
    /// (`gantry run --lua-path DIR`, repeatable).
    pub lua_path: Vec<std::path::PathBuf>,
    /// Folders scripts may read and write with `io.open` (`gantry run --allow-files DIR`,
    /// repeatable); the scene's own folder is readable without it, never writable.
    pub allow_files: Vec<std::path::PathBuf>,
}

impl Default for ScriptLimits {
    fn default() -> Self {
        Self {
            time_budget: Duration::from_secs(1),
            memory: 512 << 20,
            network: NetworkParams::default(),
            allow_launch: Vec::new(),
            lua_path: Vec::new(),
            allow_files: Vec::new(),
        }
    }
}

/// What scripts may do through the LuaSocket subset (`require 'socket'`): where they
/// may listen, whether they may connect out, and which ports they really get.
#[derive(Debug, Clone)]
pub struct NetworkParams {
    /// Where `socket.bind('*', port)` listens: gantry's own bind address (`--bind`,
    /// default 127.0.0.1). Scripts may listen there or on loopback, nowhere else.
    /// `None`: scripts may not listen at all (`gantry run --no-listen`).
    pub listen: Option<IpAddr>,
    /// Whether `socket.connect` may open outgoing connections (off by default: a
    /// downloaded scene should not reach other machines; `--allow-script-connect`).
    pub allow_connect: bool,
    /// `(asked, used)`: a script that binds or connects to port `asked` gets port
    /// `used` instead (`--script-port 6000=6001`; `used` 0 = any free port). Lets two
    /// scenes that both hard-code a port run side by side, and tests use free ports.
    pub port_map: Vec<(u16, u16)>,
    /// Ports gantry's own listeners hold, with what they are (`"the text channel
    /// (--text-port)"`): a script whose `bind` finds one of them in use is told so.
    pub gantry_ports: Vec<(u16, String)>,
    /// Set when the process is stopping (Ctrl-C, SIGTERM): a script blocked in a
    /// socket call gives up, so the simulation thread can run the cleanup hooks and
    /// exit. `None`: nothing stops a blocked call but its own timeout.
    pub stop: Option<Arc<AtomicBool>>,
    /// Set by the front end when a client asks to stop the simulation or load another
    /// scene: a script blocked in a socket call gives up, so the request is served
    /// (CoppeliaSim's GUI cannot even be clicked then). The host clears it when the
    /// simulation stops, starts or is built.
    pub interrupt: Option<Arc<AtomicBool>>,
}

impl Default for NetworkParams {
    fn default() -> Self {
        Self {
            listen: Some(IpAddr::V4(Ipv4Addr::LOCALHOST)),
            allow_connect: false,
            port_map: Vec::new(),
            gantry_ports: Vec::new(),
            stop: None,
            interrupt: None,
        }
    }
}

impl NetworkParams {
    /// The port a script asking for `port` gets (see [`NetworkParams::port_map`]).
    pub fn mapped_port(&self, port: u16) -> u16 {
        self.port_map
            .iter()
            .find(|(asked, _)| *asked == port)
            .map_or(port, |(_, used)| *used)
    }
}
