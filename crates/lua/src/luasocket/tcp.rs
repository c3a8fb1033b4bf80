//! LuaSocket's TCP objects: a master (`socket.tcp()`), which becomes a server by
//! `bind` and `listen` or a client by `connect`; clients also come from a server's
//! `accept`. One userdata type, as in LuaSocket, whose kind changes.
//!
//! Results follow LuaSocket 3: success returns the value (or 1), failure returns
//! `nil, message` with LuaSocket's messages (`"timeout"`, `"closed"`, `"address already
//! in use"`, ...), and `receive` and `send` add the partial result. Calling a method on
//! the wrong kind of object raises an error, as LuaSocket does.

use std::cell::RefCell;
use std::io::{self, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::rc::Rc;
use std::time::{Duration, Instant};

use mlua::{Lua, MultiValue, UserData, UserDataMethods, Value as LuaValue};

use super::sockets::{OpenSocket, Sockets, error_text};
use super::wait::{Waited, not_yet, wait_for};
use crate::app_state::state;
use crate::running::Running;

/// Longest a `connect` waits when the object has no timeout: a blocking connect cannot
/// be cut into slices, so it is bounded instead of waiting for the OS's minutes.
const CONNECT_CAP: Duration = Duration::from_secs(10);

/// What a TCP object is now.
pub(crate) enum Kind {
    /// Fresh from `socket.tcp()`, or bound (std binds and listens in one call, so a
    /// bound master already queues connections; `listen` only renames it).
    Master(Option<TcpListener>),
    /// Listening: `accept` gives clients.
    Server(TcpListener),
    /// Connected, with the bytes received but not yet returned by `receive`.
    Client(TcpStream, Vec<u8>),
    /// Closed: every call fails with `"closed"`.
    Closed,
}

/// One TCP object's state, shared by its userdata and the host's registry.
pub(crate) struct Tcp {
    pub(crate) kind: Kind,
    /// `settimeout`: `None` blocks for as long as it takes (LuaSocket's default).
    timeout: Option<Duration>,
}

impl OpenSocket for Tcp {
    fn close(&mut self) {
        self.kind = Kind::Closed;
    }

    fn listening_on(&self) -> Option<SocketAddr> {
        match &self.kind {
            Kind::Master(Some(l)) | Kind::Server(l) => l.local_addr().ok(),
            _ => None,
        }
    }
}

impl Tcp {
    fn kind_name(&self) -> &'static str {
        match self.kind {
            Kind::Master(_) => "master",
            Kind::Server(_) => "server",
            Kind::Client(..) => "client",
            Kind::Closed => "closed",
        }
    }
}

/// The userdata scripts hold.
#[derive(Clone)]
pub(crate) struct TcpObject(pub(crate) Rc<RefCell<Tcp>>);

impl TcpObject {
    /// A new object of `kind`, registered as opened by the running script.
    pub(crate) fn open(lua: &Lua, kind: Kind) -> Self {
        let tcp = Rc::new(RefCell::new(Tcp { kind, timeout: None }));
        let owner = state::<Running>(lua).script.get();
        let registered: Rc<RefCell<dyn OpenSocket>> = tcp.clone();
        state::<Sockets>(lua).register(owner, &registered);
        Self(tcp)
    }
}

/// `nil, message`.
fn fail(lua: &Lua, msg: &str) -> mlua::Result<MultiValue> {
    Ok(MultiValue::from_iter([
        LuaValue::Nil,
        LuaValue::String(lua.create_string(msg)?),
    ]))
}

/// `1`, LuaSocket's success for calls that return nothing else.
fn one() -> mlua::Result<MultiValue> {
    Ok(MultiValue::from_iter([LuaValue::Integer(1)]))
}

/// `ip, port, family`.
fn address(lua: &Lua, a: SocketAddr) -> mlua::Result<MultiValue> {
    let family = if a.is_ipv4() { "inet" } else { "inet6" };
    Ok(MultiValue::from_iter([
        LuaValue::String(lua.create_string(a.ip().to_string())?),
        LuaValue::Integer(i64::from(a.port())),
        LuaValue::String(lua.create_string(family)?),
    ]))
}

fn wrong_kind(method: &str, expected: &str, tcp: &Tcp) -> mlua::Error {
    mlua::Error::runtime(format!(
        "bad argument #1 to '{method}' (tcp{{{expected}}} expected, got tcp{{{}}})",
        tcp.kind_name()
    ))
}

fn stopping(method: &str, why: &str) -> mlua::Error {
    mlua::Error::runtime(format!("{method}: abandoned because {why}"))
}

/// What `receive` reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Pattern {
    /// `"*l"` (the default): a line ended by LF, without the LF and without any CR.
    Line,
    /// `"*a"`: everything until the peer closes.
    All,
    /// A number: exactly that many bytes.
    Bytes(usize),
}

impl Pattern {
    fn from_lua(v: &LuaValue) -> mlua::Result<Self> {
        match v {
            LuaValue::Nil => Ok(Self::Line),
            LuaValue::Integer(n) if *n >= 0 => Ok(Self::Bytes(*n as usize)),
            LuaValue::Number(n) if *n >= 0.0 && n.fract() == 0.0 => Ok(Self::Bytes(*n as usize)),
            LuaValue::String(s) => match s.to_str()?.as_ref() {
                "*l" | "l" => Ok(Self::Line),
                "*a" | "a" => Ok(Self::All),
                other => Err(mlua::Error::runtime(format!(
                    "bad argument #1 to 'receive' (invalid receive pattern '{other}')"
                ))),
            },
            other => Err(mlua::Error::runtime(format!(
                "bad argument #1 to 'receive' (invalid receive pattern of type {})",
                other.type_name()
            ))),
        }
    }

    /// Takes what this pattern asks for from `buf`, if it is all there. `closed`: no
    /// more bytes will come (then `All` takes everything).
    pub(crate) fn take(self, buf: &mut Vec<u8>, closed: bool) -> Option<Vec<u8>> {
        match self {
            Self::Line => {
                let end = buf.iter().position(|&b| b == b'\n')?;
                let mut line: Vec<u8> = buf.drain(..=end).collect();
                line.pop();
                // LuaSocket drops every CR of the line, not only a final one.
                line.retain(|&b| b != b'\r');
                Some(line)
            }
            Self::All => closed.then(|| std::mem::take(buf)),
            Self::Bytes(n) => (buf.len() >= n).then(|| buf.drain(..n).collect()),
        }
    }

    /// What a failed receive returns as its partial result: for a line, the CRs are
    /// dropped as they would have been.
    fn partial(self, buf: &mut Vec<u8>) -> Vec<u8> {
        let mut p = std::mem::take(buf);
        if self == Self::Line {
            p.retain(|&b| b != b'\r');
        }
        p
    }
}

/// Most bytes a connection buffers for one `receive`: a peer that sends a line without
/// end (or `"*a"` without closing) must not exhaust the memory the Lua cap does not
/// see. LuaSocket has no such limit; no script this exists for comes near it.
const MAX_BUFFERED: usize = 64 << 20;

/// Reads what is available now into `buf`: `Ok(true)` when the peer has closed.
fn fill(stream: &mut TcpStream, buf: &mut Vec<u8>) -> io::Result<bool> {
    let mut chunk = [0u8; 4096];
    loop {
        if buf.len() >= MAX_BUFFERED {
            return Err(io::Error::other(format!(
                "receive buffer full ({} MiB without the end of what was asked for)",
                MAX_BUFFERED >> 20
            )));
        }
        match stream.read(&mut chunk) {
            Ok(0) => return Ok(true),
            Ok(n) => buf.extend_from_slice(&chunk[..n]),
            Err(e) if e.kind() == io::ErrorKind::WouldBlock => return Ok(false),
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
}

/// A Lua string index (1-based, negative from the end) as a 0-based offset into `len`
/// bytes, clamped as `string.sub` clamps.
fn offset(i: i64, len: usize) -> usize {
    let len = len as i64;
    let i = if i < 0 { len + i + 1 } else { i };
    i.clamp(1, len + 1) as usize - 1
}

impl UserData for TcpObject {
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_meta_method("__tostring", |_, this, ()| {
            Ok(format!(
                "tcp{{{}}}: {:p}",
                this.0.borrow().kind_name(),
                Rc::as_ptr(&this.0)
            ))
        });

        // settimeout(value[, mode]): nil or negative blocks; both modes ('b', 't')
        // bound the whole call, which is what scripts that set one rely on.
        methods.add_method("settimeout", |_, this, (t, _mode): (Option<f64>, Option<String>)| {
            this.0.borrow_mut().timeout = match t {
                Some(s) if s >= 0.0 && s.is_finite() => Some(Duration::from_secs_f64(s)),
                _ => None,
            };
            one()
        });

        methods.add_method("close", |_, this, ()| {
            this.0.borrow_mut().close();
            one()
        });

        // setoption(name, value): the options scripts set on servers and clients are
        // accepted; only tcp-nodelay changes anything (std already sets SO_REUSEADDR on
        // listeners, and keepalive and linger do not matter for a loopback server).
        methods.add_method("setoption", |lua, this, (name, value): (String, LuaValue)| {
            match name.as_str() {
                "tcp-nodelay" => {
                    if let Kind::Client(s, _) = &this.0.borrow().kind {
                        let _ = s.set_nodelay(value.as_boolean().unwrap_or(false));
                    }
                    one()
                }
                "reuseaddr" | "reuseport" | "keepalive" | "linger" | "ipv6-v6only" => one(),
                other => fail(lua, &format!("unsupported option '{other}'")),
            }
        });

        methods.add_method("getsockname", |lua, this, ()| {
            let tcp = this.0.borrow();
            let a = match &tcp.kind {
                Kind::Master(Some(l)) | Kind::Server(l) => l.local_addr(),
                Kind::Client(s, _) => s.local_addr(),
                _ => return fail(lua, "not bound"),
            };
            match a {
                Ok(a) => address(lua, a),
                Err(e) => fail(lua, &error_text(&e)),
            }
        });

        methods.add_method("getpeername", |lua, this, ()| {
            let tcp = this.0.borrow();
            match &tcp.kind {
                Kind::Client(s, _) => match s.peer_addr() {
                    Ok(a) => address(lua, a),
                    Err(e) => fail(lua, &error_text(&e)),
                },
                _ => fail(lua, "not connected"),
            }
        });

        // bind(host, port): under the sandbox's rules (see `Sockets::listen_address`).
        methods.add_method("bind", |lua, this, (host, port): (String, u16)| {
            if !matches!(this.0.borrow().kind, Kind::Master(None)) {
                return Err(wrong_kind("bind", "master", &this.0.borrow()));
            }
            let sockets = state::<Sockets>(lua);
            let addr = match sockets.listen_address(&host, port) {
                Ok(a) => a,
                Err(e) => return fail(lua, &e.to_string()),
            };
            let listener = TcpListener::bind(addr).and_then(|l| l.set_nonblocking(true).map(|()| l));
            match listener {
                Ok(l) => {
                    let local = l.local_addr().unwrap_or(addr);
                    tracing::info!(
                        "script {} listens on {local} (LuaSocket)",
                        state::<Running>(lua).name.borrow()
                    );
                    this.0.borrow_mut().kind = Kind::Master(Some(l));
                    one()
                }
                Err(e) => fail(lua, &sockets.bind_error(addr, &e)),
            }
        });

        methods.add_method("listen", |_, this, _backlog: Option<i64>| {
            let mut tcp = this.0.borrow_mut();
            match std::mem::replace(&mut tcp.kind, Kind::Closed) {
                Kind::Master(Some(l)) => {
                    tcp.kind = Kind::Server(l);
                    one()
                }
                other => {
                    tcp.kind = other;
                    Err(wrong_kind("listen", "master (bound)", &tcp))
                }
            }
        });

        // connect(host, port): refused unless the user allowed outgoing connections.
        methods.add_method("connect", |lua, this, (host, port): (String, u16)| {
            if !matches!(this.0.borrow().kind, Kind::Master(None)) {
                return Err(wrong_kind("connect", "master", &this.0.borrow()));
            }
            let addr = match state::<Sockets>(lua).connect_address(&host, port) {
                Ok(a) => a,
                Err(e) => return fail(lua, &e.to_string()),
            };
            let limit = this.0.borrow().timeout.map_or(CONNECT_CAP, |t| t.min(CONNECT_CAP));
            let started = Instant::now();
            let stream = TcpStream::connect_timeout(&addr, limit.max(Duration::from_millis(1)))
                .and_then(|s| s.set_nonblocking(true).map(|()| s));
            // Waiting for the peer is not the script's computation (see `wait`).
            let running = state::<Running>(lua);
            running.deadline.set(running.deadline.get() + started.elapsed());
            match stream {
                Ok(s) => {
                    this.0.borrow_mut().kind = Kind::Client(s, Vec::new());
                    one()
                }
                Err(e) => fail(lua, &error_text(&e)),
            }
        });

        // accept(): the next client, waiting for one as the timeout allows.
        methods.add_method("accept", |lua, this, ()| {
            let (listener, timeout) = {
                let tcp = this.0.borrow();
                match &tcp.kind {
                    Kind::Server(l) => (l.try_clone().map_err(mlua::Error::external)?, tcp.timeout),
                    Kind::Closed => return fail(lua, "closed"),
                    _ => return Err(wrong_kind("accept", "server", &tcp)),
                }
            };
            match wait_for(lua, timeout, || not_yet(listener.accept())) {
                Ok(Waited::Ready((stream, _peer))) => {
                    stream.set_nonblocking(true).map_err(mlua::Error::external)?;
                    let client = TcpObject::open(lua, Kind::Client(stream, Vec::new()));
                    Ok(MultiValue::from_iter([LuaValue::UserData(
                        lua.create_userdata(client)?,
                    )]))
                }
                Ok(Waited::TimedOut) => fail(lua, "timeout"),
                Ok(Waited::Stopping(why)) => Err(stopping("accept", why)),
                Err(e) => fail(lua, &error_text(&e)),
            }
        });

        // receive([pattern[, prefix]]): see `Pattern`; on failure `nil, err, partial`.
        methods.add_method(
            "receive",
            |lua, this, (pattern, prefix): (LuaValue, Option<mlua::LuaString>)| {
                let pattern = Pattern::from_lua(&pattern)?;
                let mut tcp = this.0.borrow_mut();
                let timeout = tcp.timeout;
                let (stream, buf) = match &mut tcp.kind {
                    Kind::Client(s, b) => (s, b),
                    Kind::Closed => return fail(lua, "closed"),
                    _ => return Err(wrong_kind("receive", "client", &tcp)),
                };
                let mut closed = false;
                let got = wait_for(lua, timeout, || {
                    if let Some(out) = pattern.take(buf, closed) {
                        return Ok(Some(out));
                    }
                    closed = fill(stream, buf)?;
                    match pattern.take(buf, closed) {
                        Some(out) => Ok(Some(out)),
                        // Closed before the pattern was complete: `nil, "closed", partial`.
                        None if closed => Err(io::ErrorKind::UnexpectedEof.into()),
                        None => Ok(None),
                    }
                });
                let with_prefix = |data: &[u8]| -> mlua::Result<LuaValue> {
                    let mut out = prefix.as_ref().map(|p| p.as_bytes().to_vec()).unwrap_or_default();
                    out.extend_from_slice(data);
                    Ok(LuaValue::String(lua.create_string(&out)?))
                };
                let failed = |msg: &str, partial: Vec<u8>| -> mlua::Result<MultiValue> {
                    Ok(MultiValue::from_iter([
                        LuaValue::Nil,
                        LuaValue::String(lua.create_string(msg)?),
                        with_prefix(&partial)?,
                    ]))
                };
                match got {
                    Ok(Waited::Ready(data)) => Ok(MultiValue::from_iter([with_prefix(&data)?])),
                    Ok(Waited::TimedOut) => failed("timeout", pattern.partial(buf)),
                    Ok(Waited::Stopping(why)) => Err(stopping("receive", why)),
                    Err(e) => {
                        let partial = pattern.partial(buf);
                        // The peer is gone: the object is closed, as LuaSocket leaves it.
                        let msg = error_text(&e);
                        if msg == "closed" {
                            tcp.close();
                        }
                        failed(&msg, partial)
                    }
                }
            },
        );

        // send(data[, i[, j]]): the index of the last byte sent, or `nil, err, last`.
        methods.add_method(
            "send",
            |lua, this, (data, i, j): (mlua::LuaString, Option<i64>, Option<i64>)| {
                let bytes = data.as_bytes();
                let len = bytes.len();
                let from = offset(i.unwrap_or(1), len);
                let to = j.map_or(len, |j| offset(j, len) + 1).max(from).min(len);
                let mut tcp = this.0.borrow_mut();
                let timeout = tcp.timeout;
                let stream = match &mut tcp.kind {
                    Kind::Client(s, _) => s,
                    Kind::Closed => return fail(lua, "closed"),
                    _ => return Err(wrong_kind("send", "client", &tcp)),
                };
                let mut sent = from;
                let result = wait_for(lua, timeout, || {
                    while sent < to {
                        match stream.write(&bytes[sent..to]) {
                            Ok(0) => return Err(io::ErrorKind::WriteZero.into()),
                            Ok(n) => sent += n,
                            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                            Err(e) if e.kind() == io::ErrorKind::WouldBlock => return Ok(None),
                            Err(e) => return Err(e),
                        }
                    }
                    Ok(Some(()))
                });
                let last = LuaValue::Integer(sent as i64);
                let failed = |msg: &str| -> mlua::Result<MultiValue> {
                    Ok(MultiValue::from_iter([
                        LuaValue::Nil,
                        LuaValue::String(lua.create_string(msg)?),
                        last.clone(),
                    ]))
                };
                match result {
                    Ok(Waited::Ready(())) => Ok(MultiValue::from_iter([last.clone()])),
                    Ok(Waited::TimedOut) => failed("timeout"),
                    Ok(Waited::Stopping(why)) => Err(stopping("send", why)),
                    Err(e) => failed(&error_text(&e)),
                }
            },
        );

        methods.add_method("shutdown", |_, this, _how: Option<String>| {
            if let Kind::Client(s, _) = &this.0.borrow().kind {
                let _ = s.shutdown(std::net::Shutdown::Both);
            }
            one()
        });
    }
}
