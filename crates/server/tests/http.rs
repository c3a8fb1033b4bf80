//! The viewer's HTTP and WebSocket server end to end, without a browser: a real server
//! (`gantry_server::run` with `http_port: Some(0)`) and a minimal blocking WebSocket
//! client over std sockets, so exact bytes can be sent, malformed ones included.
//!
//! The browser side (the page itself, WebGL, the panels) is tested by
//! `tests/browser/test_viewer.py`.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::Path;
use std::time::{Duration, Instant};

use gantry_server::ServeConfig;
use gantry_server::http::HttpConfig;
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene_text};
use gantry_sim_core::world::World;
use gantry_sim_core::world::object_path::object_alias;
use serde_json::Value as Json;
use util::InProcess;

use crate::util;

/// A gantry run on the showroom serving the viewer on a free port; stopped when dropped.
struct Server {
    addr: SocketAddr,
    _run: InProcess,
}

impl Server {
    fn start(http: HttpConfig) -> Self {
        let run = InProcess::start(
            "showroom",
            ServeConfig {
                http_port: Some(0),
                http,
                ..ServeConfig::default()
            },
        );
        Self {
            addr: run.bound.http.expect("http listener bound"),
            _run: run,
        }
    }
}

/// One HTTP/1.1 GET: status code, headers (lower-case names), body.
fn get(addr: SocketAddr, path: &str) -> (u16, String, Vec<u8>) {
    let mut s = TcpStream::connect(addr).expect("connect");
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    write!(s, "GET {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n").unwrap();
    let mut raw = Vec::new();
    s.read_to_end(&mut raw).expect("response");
    let split = raw.windows(4).position(|w| w == b"\r\n\r\n").expect("header end");
    let head = String::from_utf8_lossy(&raw[..split]).to_lowercase();
    let code = head
        .split_whitespace()
        .nth(1)
        .and_then(|c| c.parse().ok())
        .expect("status");
    (code, head, raw[split + 4..].to_vec())
}

/// A WebSocket frame as received: opcode and payload.
struct Frame {
    opcode: u8,
    payload: Vec<u8>,
}

/// The smallest client the tests need: handshake, masked frames out, frames in.
struct Ws {
    rd: BufReader<TcpStream>,
    wr: TcpStream,
}

impl Ws {
    /// Connects; `Err(status line)` when the server refuses the upgrade.
    fn connect(addr: SocketAddr) -> Result<Ws, String> {
        let s = TcpStream::connect(addr).expect("connect");
        s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
        let mut wr = s.try_clone().unwrap();
        write!(
            wr,
            "GET /ws HTTP/1.1\r\nHost: {addr}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
             Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n"
        )
        .unwrap();
        let mut rd = BufReader::new(s);
        let mut status = String::new();
        rd.read_line(&mut status).unwrap();
        loop {
            let mut line = String::new();
            rd.read_line(&mut line).unwrap();
            if line == "\r\n" || line.is_empty() {
                break;
            }
        }
        if status.contains(" 101 ") {
            Ok(Ws { rd, wr })
        } else {
            Err(status)
        }
    }

    fn recv(&mut self) -> Frame {
        let mut h = [0u8; 2];
        self.rd.read_exact(&mut h).expect("frame header");
        let mut len = u64::from(h[1] & 0x7f);
        if len == 126 {
            let mut b = [0u8; 2];
            self.rd.read_exact(&mut b).unwrap();
            len = u64::from(u16::from_be_bytes(b));
        } else if len == 127 {
            let mut b = [0u8; 8];
            self.rd.read_exact(&mut b).unwrap();
            len = u64::from_be_bytes(b);
        }
        let mut payload = vec![0; len as usize];
        self.rd.read_exact(&mut payload).unwrap();
        Frame {
            opcode: h[0] & 0x0f,
            payload,
        }
    }

    /// The next text message, as JSON (skipping binary ones).
    fn recv_json(&mut self) -> Json {
        loop {
            let f = self.recv();
            if f.opcode == 1 {
                return serde_json::from_slice(&f.payload).expect("JSON text");
            }
        }
    }

    /// The next text message with `"t": t`.
    fn recv_type(&mut self, t: &str) -> Json {
        loop {
            let j = self.recv_json();
            if j["t"] == t {
                return j;
            }
        }
    }

    fn send(&mut self, opcode: u8, payload: &[u8]) {
        let mut f = vec![0x80 | opcode];
        let n = payload.len();
        if n < 126 {
            f.push(0x80 | n as u8);
        } else if n < 65536 {
            f.push(0x80 | 126);
            f.extend((n as u16).to_be_bytes());
        } else {
            f.push(0x80 | 127);
            f.extend((n as u64).to_be_bytes());
        }
        let mask = [0x12, 0x34, 0x56, 0x78];
        f.extend(mask);
        f.extend(payload.iter().enumerate().map(|(i, b)| b ^ mask[i % 4]));
        self.wr.write_all(&f).unwrap();
    }
}

#[test]
fn page_assets_and_api_are_served() {
    let server = Server::start(HttpConfig::default());
    let (code, head, body) = get(server.addr, "/");
    assert_eq!(code, 200);
    assert!(head.contains("content-type: text/html"), "{head}");
    assert!(String::from_utf8_lossy(&body).contains("js/main.js"));
    let (code, head, body) = get(server.addr, "/js/gl.js");
    assert_eq!(code, 200);
    assert!(head.contains("text/javascript"), "{head}");
    assert!(String::from_utf8_lossy(&body).contains("webgl2"));
    assert_eq!(get(server.addr, "/style.css").0, 200);
    assert_eq!(get(server.addr, "/nope").0, 404);
    assert_eq!(get(server.addr, "/api/graph/abc").0, 400);
    assert_eq!(get(server.addr, "/api/graph/999999.csv").0, 404);

    let (code, _, body) = get(server.addr, "/api/status");
    assert_eq!(code, 200);
    let status: Json = serde_json::from_slice(&body).unwrap();
    assert_eq!(status["state"], 17);
    assert_eq!(status["viewers"], 0);

    // BubbleRob's clearance graph, as CSV.
    let mut ws = Ws::connect(server.addr).expect("upgrade");
    let scene = ws.recv_type("scene");
    let graph = scene["objects"]
        .as_array()
        .unwrap()
        .iter()
        .find(|o| o["kind"] == "graph")
        .expect("a graph")["handle"]
        .as_i64()
        .unwrap();
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let (code, head, body) = get(server.addr, &format!("/api/graph/{graph}.csv"));
        assert_eq!(code, 200);
        assert!(head.contains("text/csv") && head.contains("attachment"), "{head}");
        if String::from_utf8_lossy(&body).lines().count() > 2 {
            break;
        }
        assert!(Instant::now() < deadline, "no samples in the graph CSV");
        std::thread::sleep(Duration::from_millis(50));
    }
}

#[test]
fn a_viewer_gets_the_scene_then_deltas_and_panels() {
    let server = Server::start(HttpConfig::default());
    let mut ws = Ws::connect(server.addr).expect("upgrade");
    let first = ws.recv();
    assert_eq!(first.opcode, 1, "the scene description comes first");
    let scene: Json = serde_json::from_slice(&first.payload).unwrap();
    assert_eq!(scene["t"], "scene");
    let objects = scene["objects"].as_array().unwrap();
    let joints = objects.iter().filter(|o| o["kind"] == "joint").count();
    // arm6: joint1 is continuous (cyclic, no limits), joint2 has limits.
    let joint = |alias: &str| objects.iter().find(|o| o["alias"] == alias).expect(alias)["joint"].clone();
    assert_eq!(
        (joint("joint1")["cyclic"].as_bool(), joint("joint1")["limits"].is_null()),
        (Some(true), true)
    );
    assert_eq!(joint("joint2")["limits"][0].as_f64(), Some(-1.9198621771937625));
    assert_eq!(joint("joint2")["type"], "revolute");
    let nose = objects.iter().find(|o| o["alias"] == "sensingNose").unwrap();
    assert_eq!(nose["proximity"]["shape"], "cone");
    let rob = objects.iter().find(|o| o["alias"] == "bubbleRob").unwrap();
    assert_eq!(rob["visuals"][0]["geom"], "sphere");

    // The first delta has every pose; the tick has every joint; the panels list three
    // running scripts and BubbleRob's speed slider. They come in whatever order the
    // simulation's timing gives, and the slider's panel only once (panels are sent when
    // they change), so one loop takes each from whichever frame carries it.
    let mut poses = None;
    let mut tick = None;
    let mut scripts = None;
    let mut uis = None;
    let deadline = Instant::now() + Duration::from_secs(30);
    while poses.is_none() || tick.is_none() || scripts.is_none() || uis.is_none() {
        assert!(
            Instant::now() < deadline,
            "within 30 s: poses {poses:?}, tick {}, scripts {}, uis {}",
            tick.is_some(),
            scripts.is_some(),
            uis.is_some()
        );
        let f = ws.recv();
        match f.opcode {
            2 if f.payload[..4] == 1u32.to_le_bytes() => {
                poses.get_or_insert(u32::from_le_bytes(f.payload[4..8].try_into().unwrap()));
            }
            1 => {
                let j: Json = serde_json::from_slice(&f.payload).unwrap();
                if j["t"] == "tick" && j.get("joints").is_some() {
                    tick.get_or_insert(j);
                } else if j["t"] == "panels" {
                    if let Some(s) = j.get("scripts") {
                        scripts = Some(s.clone());
                    }
                    if let Some(u) = j.get("uis").filter(|u| !u.as_array().unwrap().is_empty()) {
                        uis = Some(u.clone());
                    }
                }
            }
            _ => {}
        }
    }
    assert_eq!(poses, Some(objects.len() as u32));
    let tick = tick.unwrap();
    assert_eq!(tick["joints"].as_array().unwrap().len(), joints);
    assert_eq!(tick["state"], 17);

    let scripts = scripts.unwrap();
    assert_eq!(scripts.as_array().unwrap().len(), 3);
    assert!(scripts.as_array().unwrap().iter().all(|s| s["state"] == "running"));
    let slider = &uis.unwrap()[0]["content"]["rows"][0][0];
    assert_eq!(slider["type"], "hslider");
    assert_eq!(slider["id"], 1);
}

/// Siblings sharing an alias at three levels (roots, children, grandchildren), next to
/// unique ones.
const DUPLICATE_ALIASES: &str = r#"
[simulation]
dt = 0.05

[[object]]
name = "r0"
alias = "robot"
kind = "dummy"

[[object]]
name = "r1"
alias = "robot"
kind = "dummy"

[[object]]
name = "solo"
kind = "dummy"

[[object]]
name = "r0_leg0"
alias = "leg"
kind = "dummy"
parent = "r0"

[[object]]
name = "r0_arm"
alias = "arm"
kind = "dummy"
parent = "r0"

[[object]]
name = "r0_leg1"
alias = "leg"
kind = "dummy"
parent = "r0"

[[object]]
name = "r1_leg"
alias = "leg"
kind = "dummy"
parent = "r1"

[[object]]
name = "foot_a"
alias = "foot"
kind = "dummy"
parent = "r0_leg1"

[[object]]
name = "foot_b"
alias = "foot"
kind = "dummy"
parent = "r0_leg1"
"#;

#[test]
fn scene_paths_are_sim_cores_with_duplicate_sibling_aliases() {
    let model = load_scene_text(
        &DiskFiles,
        DUPLICATE_ALIASES,
        Path::new("duplicate_aliases.toml"),
        &LoadOptions::default(),
    )
    .expect("scene loads");
    // The same scene as a bare world: handles are model indices in both.
    let world = World::new(&model);
    let run = InProcess::start_model(
        model,
        ServeConfig {
            http_port: Some(0),
            ..ServeConfig::default()
        },
    );
    let mut ws = Ws::connect(run.bound.http.expect("http listener bound")).expect("upgrade");
    let scene = ws.recv_type("scene");
    let objects = scene["objects"].as_array().unwrap();
    assert_eq!(objects.len(), 9, "{scene}");
    for o in objects {
        let handle = o["handle"].as_i64().unwrap();
        // sim.getObjectAlias(h, 2): the full path.
        assert_eq!(o["path"], object_alias(&world, handle, 2), "{o}");
    }
    let mut paths: Vec<&str> = objects.iter().map(|o| o["path"].as_str().unwrap()).collect();
    paths.sort_unstable();
    assert_eq!(
        paths,
        [
            "/robot[0]",
            "/robot[0]/arm",
            "/robot[0]/leg[0]",
            "/robot[0]/leg[1]",
            "/robot[0]/leg[1]/foot[0]",
            "/robot[0]/leg[1]/foot[1]",
            "/robot[1]",
            "/robot[1]/leg",
            "/solo",
        ]
    );
}

#[test]
fn commands_work_and_bad_messages_get_error_replies() {
    let server = Server::start(HttpConfig::default());
    let mut ws = Ws::connect(server.addr).expect("upgrade");
    let reply = |ws: &mut Ws, msg: &[u8], binary: bool| {
        ws.send(if binary { 2 } else { 1 }, msg);
        ws.recv_type("reply")
    };
    for bad in [
        &b"not json"[..],
        b"{}",
        b"{\"op\":\"explode\"}",
        b"{\"op\":\"control\",\"action\":\"fly\"}",
        b"{\"op\":\"packet\",\"text\":\"<FK#J1=abc>\"}",
        b"{\"op\":\"packet\",\"text\":\"<NOPE#>\"}",
        b"{\"op\":\"ui\",\"ui\":424242,\"widget\":1,\"value\":5}",
        b"{\"op\":\"ui\",\"ui\":1000,\"widget\":1,\"value\":[1]}",
        b"{\"op\":\"reload\",\"script\":99}",
    ] {
        let r = reply(&mut ws, bad, false);
        assert_eq!(r["ok"], false, "{} -> {r}", String::from_utf8_lossy(bad));
        assert!(!r["text"].as_str().unwrap().is_empty());
    }
    assert_eq!(reply(&mut ws, b"\x01\x02", true)["ok"], false);

    // The same FK packet a TCP client sends, with the same echo.
    let r = reply(&mut ws, br#"{"id":5,"op":"packet","text":"<FK#J1=0.5>"}"#, false);
    assert_eq!((r["id"].as_i64(), r["ok"].as_bool()), (Some(5), Some(true)), "{r}");
    assert_eq!(r["text"], "<FK#J1=0.5>");
    let r = reply(&mut ws, br#"{"op":"packet","text":"<JOINTS#>"}"#, false);
    assert!(r["text"].as_str().unwrap().starts_with("<JOINTS#J1=0.5,"), "{r}");

    // Controls.
    let r = reply(&mut ws, br#"{"op":"control","action":"pause"}"#, false);
    assert_eq!((r["ok"].as_bool(), r["text"].as_str()), (Some(true), Some("paused")));
    let r = reply(&mut ws, br#"{"op":"control","action":"step"}"#, false);
    assert_eq!(r["text"], "paused");
    let r = reply(&mut ws, br#"{"op":"control","action":"start"}"#, false);
    assert_eq!(r["text"], "running");

    // The speed slider, as a user would move it.
    let r = reply(&mut ws, br#"{"op":"ui","ui":1000,"widget":1,"value":20}"#, false);
    assert_eq!(r["ok"], true, "{r}");

    // An oversize frame ends only that connection.
    ws.send(1, &vec![b' '; 100_000]);
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let f = ws.recv();
        if f.opcode == 8 {
            break;
        }
        assert!(Instant::now() < deadline, "no close after an oversize frame");
    }
    let mut again = Ws::connect(server.addr).expect("the server still accepts viewers");
    assert_eq!(again.recv_json()["t"], "scene");
}

#[test]
fn viewers_beyond_the_limit_are_refused() {
    let server = Server::start(HttpConfig {
        max_viewers: 1,
        ..HttpConfig::default()
    });
    let mut first = Ws::connect(server.addr).expect("first viewer");
    assert_eq!(first.recv_json()["t"], "scene");
    let refused = Ws::connect(server.addr).err().expect("second viewer refused");
    assert!(refused.contains("503"), "{refused}");
    drop(first);
    // The slot frees when the page leaves.
    let deadline = Instant::now() + Duration::from_secs(10);
    while Ws::connect(server.addr).is_err() {
        assert!(Instant::now() < deadline, "the slot was not freed");
        std::thread::sleep(Duration::from_millis(50));
    }
}
