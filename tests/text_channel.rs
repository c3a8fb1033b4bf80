//! End-to-end tests of the paper's text command channel against a real gantry process.

mod common;

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::Duration;

use common::{Gantry, open_fds, rss_kib, start};

/// A persistent line client.
struct Client {
    writer: TcpStream,
    reader: BufReader<TcpStream>,
}

impl Client {
    fn connect(addr: SocketAddr) -> Self {
        let s = TcpStream::connect(addr).expect("connects");
        s.set_read_timeout(Some(Duration::from_secs(20))).expect("timeout");
        s.set_nodelay(true).expect("nodelay");
        Client {
            writer: s.try_clone().expect("clone"),
            reader: BufReader::new(s),
        }
    }

    fn request(&mut self, line: &str) -> String {
        self.writer.write_all(line.as_bytes()).expect("write");
        self.writer.write_all(b"\n").expect("write");
        self.read_line()
    }

    fn read_line(&mut self) -> String {
        let mut reply = String::new();
        self.reader.read_line(&mut reply).expect("reply");
        reply
    }
}

fn joints(c: &mut Client) -> Vec<f64> {
    let reply = c.request("<JOINTS#>");
    let body = reply.trim().trim_start_matches("<JOINTS#").trim_end_matches('>');
    body.split(',')
        .map(|kv| kv.split_once('=').expect("key=value").1.parse().expect("number"))
        .collect()
}

/// The paper's C# client: connect, write the line one byte at a time with CRLF, read
/// at most 100 bytes, close.
fn csharp_style(addr: SocketAddr, line: &str) -> Vec<u8> {
    let mut s = TcpStream::connect(addr).expect("connects");
    s.set_read_timeout(Some(Duration::from_secs(10))).expect("timeout");
    for b in line.bytes().chain(*b"\r\n") {
        s.write_all(&[b]).expect("byte");
    }
    let mut buf = [0u8; 100];
    let n = s.read(&mut buf).expect("reply");
    buf[..n].to_vec()
}

fn fk_arm() -> Gantry {
    start("assets/scenes/fk_arm.toml", &[])
}

#[test]
fn csharp_client_moves_the_arm_without_leaking() {
    let g = fk_arm();
    let pid = g.child.id();
    // Warm up, then measure resources across 2,000 one-shot connections.
    for _ in 0..50 {
        csharp_style(g.text, "<FK#J1=0,J2=0,J3=0,J4=0,J5=0,J6=0>");
    }
    let (fds0, rss0) = (open_fds(pid), rss_kib(pid));
    for i in 0..2000 {
        let q = (i as f64) * 1e-4;
        let line = format!("<FK#J1={q},J2=0.1,J3=-0.2,J4=0.3,J5=-1.0,J6=0.5>");
        let reply = csharp_style(g.text, &line);
        // The acknowledgement is the packet echoed; the client reads at most 100 bytes.
        let expected = format!("{line}\n");
        let n = expected.len().min(100);
        assert_eq!(reply, expected.as_bytes()[..n], "reply to packet {i}");
    }
    let mut c = Client::connect(g.text);
    let q = joints(&mut c);
    assert!(
        (q[0] - 0.1999).abs() < 1e-9 && (q[4] + 1.0).abs() < 1e-12,
        "arm followed: {q:?}"
    );
    drop(c);
    std::thread::sleep(Duration::from_millis(300));
    let (fds1, rss1) = (open_fds(pid), rss_kib(pid));
    eprintln!("fds {fds0} -> {fds1}, rss {rss0} KiB -> {rss1} KiB");
    assert!(fds1 <= fds0 + 2, "sockets leaked: {fds0} -> {fds1}");
    assert!(
        rss1 < rss0 + 16 * 1024,
        "memory grew by {} KiB over 2,000 connections",
        rss1.saturating_sub(rss0)
    );
}

#[test]
fn persistent_client_and_read_backs() {
    let g = fk_arm();
    let mut c = Client::connect(g.text);
    let fk = "<FK#J1=0.5, J2=0.25,J3=-0.5,J4=1,J5=-1.2,J6=3.5>";
    // Spaces are tolerated; the echo is the packet as received.
    assert_eq!(c.request(fk), format!("{fk}\n"));
    let q = joints(&mut c);
    // J6 is cyclic: 3.5 rad wraps to 3.5 - 2 pi.
    let expected = [0.5, 0.25, -0.5, 1.0, -1.2, 3.5 - std::f64::consts::TAU];
    for (a, b) in q.iter().zip(expected) {
        assert!((a - b).abs() < 1e-9, "{q:?} vs {expected:?}");
    }
    // Clamping: J2's upper limit is 90 degrees.
    c.request("<FK#J2=3>");
    assert!((joints(&mut c)[1] - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    let tip = c.request("<TIP#>");
    assert!(tip.starts_with("<TIP#X=") && tip.contains(",QW="), "{tip}");
    // IK: the tip goes to the requested point, keeping the tool pointing down.
    assert_eq!(
        c.request("<IK#TX=0.40,TY=0.1,TZ=0.5,RX=0,RY=0,RZ=0>"),
        "<IK#TX=0.40,TY=0.1,TZ=0.5,RX=0,RY=0,RZ=0>\n"
    );
    let tip = c.request("<TIP#>");
    let v: Vec<f64> = tip
        .trim()
        .trim_start_matches("<TIP#")
        .trim_end_matches('>')
        .split(',')
        .map(|kv| kv.split_once('=').expect("k=v").1.parse().expect("number"))
        .collect();
    let err = ((v[0] - 0.40).powi(2) + (v[1] - 0.1).powi(2) + (v[2] - 0.5).powi(2)).sqrt();
    assert!(err < 1e-3, "tip {v:?} misses the IK target by {err} m");
    assert!(
        c.request("<IK#TX=3,TY=0,TZ=0>")
            .starts_with("<ERR#IK target out of reach")
    );
    // Case-insensitive keys and codes.
    assert_eq!(c.request("<fk#j1=0>"), "<fk#j1=0>\n");
    for _ in 0..500 {
        assert!(c.request("<JOINTS#>").starts_with("<JOINTS#J1=0,"));
    }
}

#[test]
fn malformed_packets_get_errors_and_everything_carries_on() {
    let g = fk_arm();
    let mut c = Client::connect(g.text);
    let cases = [
        ("FK#J1=0", "must start with"),
        ("<FK J1=0>", "#"),
        ("<FK#J1=abc>", "not a number"),
        ("<FK#J1=0,785>", "comma used as decimal separator"),
        ("<FK#J1=nan>", "finite"),
        ("<FK#J1=inf>", "finite"),
        ("<FK#J1=1e400>", "finite"),
        ("<FK#J1>", "="),
        ("<#J1=0>", "code"),
        ("<XX#A=1>", "unknown command"),
        ("\u{1}\u{2}\u{3}garbage\u{7f}", "ERR"),
    ];
    for (packet, needle) in cases {
        let reply = c.request(packet);
        assert!(
            reply.starts_with("<ERR#") && reply.ends_with(">\n"),
            "{packet:?} -> {reply:?}"
        );
        assert!(
            reply.contains(needle),
            "{packet:?} -> {reply:?} should mention {needle:?}"
        );
    }
    let many: Vec<String> = (0..100).map(|i| format!("K{i}=1")).collect();
    let reply = c.request(&format!("<FK#{}>", many.join(",")));
    assert!(reply.starts_with("<ERR#") && reply.contains("64"), "{reply}");
    // Invalid UTF-8 is refused on its line only.
    c.writer.write_all(b"<FK#J1=\xff\xfe>\n").expect("write");
    assert!(c.read_line().starts_with("<ERR#"));
    // The connection and the script still work.
    assert_eq!(c.request("<FK#J1=0.25>"), "<FK#J1=0.25>\n");
    assert!((joints(&mut c)[0] - 0.25).abs() < 1e-12);
    // A half packet then disconnect disturbs nobody.
    {
        let mut s = TcpStream::connect(g.text).expect("connects");
        s.write_all(b"<FK#J1=0.9,J2=").expect("write");
    }
    // An oversize line gets an error and the connection is closed.
    let mut big = Client::connect(g.text);
    big.writer.write_all(&vec![b'A'; 5000]).expect("write");
    let reply = big.read_line();
    assert!(reply.contains("longer than 4096"), "{reply}");
    assert_eq!(
        big.reader.read_line(&mut String::new()).expect("eof"),
        0,
        "closed after an oversize line"
    );
    assert!(
        (joints(&mut c)[0] - 0.25).abs() < 1e-12,
        "the half packet was not applied"
    );
}

#[test]
fn hundred_concurrent_clients_get_their_replies_in_order() {
    let g = fk_arm();
    let addr = g.text;
    let threads: Vec<_> = (0..100)
        .map(|t| {
            std::thread::spawn(move || {
                let mut c = Client::connect(addr);
                for i in 0..1000 {
                    let line = format!("<FK#J1={},J2=0.{t}>", i as f64 * 1e-3);
                    let reply = c.request(&line);
                    assert_eq!(reply, format!("{line}\n"), "client {t} packet {i}");
                }
            })
        })
        .collect();
    for t in threads {
        t.join().expect("client thread");
    }
}

#[test]
fn connection_limit_refuses_clearly() {
    let g = start("assets/scenes/fk_arm.toml", &["--max-connections", "4"]);
    let held: Vec<Client> = (0..4).map(|_| Client::connect(g.text)).collect();
    std::thread::sleep(Duration::from_millis(200));
    let mut extra = Client::connect(g.text);
    let reply = extra.read_line();
    assert!(reply.starts_with("<ERR#too many connections"), "{reply}");
    drop(held);
    std::thread::sleep(Duration::from_millis(200));
    let mut c = Client::connect(g.text);
    assert_eq!(c.request("<FK#J1=0>"), "<FK#J1=0>\n");
}

#[test]
fn no_handler_is_an_error() {
    let g = start("assets/scenes/bubble_rob.toml", &[]);
    let mut c = Client::connect(g.text);
    let reply = c.request("<FK#J1=0>");
    assert!(reply.starts_with("<ERR#no script handles packets"), "{reply}");
}
