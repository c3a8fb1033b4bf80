//! CoppeliaSim's ZMQ remote API (protocol v2), so that programs written for
//! `coppeliasim-zmqremoteapi-client` drive gantry unmodified.
//!
//! One ROUTER socket serves every client. Clients use REQ sockets, so each has at most
//! one request in flight and every request gets exactly one reply, but with ROUTER a
//! reply may be deferred: a client parked in `sim.step()` waits for its reply while
//! the others are served. Each frame holds one CBOR map; the codec lives in
//! [`gantry_protocol::remote_api`] and this module only moves bytes and keeps sessions.
//! The socket is gantry's own ([`crate::zmtp_conn`], over the pure ZMTP codec in
//! [`gantry_protocol::zmtp`]): one task per connection parses the framing once, within
//! size limits, and hands each request to `Server::dispatch` under a short lock.
//! Answers from the simulation thread are written to the client's socket by the
//! simulation thread itself, the moment it sends them ([`crate::zmtp_reply`]), so a
//! call costs no thread wake-up on the way back and nothing polls.
//!
//! What is served where:
//! * `zmqRemoteApi.require` / `zmqRemoteApi.info` for `sim`: here. INFO is generated
//!   from [`api::FUNCTIONS`], [`api::CONSTANTS`] and the functions listed in
//!   the registry's host functions ([`api::HOST_FUNCTIONS`]), so a function exists remotely
//!   exactly when it is implemented.
//! * `sim.setStepping`, `sim.step`, `sim.start/pause/stopSimulation`,
//!   `sim.acquireLock`/`sim.releaseLock`: they concern clients and the simulation loop,
//!   so they go to the simulation thread as [`Request::Remote`] and [`Request::Step`].
//! * Every other `sim.*` function: [`Request::Call`] with the resolved [`Target`], i.e. `Engine::serve(Input::Call)`, the one
//!   implementation shared with Lua scripts.
//! * Control words: `_*executed*_` (the client's answer to `_*wait*_`) and `_*end*_`.
//!
//! Sessions are keyed by the client's `uuid`. A session is dropped on `_*end*_`, when
//! the last connection that spoke for it closes, or after the client's `timeout`
//! (seconds, sent with its first message; 600 by default) without a message, and its
//! stepping level and locks go with it. So a stepping client stopped with Ctrl-C (or
//! killed) releases the simulation at once, where CoppeliaSim holds it until the
//! timeout; one that hangs without closing its socket holds it until its timeout.
//!
//! Every malformed message gets an `{"err": ...}` reply and touches nothing else.
//! * Blocking calls (`sim.wait`, `sim.waitForSignal`, `sim.moveToConfig`,
//!   `sim.moveToPose`): [`Request::Blocking`], answered when the call returns, steps
//!   later; the client's REQ socket simply waits, as ROUTER lets a reply be deferred.
//!   `sim.wait(dt, false)` (wall-clock time) is served here, without the simulation.
//!
//! Non-goals: callbacks into the client (`...@func` arguments are passed through as
//! strings), `eval`, and protocol v1 (answered with the real server's mismatch error).

use std::collections::HashMap;
use std::net::SocketAddr;
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

use bytes::Bytes;
use gantry_protocol::remote_api::{
    FUNC_END, FUNC_EXECUTED, decode_request, encode_empty_map, encode_err, encode_ret, encode_wait,
};
use gantry_protocol::{Value, cbor};
use gantry_sim_core::api::{self, CallError, Target};
use tokio::sync::{oneshot, watch};

use gantry_engine::{ClientId, HostCall};

use crate::sim_thread::{Request, SimHandle};
use crate::zmtp_conn::{self, Peer};
use crate::zmtp_reply::ReplyHandle;

/// The text the real server sends to clients that do not send a `uuid` (protocol v1).
const VERSION_MISMATCH: &str = "The client ZeroMQ remote API version does not match CoppeliaSim's version";

/// Longest accepted `uuid` (the Python client sends 36 characters). Keys of the session
/// table come from peers, so their size is bounded like everything else they send.
const MAX_UUID_LEN: usize = 128;

/// Limits and timeouts of the ZMQ listener.
#[derive(Debug, Clone)]
pub struct ZmqConfig {
    /// Most sessions at once; a new client beyond this gets an error until an idle
    /// session times out or a client sends `_*end*_`.
    pub max_clients: usize,
    /// Idle time after which a client that sent no `timeout` is forgotten (the
    /// client's default, 600 s).
    pub default_timeout: Duration,
    /// How often idle sessions are looked for.
    pub sweep_interval: Duration,
    /// Most open connections; one more is closed as soon as it is accepted. Each costs
    /// a task and its buffers whether or not it speaks for a session.
    pub max_connections: usize,
}

impl Default for ZmqConfig {
    fn default() -> Self {
        Self {
            max_clients: 1024,
            default_timeout: Duration::from_secs(600),
            sweep_interval: Duration::from_secs(1),
            max_connections: 4096,
        }
    }
}

/// The ZMQ remote API's listener, bound and not yet serving.
pub struct Listener {
    listener: tokio::net::TcpListener,
}

/// Binds the remote API on `addr` (port 0 picks a free port) and returns it with the
/// address actually bound.
///
/// # Errors
/// The OS refused the address (in use, not local, no permission).
pub async fn bind(addr: SocketAddr) -> std::io::Result<(Listener, SocketAddr)> {
    let listener = tokio::net::TcpListener::bind(addr).await?;
    let local = listener.local_addr()?;
    Ok((Listener { listener }, local))
}

/// Serves remote API clients on `listener` until `shutdown` turns true.
pub async fn serve(listener: Listener, sim: SimHandle, cfg: ZmqConfig, mut shutdown: watch::Receiver<bool>) {
    let mut sweep = tokio::time::interval(cfg.sweep_interval);
    sweep.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    let max_connections = cfg.max_connections;
    let router = Arc::new(Sessions(Mutex::new(Server::new(sim, cfg))));
    let accept = zmtp_conn::serve(listener.listener, router.clone(), max_connections, shutdown.clone());
    tokio::pin!(accept);
    loop {
        tokio::select! {
            _ = shutdown.changed() => break,
            () = &mut accept => break,
            _ = sweep.tick() => router.lock().evict_idle(Instant::now()),
        }
    }
}

/// The [`Server`] behind the socket: every connection's task locks it to dispatch a
/// request, which never waits on anything (the simulation thread's answers arrive on
/// channels, after the lock is released), so the lock is only ever held briefly.
struct Sessions(Mutex<Server>);

impl Sessions {
    fn lock(&self) -> std::sync::MutexGuard<'_, Server> {
        // A panic in dispatch would leave at worst a stale session entry.
        self.0.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

impl zmtp_conn::Router for Sessions {
    /// One request: `[delimiter, payload]` from a REQ client (any frames before the
    /// payload are its envelope, echoed in front of the reply).
    fn message(&self, peer: &Peer, mut frames: Vec<Bytes>) {
        let Some(payload) = frames.pop() else { return };
        // The routing id first, as a ROUTER socket receives it: `dispatch` keys the
        // connection's session by it, and a parked step routes its reply by it.
        let mut envelope = Vec::with_capacity(frames.len() + 1);
        envelope.push(peer.id.clone());
        envelope.extend(frames);
        let outcome = self.lock().dispatch(&payload, &envelope);
        let reply_envelope = envelope.split_off(1);
        match outcome {
            Outcome::Reply(bytes) => peer.out.reply(&reply_envelope, &bytes),
            // Written from the simulation thread as it answers (see crate::zmtp_reply).
            Outcome::Await(rx) => drop(peer.out.reply_when_ready(reply_envelope, rx, encode_answer)),
            Outcome::Deferred => {}
        }
    }

    fn connected(&self, peer: &Peer) {
        self.lock().routes.insert(peer.id.clone(), peer.out.clone());
    }

    fn disconnected(&self, peer: &Peer) {
        let mut server = self.lock();
        server.routes.remove(&peer.id);
        server.disconnected(&peer.id);
    }
}

/// `sim.wait(dt, false)`: a wait in wall-clock time, which concerns neither the
/// simulation nor its thread (CoppeliaSim's examples call it with the simulation
/// stopped): answered after `dt` seconds with the overshoot (<= 0), as `sim.wait` is.
fn wall_clock_wait(args: &[Value]) -> Outcome {
    let dt = match args.first().and_then(Value::as_f64) {
        Some(dt) if dt.is_finite() => dt.clamp(0.0, 86_400.0),
        _ => return Outcome::Reply(encode_err("argument 1: expected number (in function 'sim.wait')")),
    };
    let (reply, rx) = oneshot::channel();
    let start = Instant::now();
    tokio::spawn(async move {
        tokio::time::sleep(Duration::from_secs_f64(dt)).await;
        let overshoot = dt - start.elapsed().as_secs_f64();
        let _ = reply.send(Ok(vec![Value::Float(overshoot.min(0.0))]));
    });
    Outcome::Await(rx)
}

/// The reply to a call: its results, its error, or the end of the simulation (the
/// answer's sender was dropped).
fn encode_answer(answer: Option<Result<Vec<Value>, CallError>>) -> Vec<u8> {
    match answer {
        Some(Ok(values)) => encode_ret(&values),
        Some(Err(e)) => encode_err(&e.to_string()),
        None => encode_err("the simulation has ended"),
    }
}

/// The reply to `_*executed*_` once the step is done (or will never be: the channel
/// closed because the simulation ended or dropped the client).
fn encode_step_done(_: Option<()>) -> Vec<u8> {
    encode_ret(&[])
}

/// One client's session.
struct Session {
    /// The simulation thread's name for this client.
    id: ClientId,
    last_seen: Instant,
    /// Idle time after which the session is dropped.
    timeout: Duration,
    /// Completion of a `sim.step()` answered with `_*wait*_` and not yet acknowledged
    /// with `_*executed*_`.
    pending_step: Option<oneshot::Receiver<()>>,
    /// The reply to `_*executed*_`, held back until the step is done; the session is
    /// not idle while it waits.
    parked: Option<ReplyHandle>,
}

impl Session {
    fn is_parked(&self) -> bool {
        self.parked.as_ref().is_some_and(|p| !p.is_finished())
    }
}

/// What to do with a request.
enum Outcome {
    /// Reply now with these bytes.
    Reply(Vec<u8>),
    /// Reply with the simulation thread's answer.
    Await(oneshot::Receiver<Result<Vec<Value>, CallError>>),
    /// A parked step replies later (see `Server::executed`).
    Deferred,
}

struct Server {
    sim: SimHandle,
    cfg: ZmqConfig,
    /// Where to send a deferred reply: each connection's write side by routing id,
    /// from its handshake until it closes.
    routes: HashMap<Bytes, Arc<crate::zmtp_reply::Outgoing>>,
    sessions: HashMap<String, Session>,
    next_id: u64,
    /// `{"ret": [INFO]}` for `sim`, encoded once: it is the same for every client.
    /// Encoded INFO replies by module name.
    infos: std::collections::HashMap<&'static str, Bytes>,
    /// Clients to forget whose `DropClient` found the simulation queue full; retried
    /// on the next sweep so that no stepping level is leaked.
    pending_drops: Vec<ClientId>,
    /// The session each open connection (by its routing identity) last spoke for.
    /// The asyncio client speaks for one session over several connections.
    connections: HashMap<Bytes, String>,
}

impl Server {
    fn new(sim: SimHandle, cfg: ZmqConfig) -> Self {
        Self {
            sim,
            cfg,
            routes: HashMap::new(),
            sessions: HashMap::new(),
            next_id: 0,
            infos: api::MODULES
                .iter()
                .map(|m| (m.name, Bytes::from(encode_ret(&[module_info(m)]))))
                .collect(),
            pending_drops: Vec::new(),
            connections: HashMap::new(),
        }
    }

    fn dispatch(&mut self, payload: &[u8], envelope: &[Bytes]) -> Outcome {
        let req = match decode_request(payload) {
            Ok(r) => r,
            Err(e) => return Outcome::Reply(encode_err(&e.to_string())),
        };
        let Some(uuid) = req.uuid else {
            // What the real server answers a v1 client; a v2 client would see `err`.
            let text = Value::from(VERSION_MISMATCH);
            return Outcome::Reply(cbor::to_vec(&Value::Map(vec![
                ("success".into(), Value::Bool(false)),
                ("error".into(), text.clone()),
                ("err".into(), text),
            ])));
        };
        if uuid.len() > MAX_UUID_LEN {
            return Outcome::Reply(encode_err(&format!(
                "\"uuid\" is longer than {MAX_UUID_LEN} characters"
            )));
        }
        if req.func == FUNC_END {
            self.forget(&uuid);
            return Outcome::Reply(encode_empty_map());
        }
        if let Some(peer) = envelope.first()
            && self.connections.get(peer) != Some(&uuid)
        {
            self.connections.insert(peer.clone(), uuid.clone());
        }
        let now = Instant::now();
        let Some(session) = self.session(&uuid, now) else {
            return Outcome::Reply(encode_err(&format!(
                "too many remote API clients ({}); end one (or wait for an idle one to time out) and retry",
                self.cfg.max_clients
            )));
        };
        session.last_seen = now;
        if let Some(t) = req.timeout.filter(|t| !t.is_nan()) {
            // Bounded (and NaN ignored) so no peer value can make Duration panic.
            session.timeout = Duration::from_secs_f64(t.clamp(1.0, 30.0 * 86_400.0));
        }
        let client = session.id;
        match req.func.as_str() {
            FUNC_EXECUTED => self.executed(&uuid, envelope),
            "zmqRemoteApi.require" => Outcome::Reply(match module_name(&req.args) {
                Some(m) if self.infos.contains_key(m) => encode_ret(&[]),
                other => encode_err(&no_module(other)),
            }),
            "zmqRemoteApi.info" => Outcome::Reply(match module_name(&req.args).and_then(|m| self.infos.get(m)) {
                Some(info) => info.to_vec(),
                None => encode_err(&no_module(module_name(&req.args))),
            }),
            // The edge: the name becomes a typed target here, once.
            func => match func.contains('.').then(|| Target::resolve(func)).flatten() {
                Some(target) => self.function(client, &uuid, target, req.args),
                None => Outcome::Reply(encode_err(&CallError::NoSuchFunction(func.to_owned()).to_string())),
            },
        }
    }

    /// The session of `uuid`, created on first sight; `None` when the table is full
    /// even after dropping idle sessions.
    fn session(&mut self, uuid: &str, now: Instant) -> Option<&mut Session> {
        if !self.sessions.contains_key(uuid) {
            if self.sessions.len() >= self.cfg.max_clients {
                self.evict_idle(now);
                if self.sessions.len() >= self.cfg.max_clients {
                    return None;
                }
            }
            self.next_id += 1;
            let session = Session {
                id: ClientId(self.next_id),
                last_seen: now,
                timeout: self.cfg.default_timeout,
                pending_step: None,
                parked: None,
            };
            self.sessions.insert(uuid.to_owned(), session);
        }
        self.sessions.get_mut(uuid)
    }

    fn function(&mut self, client: ClientId, uuid: &str, target: Target, args: Vec<Value>) -> Outcome {
        let (reply, rx) = oneshot::channel();
        let request = match target {
            Target::FrontEnd(f) => match HostCall::parse(f, &args) {
                Ok(HostCall::Remote(op)) => Request::Remote { client, op, reply },
                Ok(HostCall::Step { wait }) => return self.step(client, uuid, wait),
                Ok(HostCall::LoadScene(path)) => Request::LoadScene { path, reply },
                Err(e) => return Outcome::Reply(encode_err(&e.to_string())),
            },
            Target::ScriptHost(f) if f.blocks() => {
                if f == api::ScriptHostFn::Wait && args.get(1) == Some(&Value::Bool(false)) {
                    return wall_clock_wait(&args);
                }
                Request::Blocking { client, f, args, reply }
            }
            target => Request::Call { target, args, reply },
        };
        if let Err(e) = self.sim.send(request) {
            return Outcome::Reply(encode_err(&format!("{e} (in function '{}')", target.qualified())));
        }
        Outcome::Await(rx)
    }

    /// `sim.step()`: ask the simulation thread for the next step and park the client
    /// with `_*wait*_`; the real reply goes to its `_*executed*_`. With `wait` false the
    /// step is only requested.
    fn step(&mut self, client: ClientId, uuid: &str, wait: bool) -> Outcome {
        let (done, rx) = oneshot::channel();
        if let Err(e) = self.sim.send(Request::Step { client, done }) {
            return Outcome::Reply(encode_err(&format!("{e} (in function 'sim.step')")));
        }
        if !wait {
            return Outcome::Reply(encode_ret(&[]));
        }
        if let Some(s) = self.sessions.get_mut(uuid) {
            s.pending_step = Some(rx);
        }
        Outcome::Reply(encode_wait())
    }

    /// `_*executed*_`: the client acknowledged a `_*wait*_`. Reply once its step is done.
    /// `envelope` is the routing id of the connection it came on, then the frames to
    /// echo in front of the reply.
    fn executed(&mut self, uuid: &str, envelope: &[Bytes]) -> Outcome {
        let Some(session) = self.sessions.get_mut(uuid) else {
            return Outcome::Reply(encode_err("unexpected _*executed*_: no call is waiting for it"));
        };
        let Some(mut pending) = session.pending_step.take() else {
            return Outcome::Reply(encode_err("unexpected _*executed*_: no call is waiting for it"));
        };
        // The common case when stepping fast: the step is already done.
        match pending.try_recv() {
            Ok(()) | Err(oneshot::error::TryRecvError::Closed) => return Outcome::Reply(encode_ret(&[])),
            Err(oneshot::error::TryRecvError::Empty) => {}
        }
        let Some((out, echo)) = envelope
            .split_first()
            .and_then(|(id, echo)| Some((self.routes.get(id)?, echo)))
        else {
            // Cannot happen: a connection's route lives from its READY until its task
            // ends, and that task is the one dispatching its requests.
            return Outcome::Deferred;
        };
        // Written by the simulation thread when it finishes the step.
        session.parked = Some(out.reply_when_ready(echo.to_vec(), pending, encode_step_done));
        Outcome::Deferred
    }

    /// Drops sessions idle past their timeout (never one parked in `sim.step`).
    fn evict_idle(&mut self, now: Instant) {
        let idle: Vec<String> = self
            .sessions
            .iter()
            .filter(|(_, s)| !s.is_parked() && now.saturating_duration_since(s.last_seen) > s.timeout)
            .map(|(k, _)| k.clone())
            .collect();
        for uuid in idle {
            tracing::info!("zmq remote API: client {uuid} idle past its timeout; its state is dropped");
            self.forget(&uuid);
        }
        self.pending_drops
            .retain(|&id| self.sim.send(Request::DropClient(id)).is_err());
    }

    /// A connection closed: the session it spoke for ends if no other connection
    /// speaks for it (the client process is gone, for instance stopped with Ctrl-C).
    fn disconnected(&mut self, peer: &Bytes) {
        let Some(uuid) = self.connections.remove(peer) else {
            return;
        };
        if self.connections.values().any(|u| *u == uuid) || !self.sessions.contains_key(&uuid) {
            return;
        }
        tracing::info!("zmq remote API: client {uuid} disconnected; its stepping level and locks are released");
        self.forget(&uuid);
    }

    /// Forgets a session here and on the simulation thread.
    fn forget(&mut self, uuid: &str) {
        self.connections.retain(|_, u| u != uuid);
        if let Some(s) = self.sessions.remove(uuid) {
            if let Some(p) = s.parked {
                p.abort();
            }
            if self.sim.send(Request::DropClient(s.id)).is_err() {
                self.pending_drops.push(s.id);
            }
        }
    }
}

fn module_name(args: &[Value]) -> Option<&str> {
    args.first().and_then(Value::as_str)
}

/// The error for a module gantry does not have (`require`), or a missing module name.
pub fn no_module(name: Option<&str>) -> String {
    match name {
        Some(n) => {
            let names: Vec<&str> = api::MODULES.iter().map(|m| m.name).collect();
            format!("module '{n}' is not available in gantry (it has {})", names.join(", "))
        }
        None => "argument 1: expected the module name as a string (in function 'zmqRemoteApi.require')".into(),
    }
}

/// INFO for `sim`: `{"name": {"func": {}}, ..., "handle_world": {"const": -1}, ...}`.
pub fn sim_info() -> Value {
    module_info(api::module("sim").expect("the API always has a sim module"))
}

/// INFO for one module of [`api::MODULES`], generated from the shared implementation;
/// `sim` also lists the functions the Lua host and this transport add.
pub fn module_info(module: &api::Module) -> Value {
    let func = || Value::Map(vec![("func".into(), Value::Map(Vec::new()))]);
    let extra: Vec<&str> = if module.name == "sim" {
        api::host::remote_names().collect()
    } else {
        Vec::new()
    };
    let names = module.callable().map(|(name, _)| name).chain(extra);
    let mut pairs: Vec<(Value, Value)> = names.map(|n| (n.into(), func())).collect();
    let constant = |v: i64| Value::Map(vec![("const".into(), Value::Int(v))]);
    for (name, v) in module.constants.iter() {
        // `simOMPL.StateSpaceType.pose3d`: a dotted name is a member of a nested map,
        // which the client turns into a nested namespace.
        match name.split_once('.') {
            None => pairs.push(((*name).into(), constant(*v))),
            Some((group, member)) => {
                let at = match pairs.iter().position(|(k, _)| k.as_str() == Some(group)) {
                    Some(i) => i,
                    None => {
                        pairs.push((group.into(), Value::Map(Vec::new())));
                        pairs.len() - 1
                    }
                };
                if let Value::Map(inner) = &mut pairs[at].1 {
                    inner.push((member.into(), constant(*v)));
                }
            }
        }
    }
    Value::Map(pairs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn info_lists_core_host_and_constant_members_once() {
        let info = sim_info();
        let Value::Map(pairs) = &info else {
            panic!("INFO is a map")
        };
        let mut names: Vec<&str> = pairs.iter().filter_map(|(k, _)| k.as_str()).collect();
        let n = names.len();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), n, "no member is listed twice");
        for f in [
            "getObject",
            "setStepping",
            "step",
            "callScriptFunction",
            "getSimulationState",
        ] {
            assert_eq!(
                info.get(f),
                Some(&Value::Map(vec![("func".into(), Value::Map(vec![]))])),
                "{f}"
            );
        }
        assert_eq!(
            info.get("handle_world"),
            Some(&Value::Map(vec![("const".into(), Value::Int(-1))]))
        );
    }

    #[test]
    fn info_lists_exactly_the_names_that_resolve() {
        for m in api::MODULES {
            let Value::Map(pairs) = module_info(m) else {
                panic!("INFO is a map")
            };
            for (k, v) in &pairs {
                let name = k.as_str().expect("string keys");
                let is_function = v.get("func").is_some();
                let resolves = Target::resolve(&format!("{}.{name}", m.name)).is_some();
                assert_eq!(is_function, resolves, "{}.{name}", m.name);
            }
        }
    }
}
