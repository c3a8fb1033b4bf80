//! The legacy remote API transport: CoppeliaSim's `simx*` clients (`remoteApi.so` with
//! `sim.py` or `vrep.py`, and the MATLAB, Java and C bindings of the same library).
//!
//! Servers start from the command line (`--legacy-port`, as CoppeliaSim's continuous
//! server on 19997) or from scripts (`simRemoteApi.start`, through [`LegacyServers`]).
//! Each serves one client at a time, as CoppeliaSim's do. The client sends a message
//! every few milliseconds and waits for the answer; each message's commands run at once
//! on the simulation thread through the registry (see [`crate::legacy_commands`]), and
//! streaming commands run again with every later message until discontinued, so their
//! latest results are always in the client's inbox. Synchronous mode is the client's
//! stepping level (`simxSynchronous`), and `simxSynchronousTrigger` its `sim.step`.
//! The codec is `gantry_protocol::legacy_remote_api`.

use std::collections::HashMap;
use std::net::{IpAddr, SocketAddr};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use gantry_engine::ClientId;
use gantry_lua::{ListenerError, ListenerStatus, Listeners};
use gantry_protocol::legacy_remote_api::{
    self as wire, Command, LegacyError, MessageHeader, PacketReader, SplitAssembler, opmode,
};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::watch;

use crate::legacy_commands::{self, Session};
use crate::sim_thread::{Request, SimHandle};

/// Stepping client IDs of legacy connections, far from the ZMQ server's (which count
/// from 1), so the two never share a stepping level.
static NEXT_CLIENT: AtomicU64 = AtomicU64::new(1 << 40);

/// A client that sends nothing for this long is dropped (its library sends a message
/// every 5 ms while connected, empty when idle).
const IDLE_TIMEOUT: Duration = Duration::from_secs(60);

/// Most streaming commands one client may keep running.
const MAX_STREAMING: usize = 1024;

/// What a server shares with whoever asks for its status.
type SharedStatus = Arc<Mutex<ListenerStatus>>;

fn status_of(shared: &SharedStatus) -> ListenerStatus {
    shared
        .lock()
        .map(|s| s.clone())
        .unwrap_or_else(|p| p.into_inner().clone())
}

fn set_status(shared: &SharedStatus, f: impl FnOnce(&mut ListenerStatus)) {
    match shared.lock() {
        Ok(mut s) => f(&mut s),
        Err(p) => f(&mut p.into_inner()),
    }
}

fn new_status() -> SharedStatus {
    Arc::new(Mutex::new(ListenerStatus {
        connected: false,
        client_version: 0,
        client_ip: String::new(),
        server_version: wire::SERVER_VERSION,
    }))
}

async fn serve_with_status(
    listener: TcpListener,
    sim: SimHandle,
    mut stop: watch::Receiver<bool>,
    status: SharedStatus,
) {
    loop {
        let accepted = tokio::select! {
            _ = stop.changed() => return,
            a = listener.accept() => a,
        };
        let (sock, peer) = match accepted {
            Ok(a) => a,
            Err(e) => {
                tracing::warn!("legacy remote API: accept failed: {e}");
                tokio::time::sleep(Duration::from_millis(50)).await;
                continue;
            }
        };
        if *stop.borrow() {
            return;
        }
        let _ = sock.set_nodelay(true);
        tracing::info!("legacy remote API client connected from {peer}");
        set_status(&status, |s| {
            s.connected = true;
            s.client_ip = peer.ip().to_string();
        });
        let client = ClientId(NEXT_CLIENT.fetch_add(1, Ordering::Relaxed));
        let outcome = tokio::select! {
            _ = stop.changed() => Ok(()),
            r = connection(sock, &sim, client, &status) => r,
        };
        match outcome {
            Ok(()) => tracing::info!("legacy remote API client {peer} left"),
            Err(e) => tracing::warn!("legacy remote API client {peer} dropped: {e}"),
        }
        // Whatever it held (a stepping level in synchronous mode) is released.
        if sim.send(Request::DropClient(client)).is_err() {
            tracing::debug!("legacy remote API: could not release client {}", client.0);
        }
        set_status(&status, |s| {
            s.connected = false;
            s.client_version = 0;
            s.client_ip.clear();
        });
    }
}

/// Why a connection ended early.
#[derive(Debug, thiserror::Error)]
enum ConnectionError {
    #[error("{0}")]
    Io(#[from] std::io::Error),
    #[error("{0}")]
    Protocol(#[from] LegacyError),
    #[error("no message for {0:?}")]
    Idle(Duration),
    #[error("too many streaming commands (more than {MAX_STREAMING})")]
    TooManyStreams,
    #[error("reply of {0} bytes is too large to send")]
    ReplyTooLarge(usize),
}

/// A streaming command and when it last ran.
struct Stream {
    command: Command,
    last_run: Option<Instant>,
}

/// Forgets the stream of `cmd` (same code and identifying data), if there is one.
fn forget(streams: &mut Vec<Stream>, cmd: &Command) {
    streams.retain(|s| (s.command.code, &s.command.id) != (cmd.code, &cmd.id));
}

async fn connection(
    mut sock: TcpStream,
    sim: &SimHandle,
    client: ClientId,
    status: &SharedStatus,
) -> Result<(), ConnectionError> {
    let started = Instant::now();
    let mut reader = PacketReader::new();
    let mut splits = SplitAssembler::default();
    let mut streams: Vec<Stream> = Vec::new();
    let mut session = Session::new(client);
    let mut buf = vec![0u8; 64 * 1024];
    loop {
        let n = match tokio::time::timeout(IDLE_TIMEOUT, sock.read(&mut buf)).await {
            Err(_) => return Err(ConnectionError::Idle(IDLE_TIMEOUT)),
            Ok(r) => r?,
        };
        if n == 0 {
            return Ok(());
        }
        reader.feed(&buf[..n]);
        while let Some(bytes) = reader.next_message()? {
            let message = wire::decode_message(&bytes)?;
            set_status(status, |s| s.client_version = message.header.version);
            let mut requests = message.commands;
            for chunk in message.chunks {
                if let Some(whole) = splits.add(chunk)? {
                    requests.push(whole);
                }
            }
            let mut replies = Vec::new();
            let mut received = Vec::new();
            for cmd in requests {
                received.push((cmd.code, cmd.id.clone()));
                match cmd.opmode {
                    opmode::DISCONTINUE => {
                        forget(&mut streams, &cmd);
                        // Answered without running, as CoppeliaSim does; the client drops it.
                        replies.push(reply_to(&cmd, true, Vec::new(), 0));
                        continue;
                    }
                    opmode::STREAMING | opmode::STREAMING_SPLIT => {
                        forget(&mut streams, &cmd);
                        if streams.len() >= MAX_STREAMING {
                            return Err(ConnectionError::TooManyStreams);
                        }
                        streams.push(Stream {
                            command: cmd.clone(),
                            last_run: Some(Instant::now()),
                        });
                    }
                    _ => {}
                }
                let outcome = legacy_commands::execute(sim, &mut session, &cmd).await;
                if outcome.ends_stream {
                    forget(&mut streams, &cmd);
                }
                replies.push(reply_to(&cmd, outcome.ok, outcome.data, 0));
            }
            // Streaming commands run again, no more often than their delay asks.
            let now = Instant::now();
            let mut ended = Vec::new();
            for s in &mut streams {
                if received.contains(&(s.command.code, s.command.id.clone())) {
                    continue;
                }
                let delay = Duration::from_millis(u64::from(s.command.delay_or_split));
                if s.last_run.is_some_and(|t| now.duration_since(t) < delay) {
                    continue;
                }
                s.last_run = Some(now);
                let outcome = legacy_commands::execute(sim, &mut session, &s.command).await;
                if outcome.ends_stream {
                    ended.push((s.command.code, s.command.id.clone()));
                }
                replies.push(reply_to(&s.command, outcome.ok, outcome.data, 0));
            }
            streams.retain(|s| !ended.contains(&(s.command.code, s.command.id.clone())));
            let (state, time_ms) = session.clock(sim).await;
            for r in &mut replies {
                r.sim_time_ms = time_ms;
            }
            let header = MessageHeader {
                version: wire::SERVER_VERSION,
                message_id: message.header.message_id,
                client_time: message.header.client_time,
                server_time: started.elapsed().as_millis().min(i32::MAX as u128) as i32,
                scene_id: session.scene_id(),
                server_state: state,
            };
            let reply = wire::encode_message(&header, &replies);
            if reply.len() > wire::MAX_REPLY_LEN {
                return Err(ConnectionError::ReplyTooLarge(reply.len()));
            }
            sock.write_all(&wire::packetize(&reply)).await?;
            if session.killed() {
                return Ok(());
            }
        }
    }
}

fn reply_to(cmd: &Command, ok: bool, data: Vec<u8>, sim_time_ms: i32) -> Command {
    Command {
        code: cmd.code,
        opmode: cmd.opmode,
        delay_or_split: cmd.delay_or_split,
        id: cmd.id.clone(),
        data,
        status: u8::from(!ok),
        sim_time_ms,
    }
}

/// The legacy remote API servers scripts start and stop (`simRemoteApi`), and the
/// one `--legacy-port` starts. Lives in the transport layer; the Lua host sees it as
/// [`Listeners`].
pub struct LegacyServers {
    rt: tokio::runtime::Handle,
    bind: IpAddr,
    sim: SimHandle,
    /// Set when the whole run ends: every server stops.
    shutdown: watch::Receiver<bool>,
    servers: Mutex<HashMap<u16, Running>>,
}

struct Running {
    stop: watch::Sender<bool>,
    status: SharedStatus,
}

impl std::fmt::Debug for LegacyServers {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LegacyServers")
            .field("bind", &self.bind)
            .finish_non_exhaustive()
    }
}

impl LegacyServers {
    /// Servers on `bind`, run on `rt`, answering through `sim`, all ending when
    /// `shutdown` turns true.
    pub fn new(rt: tokio::runtime::Handle, bind: IpAddr, sim: SimHandle, shutdown: watch::Receiver<bool>) -> Self {
        Self {
            rt,
            bind,
            sim,
            shutdown,
            servers: Mutex::new(HashMap::new()),
        }
    }

    /// Starts a server on `port` (0: any free port) and returns where it listens.
    ///
    /// # Errors
    /// The port is in use, or a server of ours already runs there.
    pub fn start(&self, port: u16) -> Result<SocketAddr, ListenerError> {
        let mut servers = self.servers.lock().map_err(|_| ListenerError::Poisoned)?;
        servers.retain(|_, r| !r.stop.is_closed());
        if port != 0 && servers.contains_key(&port) {
            return Err(ListenerError::AlreadyRunning(port));
        }
        // Bound here, synchronously, so the script learns at once whether it worked.
        let refused = |source| ListenerError::Listen {
            address: format!("{}:{port}", self.bind),
            source,
        };
        let std_listener = std::net::TcpListener::bind(SocketAddr::new(self.bind, port)).map_err(refused)?;
        std_listener.set_nonblocking(true).map_err(refused)?;
        let local = std_listener.local_addr().map_err(refused)?;
        let (stop_tx, stop_rx) = watch::channel(false);
        let status = new_status();
        let sim = self.sim.clone();
        let mut shutdown = self.shutdown.clone();
        let task_status = status.clone();
        let _guard = self.rt.enter();
        let listener = TcpListener::from_std(std_listener).map_err(|source| ListenerError::Listen {
            address: local.to_string(),
            source,
        })?;
        self.rt.spawn(async move {
            tokio::select! {
                _ = serve_with_status(listener, sim, stop_rx, task_status) => {}
                _ = shutdown.changed() => {}
            }
        });
        tracing::info!("legacy remote API listening on {local}");
        servers.insert(local.port(), Running { stop: stop_tx, status });
        Ok(local)
    }
}

impl Listeners for LegacyServers {
    fn start_legacy(&self, port: u16) -> Result<(), ListenerError> {
        if port == 0 {
            return Err(ListenerError::PortZero);
        }
        self.start(port).map(|_| ())
    }

    fn stop_legacy(&self, port: u16) -> Result<(), ListenerError> {
        let mut servers = self.servers.lock().map_err(|_| ListenerError::Poisoned)?;
        match servers.remove(&port) {
            Some(r) => {
                let _ = r.stop.send(true);
                tracing::info!("legacy remote API on port {port} stopped");
                Ok(())
            }
            None => Err(ListenerError::NotRunning(port)),
        }
    }

    fn legacy_status(&self, port: u16) -> Option<ListenerStatus> {
        let servers = self.servers.lock().ok()?;
        servers.get(&port).map(|r| status_of(&r.status))
    }
}
