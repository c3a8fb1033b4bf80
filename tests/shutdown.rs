//! Issue 9: SIGTERM and Ctrl-C (SIGINT) stop a running gantry cleanly while clients are
//! connected: the scripts' `sysCall_cleanup` runs (and its log line reaches stderr), the
//! graph streams are exported complete (`--export-graphs`), the summary line is printed,
//! every client sees its connection closed, the exit status is 0, and a new gantry can
//! listen on the same ports at once.

use std::io::{BufRead, BufReader, ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// A script on a graph object that records the step count as a graph stream, echoes
/// text packets, and in cleanup records a last value (-1) and logs how many steps it saw.
const PROBE_LUA: &str = r#"
function sysCall_init()
    graph = sim.getObject('.')
    stream = sim.addGraphStream(graph, 'steps', '')
    n = 0
end

function sysCall_sensing()
    n = n + 1
    sim.setGraphStreamValue(graph, stream, n)
end

function sysCall_packet(packet)
    -- No return value: the packet is echoed.
end

function sysCall_cleanup()
    sim.setGraphStreamValue(graph, stream, -1)
    sim.addLog(sim.verbosity_warnings, 'probe: cleanup after ' .. n .. ' steps')
end
"#;

const SCENE_TOML: &str = r#"
[simulation]
dt = 0.05

[floor]

[[object]]
name = "plot"
kind = "graph"
script = "probe.lua"
"#;

/// A scene folder of its own in the system temp dir, removed when the test passes.
struct SceneDir(PathBuf);

impl SceneDir {
    fn new(tag: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("gantry-shutdown-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("temp dir");
        std::fs::write(dir.join("scene.toml"), SCENE_TOML).expect("write scene");
        std::fs::write(dir.join("probe.lua"), PROBE_LUA).expect("write script");
        Self(dir)
    }
}

impl Drop for SceneDir {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// A gantry started with every listener, its stdout and stderr collected.
struct Running {
    child: Child,
    text: SocketAddr,
    zmq: SocketAddr,
    http: SocketAddr,
    /// Every stderr line, as it arrives (the reader thread ends at EOF).
    stderr: mpsc::Receiver<String>,
    /// The whole stdout, once the process closed it.
    stdout: mpsc::Receiver<String>,
}

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Starts `gantry run SCENE` on the given ports (0 = any) and waits for its three
/// listening lines.
fn start(scene: &Path, ports: [u16; 3], graphs: &Path) -> Running {
    let mut child = Command::new(env!("CARGO_BIN_EXE_gantry"))
        .arg("run")
        .arg(scene)
        .args(["--text-port", &ports[0].to_string()])
        .args(["--zmq-port", &ports[1].to_string()])
        .args(["--http-port", &ports[2].to_string()])
        .arg("--export-graphs")
        .arg(graphs)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("gantry starts");
    let (err_tx, stderr) = mpsc::channel();
    let err = child.stderr.take().expect("stderr piped");
    std::thread::spawn(move || {
        for line in BufReader::new(err).lines() {
            let Ok(line) = line else { break };
            if err_tx.send(line).is_err() {
                break;
            }
        }
    });
    let (out_tx, stdout) = mpsc::channel();
    let mut out = child.stdout.take().expect("stdout piped");
    std::thread::spawn(move || {
        let mut s = String::new();
        let _ = out.read_to_string(&mut s);
        let _ = out_tx.send(s);
    });
    let mut addrs = [None; 3];
    let mut seen = Vec::new();
    while addrs.iter().any(Option::is_none) {
        let line = stderr
            .recv_timeout(Duration::from_secs(60))
            .unwrap_or_else(|_| panic!("gantry prints its three listening lines; got:\n{}", seen.join("\n")));
        for (i, key) in ["listening text=", "listening zmq=", "listening http="]
            .iter()
            .enumerate()
        {
            if let Some(a) = line.strip_prefix(key) {
                addrs[i] = Some(a.parse::<SocketAddr>().expect("socket address"));
            }
        }
        seen.push(line);
    }
    let [text, zmq, http] = addrs.map(|a| a.expect("checked above"));
    Running {
        child,
        text,
        zmq,
        http,
        stderr,
        stdout,
    }
}

/// Sends `signal` (a `kill -s` name) to the process.
fn send_signal(child: &Child, signal: &str) {
    let status = Command::new("kill")
        .args(["-s", signal, &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(status.success(), "kill -s {signal}");
}

/// Waits for the process to exit, at most `limit`.
fn wait_exit(child: &mut Child, limit: Duration) -> ExitStatus {
    let deadline = Instant::now() + limit;
    loop {
        if let Some(status) = child.try_wait().expect("try_wait") {
            return status;
        }
        assert!(
            Instant::now() < deadline,
            "gantry still running {limit:?} after the signal"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A persistent text client that got one echo back.
fn text_client(addr: SocketAddr, i: usize) -> TcpStream {
    let mut s = TcpStream::connect(addr).expect("text channel accepts");
    s.set_read_timeout(Some(Duration::from_secs(10))).expect("timeout");
    let packet = format!("<PING#N={i}>");
    s.write_all(format!("{packet}\n").as_bytes()).expect("write");
    let mut line = String::new();
    BufReader::new(&s).read_line(&mut line).expect("echo");
    assert_eq!(line.trim_end(), packet);
    s
}

/// Whether the server closed the connection: a read ends (EOF or reset) rather than
/// timing out.
fn closed_by_server(s: &mut TcpStream) -> bool {
    let mut buf = [0u8; 256];
    loop {
        match s.read(&mut buf) {
            Ok(0) => return true,
            Ok(_) => continue,
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => return false,
            Err(_) => return true,
        }
    }
}

/// Runs the scenario for one signal.
fn stops_cleanly_on(signal: &str) {
    let dir = SceneDir::new(signal);
    let scene = dir.0.join("scene.toml");
    let graphs = dir.0.join("graphs");
    let mut g = start(&scene, [0; 3], &graphs);

    // Clients of every kind are connected when the signal arrives: text clients that
    // got a reply, one in the middle of a packet, and idle ZMQ and HTTP connections.
    let mut clients: Vec<TcpStream> = (0..3).map(|i| text_client(g.text, i)).collect();
    let mut partial = TcpStream::connect(g.text).expect("connect");
    partial.write_all(b"<PING#N=").expect("write");
    clients.push(partial);
    clients.push(TcpStream::connect(g.zmq).expect("zmq accepts"));
    clients.push(TcpStream::connect(g.http).expect("http accepts"));
    for c in &clients {
        c.set_read_timeout(Some(Duration::from_secs(10))).expect("timeout");
    }
    // A second of simulation, so there is something to export.
    std::thread::sleep(Duration::from_millis(1000));

    send_signal(&g.child, signal);
    let status = wait_exit(&mut g.child, Duration::from_secs(15));
    let stderr: Vec<String> = g.stderr.try_iter().collect();
    let stderr = stderr.join("\n");
    assert_eq!(status.code(), Some(0), "exit status after {signal}; stderr:\n{stderr}");
    for (i, c) in clients.iter_mut().enumerate() {
        assert!(closed_by_server(c), "client {i} still open after gantry exited");
    }

    // The summary line, then the cleanup hook's log line and the export, agree on the
    // number of steps.
    let stdout = g.stdout.recv_timeout(Duration::from_secs(5)).expect("stdout closed");
    let steps: u64 = stdout
        .lines()
        .last()
        .and_then(|l| l.strip_prefix("steps="))
        .and_then(|l| l.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("summary line on stdout: {stdout:?}"));
    assert!(steps >= 5, "a second in real time is about 20 steps, got {steps}");
    assert!(
        stderr.contains(&format!("probe: cleanup after {steps} steps")),
        "cleanup hook's log line:\n{stderr}"
    );
    assert!(stderr.contains("graph streams written to"), "{stderr}");

    // The CSV is complete: one row per step with the step count, then the cleanup row.
    let csv = std::fs::read_to_string(graphs.join("plot.csv")).expect("plot.csv exported");
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("time,steps"));
    let rows: Vec<(f64, f64)> = lines
        .map(|l| {
            let (t, v) = l.split_once(',').expect("two columns");
            (t.parse().expect("time"), v.parse().expect("value"))
        })
        .collect();
    assert_eq!(rows.len() as u64, steps + 1, "{csv}");
    for (k, (t, v)) in rows.iter().enumerate() {
        let k = k as f64 + 1.0;
        assert!((t - 0.05 * k).abs() < 1e-9, "row {k}: time {t}");
        let expected = if k as u64 == steps + 1 { -1.0 } else { k };
        assert_eq!(*v, expected, "row {k}");
    }

    // Every port is free again: a new gantry listens on the same three at once.
    let ports = [g.text.port(), g.zmq.port(), g.http.port()];
    drop(g);
    let again = start(&scene, ports, &graphs);
    assert_eq!([again.text.port(), again.zmq.port(), again.http.port()], ports);
    send_signal(&again.child, signal);
    let mut again = again;
    assert_eq!(wait_exit(&mut again.child, Duration::from_secs(15)).code(), Some(0));
}

#[test]
fn sigterm_runs_cleanup_exports_graphs_and_exits_0() {
    stops_cleanly_on("TERM");
}

#[test]
fn sigint_runs_cleanup_exports_graphs_and_exits_0() {
    stops_cleanly_on("INT");
}
