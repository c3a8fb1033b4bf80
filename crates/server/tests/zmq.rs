//! The ZMQ remote API end to end: a real server (`gantry_server::run` on port 0) and
//! minimal REQ clients built on the `zeromq` crate and our own codec.
//!
//! These cover what the Python suite (tests/python) cannot reach cheaply: raw bytes that
//! no real client sends, idle eviction with a short timeout, and exact replies.

use std::time::{Duration, Instant};

use gantry_protocol::Value;
use gantry_protocol::remote_api::{FUNC_END, FUNC_EXECUTED, FUNC_WAIT, Reply, Request, decode_reply, encode_request};
use gantry_server::ServeConfig;
use util::InProcess;
use zeromq::{ReqSocket, Socket, SocketRecv, SocketSend, ZmqMessage};

mod util;

/// A gantry run serving ZMQ on a free port; stopped when dropped.
struct Server {
    port: u16,
    _run: InProcess,
}

impl Server {
    /// Runs `assets/scenes/<scene>.toml` free-running at full speed (`--fast`).
    fn start(scene: &str) -> Self {
        let run = InProcess::start(
            scene,
            ServeConfig {
                zmq_port: Some(0),
                ..ServeConfig::default()
            },
        );
        Self {
            port: run.bound.zmq.expect("zmq listener bound").port(),
            _run: run,
        }
    }
}

/// A remote API client as the Python client 2.0.4 behaves on the wire.
struct Client {
    sock: ReqSocket,
    uuid: String,
    first: bool,
    timeout: Option<f64>,
}

impl Client {
    async fn connect(port: u16, uuid: &str) -> Self {
        let mut sock = ReqSocket::new();
        sock.connect(&format!("tcp://127.0.0.1:{port}")).await.expect("connect");
        Self {
            sock,
            uuid: uuid.to_owned(),
            first: true,
            timeout: None,
        }
    }

    /// Sends raw bytes and returns the decoded reply.
    async fn raw(&mut self, bytes: Vec<u8>) -> Reply {
        self.sock.send(ZmqMessage::from(bytes)).await.expect("send");
        let msg = tokio::time::timeout(Duration::from_secs(20), self.sock.recv())
            .await
            .expect("reply within 20 s")
            .expect("recv");
        let payload = msg.into_vec().pop().expect("one frame");
        decode_reply(&payload).expect("reply decodes")
    }

    /// One request, one reply; `ver`/`lang`/`timeout` go with the first message only.
    async fn send(&mut self, func: &str, args: Vec<Value>) -> Reply {
        let mut req = Request {
            func: func.to_owned(),
            args,
            uuid: Some(self.uuid.clone()),
            ..Request::default()
        };
        if self.first {
            self.first = false;
            req.ver = Some(2);
            req.lang = Some("python".into());
            req.timeout = Some(self.timeout.unwrap_or(600.0));
        }
        self.raw(encode_request(&req)).await
    }

    /// A call as the client makes it: answers `_*wait*_` with `_*executed*_` until a
    /// final reply comes.
    async fn call(&mut self, func: &str, args: Vec<Value>) -> Reply {
        let mut reply = self.send(func, args).await;
        while matches!(&reply, Reply::Call { func, .. } if func == FUNC_WAIT) {
            reply = self.send(FUNC_EXECUTED, vec![]).await;
        }
        reply
    }

    async fn ok(&mut self, func: &str, args: Vec<Value>) -> Vec<Value> {
        match self.call(func, args).await {
            Reply::Ret(v) => v,
            other => panic!("{func}: expected a result, got {other:?}"),
        }
    }

    async fn err(&mut self, func: &str, args: Vec<Value>) -> String {
        match self.call(func, args).await {
            Reply::Err(e) => e,
            other => panic!("{func}: expected an error, got {other:?}"),
        }
    }

    async fn time(&mut self) -> f64 {
        self.ok("sim.getSimulationTime", vec![]).await[0]
            .as_f64()
            .expect("a number")
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn require_and_info_describe_sim() {
    let server = Server::start("fk_arm");
    let mut c = Client::connect(server.port, "info").await;
    assert_eq!(
        c.call("zmqRemoteApi.require", vec!["sim".into()]).await,
        Reply::Ret(vec![])
    );
    let info = c.ok("zmqRemoteApi.info", vec!["sim".into()]).await;
    assert_eq!(info.len(), 1);
    let func = Value::Map(vec![("func".into(), Value::Map(vec![]))]);
    for f in [
        "getObject",
        "getObjectPosition",
        "setStepping",
        "step",
        "stopSimulation",
        "callScriptFunction",
    ] {
        assert_eq!(info[0].get(f), Some(&func), "{f} in INFO");
    }
    assert_eq!(
        info[0].get("handle_world"),
        Some(&Value::Map(vec![("const".into(), Value::Int(-1))]))
    );
    // Every module of the shared implementation can be required; unknown ones cannot.
    for m in ["simIK", "simUI", "simVision"] {
        assert_eq!(
            c.ok("zmqRemoteApi.require", vec![m.into()]).await,
            Vec::<Value>::new(),
            "{m}"
        );
    }
    let e = c.err("zmqRemoteApi.require", vec!["simBogus".into()]).await;
    assert!(e.contains("simBogus") && e.contains("simIK"), "{e}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn errors_are_replies_and_hurt_nobody() {
    let server = Server::start("fk_arm");
    let mut c = Client::connect(server.port, "errors").await;
    let e = c.err("sim.getObject", vec!["/doesNotExist".into()]).await;
    assert!(
        e.contains("object does not exist") && e.ends_with("(in function 'sim.getObject')"),
        "{e}"
    );
    assert_eq!(
        c.err("sim.bogus", vec![1.into(), Value::Nil]).await,
        "No such function: sim.bogus"
    );
    assert_eq!(
        c.err("simX.getObject", vec![]).await,
        "No such function: simX.getObject"
    );
    // Wrong argument types, in the core and in the transport's own functions.
    let e = c.err("sim.getObjectPosition", vec!["base".into()]).await;
    assert!(
        e.contains("argument 1") && e.ends_with("(in function 'sim.getObjectPosition')"),
        "{e}"
    );
    let e = c.err("sim.setStepping", vec!["yes".into()]).await;
    assert!(e.contains("argument 1: expected boolean"), "{e}");
    let e = c
        .err("sim.setJointPosition", vec![Value::Map(vec![]), Value::Array(vec![])])
        .await;
    assert!(e.contains("(in function 'sim.setJointPosition')"), "{e}");
    // `_*executed*_` with nothing to acknowledge.
    let e = c.err(FUNC_EXECUTED, vec![]).await;
    assert!(e.contains("unexpected"), "{e}");

    // Bytes no client would send: not CBOR, truncated CBOR, not a map, no func.
    for bad in [vec![0xff, 0x00], vec![0xa1, 0x64], vec![0x80], vec![0xa0], vec![]] {
        match c.raw(bad.clone()).await {
            Reply::Err(e) => assert!(e.starts_with("message"), "{bad:?}: {e}"),
            other => panic!("{bad:?}: expected an error, got {other:?}"),
        }
    }
    // A v1 client (no uuid) gets the real server's version mismatch.
    let v1 = encode_request(&Request {
        func: "sim.getObject".into(),
        ..Request::default()
    });
    match c.raw(v1).await {
        Reply::Err(e) => assert!(e.contains("version does not match"), "{e}"),
        other => panic!("expected an error, got {other:?}"),
    }

    // A NaN or negative idle timeout is ignored or bounded, not a panic.
    for (uuid, t) in [
        ("nan-timeout", f64::NAN),
        ("negative-timeout", -5.0),
        ("huge-timeout", 1e300),
    ] {
        let mut odd = Client::connect(server.port, uuid).await;
        odd.timeout = Some(t);
        assert_eq!(odd.ok("sim.getSimulationState", vec![]).await, vec![Value::Int(17)]);
    }

    // The same client and a new one are still served.
    let h = c.ok("sim.getObject", vec!["/arm6/joint1".into()]).await;
    assert!(matches!(h[..], [Value::Int(_)]), "{h:?}");
    let mut d = Client::connect(server.port, "after-errors").await;
    assert_eq!(d.ok("sim.getSimulationState", vec![]).await, vec![Value::Int(17)]);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn stepping_client_holds_the_simulation_and_steps_by_dt() {
    let server = Server::start("bubble_rob");
    let mut a = Client::connect(server.port, "stepper").await;
    let mut b = Client::connect(server.port, "observer").await;
    assert_eq!(a.ok("sim.setStepping", vec![true.into()]).await, vec![Value::Int(0)]);
    let dt = a.ok("sim.getSimulationTimeStep", vec![]).await[0].as_f64().unwrap();
    let t0 = a.time().await;
    // Held: a free-running --fast simulation would have moved on by many steps.
    tokio::time::sleep(Duration::from_millis(200)).await;
    assert_eq!(b.time().await, t0);
    // client.step() sends `sim.step [true]`: a wait, then the step.
    assert_eq!(
        a.send("sim.step", vec![true.into()]).await,
        Reply::Call {
            func: FUNC_WAIT.into(),
            args: vec![]
        }
    );
    assert_eq!(a.send(FUNC_EXECUTED, vec![]).await, Reply::Ret(vec![]));
    assert!((a.time().await - (t0 + dt)).abs() < 1e-9);
    for _ in 0..10 {
        a.ok("sim.step", vec![]).await;
    }
    assert!((b.time().await - (t0 + 11.0 * dt)).abs() < 1e-9);
    // Nested levels: the call returns the previous level.
    assert_eq!(a.ok("sim.setStepping", vec![true.into()]).await, vec![Value::Int(1)]);
    assert_eq!(a.ok("sim.setStepping", vec![false.into()]).await, vec![Value::Int(2)]);
    assert_eq!(a.ok("sim.setStepping", vec![false.into()]).await, vec![Value::Int(1)]);
    // Free-running again.
    let t1 = b.time().await;
    tokio::time::sleep(Duration::from_millis(100)).await;
    assert!(b.time().await > t1);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_parked_client_waits_for_every_stepper_while_others_are_served() {
    let server = Server::start("bubble_rob");
    let mut a = Client::connect(server.port, "stepper-a").await;
    let mut b = Client::connect(server.port, "stepper-b").await;
    let mut c = Client::connect(server.port, "bystander").await;
    a.ok("sim.setStepping", vec![true.into()]).await;
    b.ok("sim.setStepping", vec![true.into()]).await;
    let t0 = c.time().await;
    // A asks for a step; B has not, so A stays parked on its `_*executed*_`.
    assert!(matches!(a.send("sim.step", vec![]).await, Reply::Call { .. }));
    let parked = tokio::spawn(async move {
        let r = a.send(FUNC_EXECUTED, vec![]).await;
        (a, r)
    });
    tokio::time::sleep(Duration::from_millis(200)).await;
    assert!(!parked.is_finished(), "A is parked until B steps too");
    // Meanwhile another client is served at once, many times over.
    let start = Instant::now();
    for _ in 0..200 {
        assert_eq!(c.time().await, t0);
    }
    assert!(start.elapsed() < Duration::from_secs(5));
    b.ok("sim.step", vec![]).await;
    let (mut a, r) = tokio::time::timeout(Duration::from_secs(5), parked)
        .await
        .expect("A released")
        .unwrap();
    assert_eq!(r, Reply::Ret(vec![]));
    let dt = a.ok("sim.getSimulationTimeStep", vec![]).await[0].as_f64().unwrap();
    assert!((c.time().await - (t0 + dt)).abs() < 1e-9);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn stop_resets_levels_and_start_runs_again() {
    let server = Server::start("bubble_rob");
    let mut a = Client::connect(server.port, "controller").await;
    a.ok("sim.setStepping", vec![true.into()]).await;
    a.ok("sim.setStepping", vec![true.into()]).await;
    a.ok("sim.step", vec![]).await;
    assert_eq!(a.ok("sim.stopSimulation", vec![]).await, vec![]);
    assert_eq!(a.ok("sim.getSimulationState", vec![]).await, vec![Value::Int(0)]);
    assert_eq!(a.time().await, 0.0, "the initial scene is back");
    // A step while stopped returns after one wait round trip.
    a.ok("sim.step", vec![]).await;
    assert_eq!(
        a.ok("sim.setStepping", vec![true.into()]).await,
        vec![Value::Int(0)],
        "stop reset the level"
    );
    a.ok("sim.startSimulation", vec![]).await;
    assert_eq!(a.ok("sim.getSimulationState", vec![]).await, vec![Value::Int(17)]);
    a.ok("sim.step", vec![]).await;
    assert!(a.time().await > 0.0);
    a.ok("sim.pauseSimulation", vec![]).await;
    assert_eq!(a.ok("sim.getSimulationState", vec![]).await, vec![Value::Int(8)]);
    let t = a.time().await;
    a.ok("sim.step", vec![]).await;
    assert_eq!(a.time().await, t, "paused: step returns without stepping");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn end_and_idle_timeout_release_a_stepping_client() {
    let server = Server::start("bubble_rob");
    let mut watcher = Client::connect(server.port, "watcher").await;

    // `_*end*_` drops the client at once.
    let mut leaving = Client::connect(server.port, "leaving").await;
    leaving.ok("sim.setStepping", vec![true.into()]).await;
    let t = watcher.time().await;
    tokio::time::sleep(Duration::from_millis(100)).await;
    assert_eq!(watcher.time().await, t);
    assert_eq!(leaving.send(FUNC_END, vec![]).await, Reply::Empty);
    tokio::time::sleep(Duration::from_millis(100)).await;
    assert!(watcher.time().await > t, "free-running after _*end*_");

    // A client that goes silent is dropped after its timeout (1 s here).
    let mut silent = Client::connect(server.port, "silent").await;
    silent.timeout = Some(1.0);
    silent.ok("sim.setStepping", vec![true.into()]).await;
    let t = watcher.time().await;
    tokio::time::sleep(Duration::from_millis(300)).await;
    assert_eq!(watcher.time().await, t, "held while the client may still come back");
    let deadline = Instant::now() + Duration::from_secs(10);
    while watcher.time().await == t {
        assert!(Instant::now() < deadline, "the idle client was never dropped");
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    // The watcher itself, with the default timeout, is still known: its calls work.
    assert_eq!(watcher.ok("sim.getSimulationState", vec![]).await, vec![Value::Int(17)]);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn wrong_peers_do_not_stop_the_listener() {
    let server = Server::start("fk_arm");
    // A client that sends a request and vanishes before its reply.
    {
        let mut gone = Client::connect(server.port, "gone").await;
        gone.sock.send(ZmqMessage::from(vec![0xffu8])).await.unwrap();
    }
    // A raw TCP peer speaking garbage instead of ZMTP.
    {
        use tokio::io::AsyncWriteExt;
        let mut s = tokio::net::TcpStream::connect(("127.0.0.1", server.port))
            .await
            .unwrap();
        let _ = s.write_all(&[0x13; 4096]).await;
    }
    tokio::time::sleep(Duration::from_millis(100)).await;
    let mut c = Client::connect(server.port, "after").await;
    assert_eq!(c.ok("sim.getSimulationState", vec![]).await, vec![Value::Int(17)]);
}
