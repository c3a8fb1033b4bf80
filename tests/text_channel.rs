//! End-to-end tests of the paper's text command channel against a real gantry process.

use crate::common;

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};

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

/// Issue #9: bytes that are not text at all. Each line gets exactly one `<ERR#...>`
/// reply, in order, even when pipelined in one write; NUL bytes never reach the reply
/// (they would truncate it for C clients); the connection and the arm carry on.
#[test]
fn binary_garbage_and_nul_bytes_get_one_error_per_line() {
    let g = fk_arm();
    let mut c = Client::connect(g.text);
    assert_eq!(c.request("<FK#J1=0.5>"), "<FK#J1=0.5>\n");
    let before = joints(&mut c);
    // Deterministic garbage (xorshift): 60 lines of 1 to 200 bytes, anything but LF and CR
    // (line ends) and starting with NUL so that no line is blank. Lines that happen to be
    // valid UTF-8 reach the packet parser, the others are refused by the line decoder.
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let mut lines: Vec<Vec<u8>> = (0..60)
        .map(|_| {
            let len = 1 + (next() % 200) as usize;
            let mut line = vec![0u8];
            line.extend((1..len).map(|_| next() as u8).filter(|b| !matches!(b, b'\n' | b'\r')));
            line
        })
        .collect();
    // NULs inside otherwise well-formed packets, each refused by the part it breaks.
    let embedded: [(&[u8], &str); 4] = [
        (b"<FK#J1=0\x00.9>", "of key J1 is not a number"),
        (b"<FK#J\x001=0.9>", "invalid key"),
        (b"<F\x00K#J1=0.9>", "invalid command code"),
        (b"\x00<FK#J1=0.9>", "must start with '('"),
    ];
    lines.extend(embedded.iter().map(|(l, _)| l.to_vec()));
    let mut blob = Vec::new();
    for l in &lines {
        blob.extend_from_slice(l);
        blob.push(b'\n');
    }
    c.writer.write_all(&blob).expect("write");
    for (i, line) in lines.iter().enumerate() {
        let reply = c.read_line();
        assert!(
            reply.starts_with("<ERR#") && reply.ends_with(">\n") && !reply.contains('\0'),
            "line {i} {line:?} -> {reply:?}"
        );
        let expected = match embedded.iter().find(|(l, _)| *l == line.as_slice()) {
            Some((_, why)) => *why,
            None if std::str::from_utf8(line).is_ok() => "must start with '('",
            None => "line is not valid UTF-8",
        };
        assert!(
            reply.contains(expected),
            "line {i} {line:?} -> {reply:?}, expected {expected:?}"
        );
    }
    // The same connection is still in step: the next reply answers the next request.
    assert_eq!(
        c.request("<PING#>"),
        "<ERR#unknown command PING; use FK, IK, JOINTS or TIP>\n"
    );
    assert_eq!(joints(&mut c), before, "no garbage line moved the arm");
    assert_eq!(c.request("<FK#J1=0.25>"), "<FK#J1=0.25>\n");
    assert!((joints(&mut c)[0] - 0.25).abs() < 1e-12);
}

/// Issue #9: clients that send half a packet and vanish. Each must release its
/// connection slot and socket; with a limit of 4 connections, 200 of them would lock
/// everybody out if a single one leaked.
#[test]
fn a_half_packet_then_disconnect_leaks_no_connection() {
    let mut g = start("assets/scenes/fk_arm.toml", &["--max-connections", "4"]);
    let pid = g.child.id();
    let mut c = Client::connect(g.text);
    assert_eq!(c.request("<FK#J1=0.25>"), "<FK#J1=0.25>\n");
    let fds0 = open_fds(pid);
    for i in 0..200 {
        let mut s = TcpStream::connect(g.text).expect("connects");
        // A refused connection (slots still held by earlier ones) is fine here; only
        // leaks matter, and they are checked below.
        let _ = s.write_all(format!("<FK#J1=0.{i},J2=").as_bytes());
        if i % 3 == 0 {
            // Some also shut down their write side first, as a client that gives up would.
            let _ = s.shutdown(std::net::Shutdown::Write);
        }
    }
    // Connections still queued behind the listener do not show in the fd count, so first
    // wait until a new client is served: by then every earlier one has been accepted.
    let deadline = Instant::now() + Duration::from_secs(10);
    let _probe = loop {
        if let Some(p) = served(g.text, "<FK#J3=0.1>") {
            break p;
        }
        assert!(Instant::now() < deadline, "no new connection was served again");
        std::thread::sleep(Duration::from_millis(50));
    };
    // Then every socket of the vanished clients must be closed: only `c` and the probe
    // remain.
    while open_fds(pid) > fds0 + 1 {
        assert!(Instant::now() < deadline, "sockets leaked: {fds0} -> {}", open_fds(pid));
        std::thread::sleep(Duration::from_millis(50));
    }
    assert!(g.child.try_wait().expect("wait").is_none(), "gantry is still running");
    // And every slot but those of `c` and the probe is free: two more clients are
    // served at once, reaching the limit of 4.
    let mut others: Vec<Client> = (0..2).map(|_| Client::connect(g.text)).collect();
    for (k, o) in others.iter_mut().enumerate() {
        let line = format!("<FK#J2=0.{k}>");
        assert_eq!(o.request(&line), format!("{line}\n"), "client {k} was refused a slot");
    }
    // No half packet was applied: J1 is where `c` put it.
    assert!((joints(&mut c)[0] - 0.25).abs() < 1e-12);
}

/// A new client whose `line` was served (echoed), or `None` if the connection was
/// refused (too many connections) or reset.
fn served(addr: SocketAddr, line: &str) -> Option<Client> {
    let mut c = Client::connect(addr);
    c.writer.write_all(format!("{line}\n").as_bytes()).ok()?;
    let mut reply = String::new();
    c.reader.read_line(&mut reply).ok()?;
    (reply == format!("{line}\n")).then_some(c)
}

/// Reads the reply to a flood that the server cuts off: the error line, or nothing if
/// the reset that a close with unread input causes overtook it. Either way the
/// connection must end promptly rather than hang or be buffered without bound.
fn refused_or_reset(c: &mut Client) -> Option<String> {
    let mut reply = String::new();
    match c.reader.read_line(&mut reply) {
        Ok(_) => Some(reply),
        Err(e) if e.kind() == std::io::ErrorKind::ConnectionReset => None,
        Err(e) => panic!("the server neither refused nor closed the connection: {e}"),
    }
}

/// Issue #9: a line longer than the 4 KiB limit. The sender gets an error and is
/// disconnected (it is not speaking the protocol); everybody else carries on.
#[test]
fn an_oversize_line_closes_only_that_connection() {
    let g = fk_arm();
    let mut bystander = Client::connect(g.text);
    assert_eq!(bystander.request("<FK#J1=0.5>"), "<FK#J1=0.5>\n");
    // A complete line of 4098 bytes, one packet whose value is too long.
    let mut long = Client::connect(g.text);
    // Written in one go, so that the server has read the whole line, LF included, when
    // it closes (unread input would make the close a reset that can overtake the reply).
    let line = format!("<FK#J1={}>\n", "1".repeat(4090));
    long.writer.write_all(line.as_bytes()).expect("write");
    assert_eq!(
        long.read_line(),
        "<ERR#line longer than 4096 bytes; connection closed>\n"
    );
    assert_eq!(long.reader.read_line(&mut String::new()).expect("eof"), 0, "closed");
    // A megabyte with no newline at all: refused once it passes the limit, not buffered.
    let mut flood = Client::connect(g.text);
    let mut w = flood.writer.try_clone().expect("clone");
    let writer = std::thread::spawn(move || {
        // Fails with a broken pipe once the server has closed; that is the point.
        let _ = w.write_all(&vec![b'A'; 1 << 20]);
    });
    if let Some(reply) = refused_or_reset(&mut flood) {
        assert!(reply.is_empty() || reply.contains("longer than 4096"), "{reply:?}");
    }
    writer.join().expect("writer thread");
    // The bystander and new clients are served as before.
    assert!((joints(&mut bystander)[0] - 0.5).abs() < 1e-12);
    let mut fresh = Client::connect(g.text);
    assert_eq!(fresh.request("<FK#J1=0.75>"), "<FK#J1=0.75>\n");
    assert!((joints(&mut bystander)[0] - 0.75).abs() < 1e-12);
}

/// Issue #9: `nan`, `inf` and values that overflow a double are refused with an error
/// naming the field, and the whole packet is refused: its valid fields are not applied
/// either, so a robot never moves on half a command.
#[test]
fn nan_and_inf_are_refused_naming_the_field() {
    let g = fk_arm();
    let mut c = Client::connect(g.text);
    assert_eq!(c.request("<FK#J1=0.5>"), "<FK#J1=0.5>\n");
    let before = joints(&mut c);
    let cases = [
        ("<FK#J1=nan>", "J1", "nan"),
        ("<FK#J2=0.1,J3=-inf>", "J3", "-inf"),
        ("<FK#j4=NaN,J5=0>", "J4", "NaN"),
        ("<FK#J5=infinity>", "J5", "infinity"),
        ("<FK#J6=1e400>", "J6", "1e400"),
        ("<FK#J2=-1e309>", "J2", "-1e309"),
        ("<IK#TX=nan,TY=0,TZ=0.5>", "TX", "nan"),
    ];
    for (packet, key, value) in cases {
        assert_eq!(
            c.request(packet),
            format!(
                "<ERR#value \"{value}\" of key {key} is not a finite number; \
                 inf, nan and out-of-range values like 1e400 are refused>\n"
            ),
            "{packet}"
        );
    }
    assert_eq!(joints(&mut c), before, "no field of a refused packet was applied");
    assert_eq!(c.request("<FK#J2=0.1>"), "<FK#J2=0.1>\n");
    assert!((joints(&mut c)[1] - 0.1).abs() < 1e-12);
}

/// Issue #9: huge but finite angles are valid numbers. They are clamped to the joint
/// limits or wrapped on cyclic joints, as CoppeliaSim does, and nothing downstream
/// (forward kinematics, the tip pose) overflows.
#[test]
fn huge_joint_angles_are_clamped_or_wrapped_and_the_arm_stays_finite() {
    let g = fk_arm();
    let mut c = Client::connect(g.text);
    let packet = "<FK#J1=1e308,J2=1e308,J3=-1e308,J4=-1.7976931348623157e308,J5=1e308,J6=5e-324>";
    assert_eq!(c.request(packet), format!("{packet}\n"));
    let q = joints(&mut c);
    let pi = std::f64::consts::PI;
    // J1 and J4 are cyclic: wrapped into (-pi, pi].
    for k in [0, 3] {
        assert!(q[k] > -pi && q[k] <= pi, "J{} = {} not wrapped", k + 1, q[k]);
    }
    // J2, J3 and J5 sit on the limits of arm6.urdf.
    assert_eq!(q[1], std::f64::consts::FRAC_PI_2, "J2 at its upper limit");
    assert_eq!(q[2], -0.8726646259971648, "J3 at its lower limit");
    assert_eq!(q[4], 2.0943951023931953, "J5 at its upper limit");
    // The smallest subnormal survives the round trip.
    assert_eq!(q[5], 5e-324);
    let tip = c.request("<TIP#>");
    let v: Vec<f64> = tip
        .trim()
        .trim_start_matches("<TIP#")
        .trim_end_matches('>')
        .split(',')
        .map(|kv| kv.split_once('=').expect("k=v").1.parse().expect("number"))
        .collect();
    assert!(v.len() == 7 && v.iter().all(|x| x.is_finite()), "{tip}");
    // An ordinary command afterwards behaves as usual.
    assert_eq!(c.request("<FK#J1=0.1,J2=0.2>"), "<FK#J1=0.1,J2=0.2>\n");
    let q = joints(&mut c);
    assert!((q[0] - 0.1).abs() < 1e-12 && (q[1] - 0.2).abs() < 1e-12, "{q:?}");
}

/// Issue #9: packets with thousands of fields. Within the line limit they are refused
/// by count (or at the first duplicate key) and the connection stays; beyond it they are
/// oversize lines. The parser stops at the first fault, so none of this costs much.
#[test]
fn thousands_of_fields_are_refused_and_the_arm_is_untouched() {
    let g = fk_arm();
    let mut c = Client::connect(g.text);
    let before = joints(&mut c);
    let distinct: Vec<String> = (0..500).map(|i| format!("K{i}=1")).collect();
    let packet = format!("<FK#J1=0.9,{}>", distinct.join(","));
    assert!(packet.len() < 4096, "fits one line: {} bytes", packet.len());
    assert_eq!(c.request(&packet), "<ERR#too many fields: at most 64 per packet>\n");
    let repeated = format!("<FK#{}>", vec!["A=1"; 1000].join(","));
    assert!(repeated.len() < 4096);
    assert_eq!(
        c.request(&repeated),
        "<ERR#duplicate key A; each key may appear once per packet>\n"
    );
    // 5,000 fields (about 34 KB) on another connection: an oversize line.
    let mut big = Client::connect(g.text);
    let fields: Vec<String> = (0..5000).map(|i| format!("K{i}=1")).collect();
    let _ = big.writer.write_all(format!("<FK#{}>\n", fields.join(",")).as_bytes());
    if let Some(reply) = refused_or_reset(&mut big) {
        assert!(reply.is_empty() || reply.contains("longer than 4096"), "{reply:?}");
    }
    assert_eq!(joints(&mut c), before, "J1=0.9 of the refused packet was not applied");
    assert_eq!(c.request("<FK#J1=0.3>"), "<FK#J1=0.3>\n");
    assert!((joints(&mut c)[0] - 0.3).abs() < 1e-12);
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
