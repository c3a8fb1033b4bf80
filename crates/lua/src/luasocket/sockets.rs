//! Every socket the scripts opened, and the sandbox's rules for opening one.
//!
//! Sockets are Lua userdata, so Lua's collector would close them whenever it gets
//! round to it. That is too late for a stop: CoppeliaSim gives each run fresh Lua
//! states, so a scene's script binds port 6000 again at every start and must find it
//! free. The host therefore closes the sockets itself when the script that opened them
//! goes away: all of them at a stop ([`Sockets::close_all`]), one script's at its
//! reload or removal ([`Sockets::close_owned_by`]); dropping the Lua state closes the
//! rest.

use std::cell::RefCell;
use std::io;
use std::net::{IpAddr, Ipv4Addr, Ipv6Addr, SocketAddr, ToSocketAddrs};
use std::rc::{Rc, Weak};

use crate::limits::NetworkParams;

/// What the registry needs of a socket (the TCP objects implement it).
pub(crate) trait OpenSocket {
    /// Closes it now: its port is free when this returns.
    fn close(&mut self);
    /// The address it listens on, if it is a server.
    fn listening_on(&self) -> Option<SocketAddr>;
}

/// Why the sandbox refuses a `bind` or a `connect`. The text is LuaSocket-style (scripts
/// test `err` against LuaSocket's strings, hence the `permission denied` and
/// `connection refused` prefixes) and goes to the script as the call's error value.
#[derive(Debug, thiserror::Error)]
pub(crate) enum SandboxError {
    /// gantry runs with `--no-listen`.
    #[error("permission denied: gantry runs with --no-listen, so scripts may not listen either")]
    NoListen,
    /// `bind` to a host name other than `localhost`.
    #[error("permission denied: gantry's scripts listen on an IP address, '*' or 'localhost', not '{0}'")]
    ListenHost(String),
    /// `bind` to an address that is neither gantry's bind address nor loopback.
    #[error(
        "permission denied: gantry's scripts may listen only on its bind address {ours} or on loopback, \
         not {ip} (ask for '*'; `gantry run --bind ADDR` moves gantry and its scripts)"
    )]
    ListenAddress {
        /// gantry's bind address.
        ours: IpAddr,
        /// The address asked for.
        ip: IpAddr,
    },
    /// Outgoing connections are not allowed.
    #[error(
        "connection refused: gantry's sandbox does not let scripts open connections (to {host}:{port}); \
         run gantry with --allow-script-connect to allow it"
    )]
    NoConnect { host: String, port: u16 },
    /// The host name does not resolve.
    #[error("host not found: {host} ({source})")]
    Resolve { host: String, source: io::Error },
    /// The host name resolves to no address.
    #[error("host not found: {host}")]
    NoAddress { host: String },
}

/// A socket and the index of the script that opened it.
type Opened = (Option<usize>, Weak<RefCell<dyn OpenSocket>>);

/// The open sockets and the rules (installed in the Lua state's app data).
pub(crate) struct Sockets {
    /// What scripts may do.
    pub(crate) params: NetworkParams,
    /// Each socket with the index of the script that opened it (`None`: code run for a
    /// remote client). Weak: a socket the script dropped is closed by the collector.
    open: RefCell<Vec<Opened>>,
}

impl Sockets {
    /// No socket yet, under `params`.
    pub(crate) fn new(params: NetworkParams) -> Self {
        Self {
            params,
            open: RefCell::new(Vec::new()),
        }
    }

    /// Records a socket opened by script `owner`.
    pub(crate) fn register(&self, owner: Option<usize>, socket: &Rc<RefCell<dyn OpenSocket>>) {
        let mut open = self.open.borrow_mut();
        open.retain(|(_, s)| s.strong_count() > 0);
        open.push((owner, Rc::downgrade(socket)));
    }

    /// Closes every socket (the simulation stopped: its scripts' states are gone).
    pub(crate) fn close_all(&self) {
        for (_, s) in self.open.take() {
            if let Some(s) = s.upgrade() {
                s.borrow_mut().close();
            }
        }
    }

    /// Closes the sockets of script `script` (reloaded or removed).
    pub(crate) fn close_owned_by(&self, script: usize) {
        self.open.borrow_mut().retain(|(owner, s)| {
            if *owner != Some(script) {
                return true;
            }
            if let Some(s) = s.upgrade() {
                s.borrow_mut().close();
            }
            false
        });
    }

    /// A stop, start or new scene has come: a pending interrupt is served.
    pub(crate) fn clear_interrupt(&self) {
        if let Some(i) = &self.params.interrupt {
            i.store(false, std::sync::atomic::Ordering::SeqCst);
        }
    }

    /// The addresses scripts listen on now.
    pub(crate) fn listening(&self) -> Vec<SocketAddr> {
        self.open
            .borrow()
            .iter()
            .filter_map(|(_, s)| s.upgrade()?.borrow().listening_on())
            .collect()
    }

    /// Where `bind(host, port)` may listen, or why it may not (a LuaSocket-style
    /// message: scripts test `err` against LuaSocket's strings, hence the prefix).
    pub(crate) fn listen_address(&self, host: &str, port: u16) -> Result<SocketAddr, SandboxError> {
        let Some(ours) = self.params.listen else {
            return Err(SandboxError::NoListen);
        };
        let port = self.params.mapped_port(port);
        let ip = match host {
            // LuaSocket's "any address": here, gantry's own bind address.
            "*" | "" | "0.0.0.0" | "::" => ours,
            "localhost" => match ours {
                IpAddr::V6(_) => IpAddr::V6(Ipv6Addr::LOCALHOST),
                IpAddr::V4(_) => IpAddr::V4(Ipv4Addr::LOCALHOST),
            },
            other => other.parse().map_err(|_| SandboxError::ListenHost(other.to_owned()))?,
        };
        if ip.is_loopback() || ip == ours || ours.is_unspecified() {
            Ok(SocketAddr::new(ip, port))
        } else {
            Err(SandboxError::ListenAddress { ours, ip })
        }
    }

    /// The address `connect(host, port)` may reach, or why not.
    pub(crate) fn connect_address(&self, host: &str, port: u16) -> Result<SocketAddr, SandboxError> {
        if !self.params.allow_connect {
            return Err(SandboxError::NoConnect {
                host: host.to_owned(),
                port,
            });
        }
        let port = self.params.mapped_port(port);
        (host, port)
            .to_socket_addrs()
            .map_err(|source| SandboxError::Resolve {
                host: host.to_owned(),
                source,
            })?
            .next()
            .ok_or_else(|| SandboxError::NoAddress { host: host.to_owned() })
    }

    /// LuaSocket's message for `e` from `bind` on `addr`, with what holds the port when
    /// it is one of gantry's own.
    pub(crate) fn bind_error(&self, addr: SocketAddr, e: &io::Error) -> String {
        let base = error_text(e);
        if e.kind() != io::ErrorKind::AddrInUse {
            return base;
        }
        match self.params.gantry_ports.iter().find(|(p, _)| *p == addr.port()) {
            Some((p, what)) => format!(
                "{base} (gantry's {what} listens on port {p}: give it another port, or map the script's \
                 with --script-port {p}=OTHER)"
            ),
            None => format!(
                "{base} (another program, or another gantry, listens on port {}: stop it, or map the \
                 script's port with --script-port {}=OTHER)",
                addr.port(),
                addr.port()
            ),
        }
    }
}

/// LuaSocket's error strings for the OS errors scripts may test for.
pub(crate) fn error_text(e: &io::Error) -> String {
    use io::ErrorKind as K;
    match e.kind() {
        K::AddrInUse => "address already in use".into(),
        K::AddrNotAvailable => "cannot assign requested address".into(),
        K::ConnectionRefused => "connection refused".into(),
        K::PermissionDenied => "permission denied".into(),
        K::BrokenPipe | K::ConnectionReset | K::ConnectionAborted | K::NotConnected | K::UnexpectedEof => {
            "closed".into()
        }
        K::TimedOut | K::WouldBlock => "timeout".into(),
        _ => e.to_string(),
    }
}
