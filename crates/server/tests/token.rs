//! The access token (issue 9, security) end to end on a real in-process server: the
//! text channel's `<AUTH#TOKEN>` handshake, the viewer's 401 / `?token=` / cookie /
//! bearer rules on every route, the WebSocket's same-origin check, and where the ZMQ
//! listener binds when a token is set.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{IpAddr, Ipv4Addr, SocketAddr, TcpStream};
use std::time::{Duration, Instant};

use gantry_server::{AccessToken, ServeConfig, TextConfig};
use util::InProcess;

use crate::util;

const TOKEN: &str = "lab-token-0123456789";

fn token() -> Option<AccessToken> {
    Some(AccessToken::new(TOKEN).expect("a valid token"))
}

/// The showroom (its arm answers text packets) with every listener on free ports.
fn start(serve: ServeConfig) -> InProcess {
    InProcess::start(
        "showroom",
        ServeConfig {
            text_port: Some(0),
            zmq_port: Some(0),
            http_port: Some(0),
            ..serve
        },
    )
}

/// A text-channel connection: write lines, read reply lines.
struct Line {
    rd: BufReader<TcpStream>,
    wr: TcpStream,
}

impl Line {
    fn connect(addr: SocketAddr) -> Self {
        let s = TcpStream::connect(addr).expect("connect");
        s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
        Self {
            wr: s.try_clone().unwrap(),
            rd: BufReader::new(s),
        }
    }

    /// Sends `line` and returns the reply line without its newline.
    fn ask(&mut self, line: &str) -> String {
        writeln!(self.wr, "{line}").unwrap();
        self.reply()
    }

    fn reply(&mut self) -> String {
        let mut r = String::new();
        self.rd.read_line(&mut r).expect("reply");
        r.trim_end().to_owned()
    }

    /// Whether the server has closed the connection (EOF before any further byte).
    fn is_closed(&mut self) -> bool {
        let mut b = [0u8; 1];
        matches!(self.rd.read(&mut b), Ok(0))
    }
}

#[test]
fn text_channel_requires_auth_first_when_a_token_is_set() {
    let run = start(ServeConfig {
        token: token(),
        ..ServeConfig::default()
    });
    let addr = run.bound.text.expect("text");

    let mut ok = Line::connect(addr);
    assert_eq!(ok.ask(&format!("<AUTH#{TOKEN}>")), "<AUTH#OK>");
    assert!(
        ok.ask("<JOINTS#>").starts_with("<JOINTS#J1="),
        "packets flow after auth"
    );
    assert_eq!(
        ok.ask(&format!("< auth # {TOKEN} >")),
        "<AUTH#OK>",
        "repeating is harmless"
    );
    assert_eq!(ok.ask("<AUTH#not-the-token>"), "<ERR#wrong access token>");
    assert!(ok.ask("<JOINTS#>").starts_with("<JOINTS#"), "and does not close");

    let mut none = Line::connect(addr);
    let r = none.ask("<JOINTS#>");
    assert!(r.starts_with("<ERR#access token required"), "{r}");
    assert!(r.contains("(AUTH#TOKEN)"), "says what to send: {r}");
    assert!(none.is_closed(), "closed after refusing");

    let mut wrong = Line::connect(addr);
    assert_eq!(
        wrong.ask("<AUTH#lab-token-012345678X>"),
        "<ERR#wrong access token; connection closed>"
    );
    assert!(wrong.is_closed());

    // The token is the whole value: a prefix or an extension is wrong too.
    for guess in [&TOKEN[..TOKEN.len() - 1], &format!("{TOKEN}0")[..]] {
        let mut c = Line::connect(addr);
        assert!(c.ask(&format!("<AUTH#{guess}>")).starts_with("<ERR#wrong access token"));
    }
}

#[test]
fn an_unauthenticated_text_connection_is_closed_after_the_deadline() {
    let run = start(ServeConfig {
        token: token(),
        text: TextConfig {
            // The authentication deadline is the shorter of AUTH_TIMEOUT and this.
            idle_timeout: Duration::from_millis(300),
            ..TextConfig::default()
        },
        ..ServeConfig::default()
    });
    let mut silent = Line::connect(run.bound.text.expect("text"));
    let t0 = Instant::now();
    let r = silent.reply();
    assert!(r.starts_with("<ERR#access token required within"), "{r}");
    assert!(t0.elapsed() < Duration::from_secs(5));
    assert!(silent.is_closed());
}

#[test]
fn without_a_token_auth_is_acknowledged_and_packets_need_none() {
    let run = start(ServeConfig::default());
    let mut c = Line::connect(run.bound.text.expect("text"));
    assert!(c.ask("<JOINTS#>").starts_with("<JOINTS#J1="));
    assert_eq!(c.ask("<AUTH#anything-at-all>"), "<AUTH#OK>");
}

#[test]
fn an_http_request_on_the_text_channel_is_closed_before_its_body() {
    let run = start(ServeConfig::default());
    let mut c = Line::connect(run.bound.text.expect("text"));
    // A web page's fetch() to the text port: the body would otherwise be a packet.
    write!(
        c.wr,
        "POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 43\r\n\r\n<FK#J1=1,J2=0,J3=0,J4=0,J5=0,J6=0>\n"
    )
    .unwrap();
    let r = c.reply();
    assert!(r.contains("not HTTP"), "{r}");
    assert!(c.is_closed(), "nothing after the request line is read");
}

/// One HTTP/1.1 request with `headers` (each `Name: value`): status code, lower-case
/// head, and the body (empty for a WebSocket upgrade, whose socket stays open).
fn request<S: AsRef<str>>(addr: SocketAddr, path: &str, headers: &[S]) -> (u16, String, Vec<u8>) {
    let mut s = TcpStream::connect(addr).expect("connect");
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    let mut req = format!("GET {path} HTTP/1.1\r\nHost: {addr}\r\n");
    if !headers.iter().any(|h| h.as_ref().starts_with("Connection:")) {
        req.push_str("Connection: close\r\n");
    }
    for h in headers {
        req.push_str(h.as_ref());
        req.push_str("\r\n");
    }
    req.push_str("\r\n");
    s.write_all(req.as_bytes()).unwrap();
    let mut rd = BufReader::new(s);
    let mut head = String::new();
    loop {
        let mut line = String::new();
        if rd.read_line(&mut line).unwrap_or(0) == 0 || line == "\r\n" {
            break;
        }
        head.push_str(&line);
    }
    let head = head.to_lowercase();
    let code = head
        .split_whitespace()
        .nth(1)
        .and_then(|c| c.parse().ok())
        .expect("status");
    let mut body = Vec::new();
    if code == 101 {
        // The first WebSocket frame: the scene description, a text message.
        let mut h = [0u8; 2];
        rd.read_exact(&mut h).expect("a frame");
        body.push(h[0] & 0x0f);
    } else {
        // By length: an upgrade request keeps the connection open even when refused.
        let len = head
            .lines()
            .find_map(|l| l.strip_prefix("content-length:"))
            .and_then(|v| v.trim().parse().ok())
            .unwrap_or(0);
        body.resize(len, 0);
        rd.read_exact(&mut body).expect("body");
    }
    (code, head, body)
}

/// [`request`] without extra headers.
fn get(addr: SocketAddr, path: &str) -> (u16, String, Vec<u8>) {
    request::<&str>(addr, path, &[])
}

const UPGRADE: [&str; 4] = [
    "Upgrade: websocket",
    "Connection: Upgrade",
    "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==",
    "Sec-WebSocket-Version: 13",
];

fn ws_with(extra: &[&str]) -> Vec<String> {
    UPGRADE.iter().chain(extra).map(|s| (*s).to_owned()).collect()
}

#[test]
fn every_viewer_route_requires_the_token() {
    let run = start(ServeConfig {
        token: token(),
        ..ServeConfig::default()
    });
    let addr = run.bound.http.expect("http");
    for path in [
        "/",
        "/js/main.js",
        "/style.css",
        "/favicon.ico",
        "/api/status",
        "/api/graph/1.csv",
        "/nope",
    ] {
        let (code, head, body) = get(addr, path);
        assert_eq!(code, 401, "{path}");
        assert!(head.contains("www-authenticate: bearer"), "{path}: {head}");
        let text = String::from_utf8_lossy(&body);
        assert!(
            text.contains("requires an access token") && text.contains("?token="),
            "{text}"
        );
        assert!(!text.contains(TOKEN));
        let (code, ..) = get(addr, &format!("{path}?token=wrong-token-0000"));
        assert_eq!(code, 401, "{path} with a wrong token");
    }
    let (code, ..) = request(addr, "/ws", &UPGRADE);
    assert_eq!(code, 401, "the WebSocket without the token");

    // Opening the page with ?token= sets the cookie that the rest then carries.
    let (code, head, body) = get(addr, &format!("/?token={TOKEN}"));
    assert_eq!(code, 200);
    assert!(String::from_utf8_lossy(&body).contains("js/main.js"));
    let port = addr.port();
    let set_cookie = head
        .lines()
        .find(|l| l.starts_with("set-cookie:"))
        .unwrap_or_else(|| panic!("no cookie: {head}"));
    assert!(set_cookie.contains(&format!("gantry_token_{port}={}", TOKEN.to_lowercase())));
    for attr in ["httponly", "samesite=strict", "path=/"] {
        assert!(set_cookie.contains(attr), "{set_cookie}");
    }
    assert!(head.contains("referrer-policy: no-referrer"), "{head}");

    let cookie = format!("Cookie: other=1; gantry_token_{port}={TOKEN}");
    for path in ["/js/main.js", "/style.css", "/api/status"] {
        let (code, head, _) = request(addr, path, &[&cookie]);
        assert_eq!(code, 200, "{path} with the cookie");
        assert!(!head.contains("set-cookie"), "only ?token= sets the cookie");
    }
    assert_eq!(
        request(addr, "/api/graph/999999.csv", &[&cookie]).0,
        404,
        "past the gate"
    );
    let (code, _, first) = request(addr, "/ws", &ws_with(&[&cookie]));
    assert_eq!(code, 101, "the WebSocket with the cookie");
    assert_eq!(first, [1], "its first message is text (the scene)");

    // Another gantry's cookie (another port) does not open this one.
    let stale = format!("Cookie: gantry_token_{}={TOKEN}", port.wrapping_add(1));
    assert_eq!(request(addr, "/api/status", &[&stale]).0, 401);
    // Programs use the bearer header.
    let bearer = format!("Authorization: Bearer {TOKEN}");
    assert_eq!(request(addr, "/api/status", &[&bearer]).0, 200);
    assert_eq!(
        request(addr, "/api/status", &["Authorization: Bearer nope-nope-nope"]).0,
        401
    );
}

#[test]
fn a_websocket_from_another_site_is_refused_token_or_not() {
    let run = start(ServeConfig::default());
    let addr = run.bound.http.expect("http");
    let (code, _, body) = request(addr, "/ws", &ws_with(&["Origin: http://evil.example"]));
    assert_eq!(code, 403);
    assert!(String::from_utf8_lossy(&body).contains("another site"));
    let own = format!("Origin: http://{addr}");
    assert_eq!(request(addr, "/ws", &ws_with(&[&own])).0, 101, "the page's own origin");
    assert_eq!(request(addr, "/ws", &UPGRADE).0, 101, "programs send no Origin");
    assert_eq!(get(addr, "/").0, 200, "no token: open as before");
}

#[test]
fn with_a_token_zmq_stays_on_loopback_unless_exposed() {
    let any = IpAddr::V4(Ipv4Addr::UNSPECIFIED);
    let guarded = start(ServeConfig {
        bind: any,
        token: token(),
        ..ServeConfig::default()
    });
    assert_eq!(guarded.bound.text.expect("text").ip(), any);
    assert_eq!(guarded.bound.http.expect("http").ip(), any);
    assert_eq!(guarded.bound.zmq.expect("zmq").ip(), IpAddr::V4(Ipv4Addr::LOCALHOST));
    drop(guarded);

    let exposed = start(ServeConfig {
        bind: any,
        token: token(),
        expose_zmq: true,
        ..ServeConfig::default()
    });
    assert_eq!(exposed.bound.zmq.expect("zmq").ip(), any, "--expose-zmq");
    drop(exposed);

    let open = start(ServeConfig {
        bind: any,
        ..ServeConfig::default()
    });
    assert_eq!(open.bound.zmq.expect("zmq").ip(), any, "no token: unchanged");
}
