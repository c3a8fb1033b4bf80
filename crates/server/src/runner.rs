//! Wiring: bind the listeners, start the simulation thread, shut everything down
//! together on Ctrl-C, SIGTERM or the end of the run.

use std::net::{IpAddr, Ipv4Addr, Ipv6Addr, SocketAddr};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use gantry_sim_core::scene::SceneModel;
use tokio::net::TcpListener;
use tokio::sync::watch;

use crate::auth::AccessToken;
use crate::http::HttpConfig;
use crate::sim_thread::{RunSummary, SimConfig, SimHandle, channel, run_sim_thread_debugged};

/// Which listeners to open. A port of `None` disables that listener; `Some(0)` lets
/// the OS pick a free port (the bound address is logged).
#[derive(Debug, Clone)]
pub struct ServeConfig {
    /// Address every listener binds (default 127.0.0.1).
    pub bind: IpAddr,
    /// Text command channel.
    pub text_port: Option<u16>,
    /// ZMQ remote API.
    pub zmq_port: Option<u16>,
    /// A legacy remote API server (`simx*` clients) from the start, as CoppeliaSim's
    /// continuous server on 19997; scripts may start more (`simRemoteApi.start`).
    pub legacy_port: Option<u16>,
    /// Browser viewer (HTTP and WebSocket).
    pub http_port: Option<u16>,
    /// The script debugger's Debug Adapter Protocol listener (`--debug`); `None`: no
    /// debugger at all (nothing is installed in the Lua host).
    pub dap_port: Option<u16>,
    /// Limits of the text channel.
    pub text: crate::text::TextConfig,
    /// Limits of the viewer.
    pub http: HttpConfig,
    /// Access token required by the text channel and the viewer; `None` leaves them
    /// open (fine on loopback). The ZMQ remote API cannot check it (CoppeliaSim's
    /// protocol has no authentication), so with a token and a non-loopback `bind` it
    /// stays on loopback unless `expose_zmq`.
    pub token: Option<AccessToken>,
    /// With a token and a non-loopback `bind`, bind the unauthenticated ZMQ remote API
    /// on `bind` anyway instead of loopback.
    pub expose_zmq: bool,
}

impl Default for ServeConfig {
    fn default() -> Self {
        Self {
            bind: IpAddr::V4(Ipv4Addr::LOCALHOST),
            text_port: None,
            zmq_port: None,
            legacy_port: None,
            http_port: None,
            dap_port: None,
            text: crate::text::TextConfig::default(),
            http: HttpConfig::default(),
            token: None,
            expose_zmq: false,
        }
    }
}

/// Why a run could not start or finish.
#[derive(Debug, thiserror::Error)]
pub enum ServerError {
    /// A listener could not bind.
    #[error("cannot listen on {addr}: {source} (is another gantry running? choose another port, or 0 for any)")]
    Bind {
        /// The address.
        addr: SocketAddr,
        /// The OS error.
        source: std::io::Error,
    },
    /// The async runtime could not start.
    #[error("cannot start the network runtime: {0}")]
    Runtime(std::io::Error),
    /// The simulation could not be created.
    #[error(transparent)]
    Script(#[from] gantry_lua::ScriptError),
    /// The simulation thread panicked.
    #[error("the simulation thread panicked: {0}")]
    Panic(String),
    /// The recording (`--record`) could not start.
    #[error(transparent)]
    Record(#[from] gantry_record::RecordError),
}

/// Shared shutdown flag: set by signals or by the caller.
#[derive(Clone, Default)]
pub struct Shutdown(Arc<AtomicBool>);

impl Shutdown {
    /// Asks everything to stop.
    pub fn trigger(&self) {
        self.0.store(true, Ordering::SeqCst);
    }
    /// Whether a stop was asked for.
    pub fn is_triggered(&self) -> bool {
        self.0.load(Ordering::SeqCst)
    }
}

/// Addresses the listeners bound, reported through `on_ready`.
#[derive(Debug, Clone, Default)]
pub struct BoundAddrs {
    /// Text channel.
    pub text: Option<SocketAddr>,
    /// ZMQ remote API.
    pub zmq: Option<SocketAddr>,
    /// The legacy remote API server of `--legacy-port`.
    pub legacy: Option<SocketAddr>,
    /// Browser viewer: open `http://ADDR/`.
    pub http: Option<SocketAddr>,
    /// The debugger's DAP listener.
    pub dap: Option<SocketAddr>,
}

/// Runs a scene with its listeners until the run ends or `shutdown` triggers (Ctrl-C
/// and SIGTERM trigger it too). Returns the run summary after cleanup hooks ran and
/// every socket closed.
///
/// # Errors
/// A listener could not bind, or the simulation could not start.
pub fn run(
    model: SceneModel,
    sim: SimConfig,
    serve: ServeConfig,
    shutdown: Shutdown,
    on_ready: impl FnOnce(&BoundAddrs),
) -> Result<RunSummary, ServerError> {
    let running = start(model, sim, serve, shutdown, Signals::Catch)?;
    on_ready(running.bound());
    running.wait()
}

/// Whether [`start`] takes over Ctrl-C and SIGTERM.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Signals {
    /// The first signal stops the run cleanly, a second exits at once: the binary.
    Catch,
    /// Leave signals to the host process (Python keeps its KeyboardInterrupt).
    Leave,
}

/// A scene running on its simulation thread with its listeners, started by [`start`].
pub struct Running {
    rt: tokio::runtime::Runtime,
    handle: SimHandle,
    bound: BoundAddrs,
    sim_thread: std::thread::JoinHandle<Result<RunSummary, gantry_lua::ScriptError>>,
    stop_tx: watch::Sender<bool>,
    shutdown: Shutdown,
}

impl Running {
    /// The addresses the listeners bound.
    pub fn bound(&self) -> &BoundAddrs {
        &self.bound
    }

    /// A handle for sending requests to the simulation thread, as the transports do.
    pub fn handle(&self) -> SimHandle {
        self.handle.clone()
    }

    /// Asks the run to end (cleanup hooks run on the simulation thread).
    pub fn stop(&self) {
        self.shutdown.trigger();
    }

    /// Waits for the run to end, then closes every listener. The run ends when the
    /// step count is reached, `shutdown` triggers, or no request handle is left.
    ///
    /// # Errors
    /// The simulation could not be created, or its thread panicked.
    pub fn wait(self) -> Result<RunSummary, ServerError> {
        let Running {
            rt,
            handle,
            sim_thread,
            stop_tx,
            ..
        } = self;
        drop(handle);
        let result = sim_thread.join().map_err(|p| {
            ServerError::Panic(
                p.downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| (*s).to_owned()))
                    .unwrap_or_default(),
            )
        })?;
        let _ = stop_tx.send(true);
        rt.shutdown_timeout(std::time::Duration::from_secs(2));
        Ok(result?)
    }
}

/// Binds the listeners and starts the simulation thread, without waiting for the run
/// to end (see [`Running::wait`]). The binary uses it through [`run`]; the Python
/// package uses it to let a viewer, text or ZMQ clients watch a run it drives.
///
/// # Errors
/// A listener could not bind, or the runtime or thread could not start.
pub fn start(
    model: SceneModel,
    mut sim: SimConfig,
    serve: ServeConfig,
    shutdown: Shutdown,
    signals: Signals,
) -> Result<Running, ServerError> {
    // First, so that a file that cannot be written fails the run before it starts.
    let recorder = sim.record.take().map(gantry_record::Recorder::create).transpose()?;
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(ServerError::Runtime)?;
    let (handle, rx) = channel();
    // A stop or a new scene asked for while a script waits in a LuaSocket call ends
    // the wait, so the request is served.
    let interrupt = Arc::new(AtomicBool::new(false));
    let handle = handle.interrupting(interrupt.clone());
    sim.limits.network.interrupt = Some(interrupt);
    let (stop_tx, stop_rx) = watch::channel(false);
    let (debug_hub, debug_link) = match serve.dap_port {
        Some(_) => {
            // A stopped script resumes when the process is asked to stop.
            let (hub, link) = crate::debug::DebugHub::new(handle.clone(), shutdown.0.clone());
            (Some(hub), Some(link))
        }
        None => (None, None),
    };

    // Legacy remote API servers, started by --legacy-port or by scripts; unauthenticated
    // like the ZMQ remote API, so they follow its address.
    let legacy = Arc::new(crate::legacy::LegacyServers::new(
        rt.handle().clone(),
        zmq_ip(&serve),
        handle.clone(),
        stop_rx.clone(),
    ));
    sim.listeners = Some(legacy.clone());

    // The viewer's pose stream: published by the simulation thread, only when a page
    // is connected.
    let bound = rt.block_on(async {
        let mut bound = BoundAddrs::default();
        if let Some(port) = serve.text_port {
            let addr = SocketAddr::new(serve.bind, port);
            let listener = TcpListener::bind(addr)
                .await
                .map_err(|source| ServerError::Bind { addr, source })?;
            let local = listener
                .local_addr()
                .map_err(|source| ServerError::Bind { addr, source })?;
            tracing::info!("text command channel listening on {local}");
            bound.text = Some(local);
            tokio::spawn(crate::text::serve(
                listener,
                handle.clone(),
                serve.text.clone(),
                serve.token.clone(),
                stop_rx.clone(),
            ));
        }
        if let Some(port) = serve.zmq_port {
            let addr = SocketAddr::new(zmq_ip(&serve), port);
            let (listener, local) = crate::zmq::bind(addr)
                .await
                .map_err(|source| ServerError::Bind { addr, source })?;
            tracing::info!("ZMQ remote API listening on {local}");
            bound.zmq = Some(local);
            tokio::spawn(crate::zmq::serve(
                listener,
                handle.clone(),
                crate::zmq::ZmqConfig::default(),
                stop_rx.clone(),
            ));
        }
        if let Some(port) = serve.legacy_port {
            let addr = SocketAddr::new(zmq_ip(&serve), port);
            let local = legacy.start(port).map_err(|e| ServerError::Bind {
                addr,
                source: std::io::Error::other(e),
            })?;
            bound.legacy = Some(local);
        }
        if let (Some(port), Some(hub)) = (serve.dap_port, &debug_hub) {
            // Always loopback: the debugger runs code in the scripts (evaluate), so it is
            // never exposed with --bind.
            let addr = SocketAddr::new(loopback_of(serve.bind), port);
            let listener = TcpListener::bind(addr)
                .await
                .map_err(|source| ServerError::Bind { addr, source })?;
            let local = listener
                .local_addr()
                .map_err(|source| ServerError::Bind { addr, source })?;
            tracing::info!("script debugger (DAP) listening on {local}");
            bound.dap = Some(local);
            tokio::spawn(crate::dap::serve(listener, hub.clone(), stop_rx.clone()));
        }
        if let Some(port) = serve.http_port {
            let addr = SocketAddr::new(serve.bind, port);
            let listener = match TcpListener::bind(addr).await {
                Ok(l) => l,
                Err(source) if serve.http.optional => {
                    tracing::warn!(
                        "no browser viewer: cannot listen on {addr}: {source} (pass --http-port P, or 0 for any free port)"
                    );
                    return Ok(bound);
                }
                Err(source) => return Err(ServerError::Bind { addr, source }),
            };
            let local = listener
                .local_addr()
                .map_err(|source| ServerError::Bind { addr, source })?;
            match serve.token {
                Some(_) => tracing::info!("viewer at http://{local}/ (access token required: open it with ?token=...)"),
                None => tracing::info!("viewer at http://{local}/"),
            }
            bound.http = Some(local);
            let frames = crate::http::frame_channel();
            sim.frames = Some(frames.clone());
            tokio::spawn(crate::http::serve(
                listener,
                handle.clone(),
                frames,
                serve.http.clone(),
                serve.token.clone(),
                stop_rx.clone(),
                crate::http::Sidecars {
                    debug: debug_hub.clone(),
                    ros2: sim.ros2.as_ref().map(|r| r.network.clone()),
                },
            ));
        }
        Ok::<_, ServerError>(bound)
    })?;
    if !serve.bind.is_loopback() {
        match serve.token {
            None => tracing::warn!(
                "listening on {} (not loopback): anyone who can reach this machine can drive the simulation (--token TOKEN requires an access token)",
                serve.bind
            ),
            Some(_) => tracing::warn!(
                "listening on {} (not loopback): the text channel and the viewer require the access token, which travels unencrypted (use an SSH tunnel on networks you do not trust)",
                serve.bind
            ),
        }
        if let (Some(_), Some(zmq)) = (&serve.token, bound.zmq) {
            if zmq.ip().is_loopback() {
                tracing::warn!(
                    "ZMQ remote API kept on {zmq}: it has no authentication (CoppeliaSim's protocol), so with --token it does not follow --bind {}; reach it through an SSH tunnel, or pass --expose-zmq",
                    serve.bind
                );
            } else {
                tracing::warn!(
                    "ZMQ remote API on {zmq} has no authentication: --token does not protect it (--expose-zmq)"
                );
            }
        }
    }
    // Signals are caught from before the caller announces the listeners: a client that
    // sees them and at once sends SIGTERM must get a clean stop, not the default action
    // (death by signal, no cleanup, no export). The first signal only sets the flag;
    // the simulation thread notices it between steps, runs the cleanup hooks and
    // exports. A second one exits at once.
    if signals == Signals::Catch {
        let mut signals = {
            let _rt = rt.enter();
            SignalStream::register()
        };
        let shutdown = shutdown.clone();
        rt.spawn(async move {
            signals.recv().await;
            tracing::info!("stopping (signal received; another one exits without cleanup)");
            shutdown.trigger();
            signals.recv().await;
            tracing::warn!("second signal: exiting without cleanup");
            std::process::exit(130);
        });
    }
    // Scripts' LuaSocket calls: a blocked `accept` gives up when the run is asked to
    // stop, and a `bind` that finds one of these ports taken says it is gantry's.
    sim.limits.network.stop = Some(shutdown.0.clone());
    for (addr, what) in [
        (bound.text, "text channel (--text-port)"),
        (bound.zmq, "ZMQ remote API (--zmq-port)"),
        (bound.legacy, "legacy remote API (--legacy-port)"),
        (bound.http, "viewer (--http-port)"),
        (bound.dap, "debugger (--debug=PORT)"),
    ] {
        if let Some(a) = addr {
            sim.limits.network.gantry_ports.push((a.port(), what.to_owned()));
        }
    }
    let sim_shutdown = shutdown.clone();
    let sim_thread = std::thread::Builder::new()
        .name("gantry-sim".into())
        .spawn(move || {
            let should_stop = || sim_shutdown.is_triggered();
            run_sim_thread_debugged(model, sim, rx, should_stop, Vec::new(), debug_link, recorder)
        })
        .map_err(ServerError::Runtime)?;
    Ok(Running {
        rt,
        handle,
        bound,
        sim_thread,
        stop_tx,
        shutdown,
    })
}

/// Where the ZMQ remote API listens: `bind`, except with a token and a non-loopback
/// `bind`, where an unauthenticated listener would leave the token protecting only
/// two of the three ways in; then loopback of the same family, unless `expose_zmq`.
fn zmq_ip(serve: &ServeConfig) -> IpAddr {
    if serve.token.is_none() || serve.bind.is_loopback() || serve.expose_zmq {
        return serve.bind;
    }
    match serve.bind {
        IpAddr::V4(_) => IpAddr::V4(Ipv4Addr::LOCALHOST),
        IpAddr::V6(_) => IpAddr::V6(Ipv6Addr::LOCALHOST),
    }
}

/// Loopback of the same family as `bind`.
fn loopback_of(bind: IpAddr) -> IpAddr {
    match bind {
        IpAddr::V4(_) => IpAddr::V4(Ipv4Addr::LOCALHOST),
        IpAddr::V6(_) => IpAddr::V6(Ipv6Addr::LOCALHOST),
    }
}

/// Ctrl-C (SIGINT) and SIGTERM. Registered on creation (unlike `tokio::signal::ctrl_c`,
/// which registers when first polled), so neither kills the process from then on.
struct SignalStream {
    #[cfg(unix)]
    int: Option<tokio::signal::unix::Signal>,
    #[cfg(unix)]
    term: Option<tokio::signal::unix::Signal>,
}

impl SignalStream {
    /// Must run inside the runtime (`Runtime::enter`).
    fn register() -> Self {
        #[cfg(unix)]
        {
            use tokio::signal::unix::{SignalKind, signal};
            Self {
                int: signal(SignalKind::interrupt()).ok(),
                term: signal(SignalKind::terminate()).ok(),
            }
        }
        #[cfg(not(unix))]
        Self {}
    }

    /// The next signal. Never returns if none could be registered.
    async fn recv(&mut self) {
        #[cfg(unix)]
        {
            async fn next(s: &mut Option<tokio::signal::unix::Signal>) {
                if let Some(s) = s
                    && s.recv().await.is_some()
                {
                    return;
                }
                std::future::pending().await
            }
            tokio::select! {
                () = next(&mut self.int) => {}
                () = next(&mut self.term) => {}
            }
        }
        #[cfg(not(unix))]
        if tokio::signal::ctrl_c().await.is_err() {
            std::future::pending::<()>().await;
        }
    }
}
