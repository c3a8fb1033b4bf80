//! The text command channel: the paper's `<CODE#KEY=VALUE,...>` packets over TCP.
//!
//! Both client styles work at once: a new connection per command (the paper's C#
//! client writes one line byte by byte, reads at most 100 bytes and closes) and
//! persistent connections carrying many packets. Lines end in LF; CRs are dropped.
//! Each well-formed packet goes to the scripts' `sysCall_packet(packet)` on the
//! simulation thread, which serves it between steps as soon as it arrives. The packet
//! table has `code` (upper case), `fields` (by upper-case key), `ordered` (an array of
//! `{key=, value=}` in packet order), `raw` (the line as received) and `client` (a
//! connection id). The hook's returned string is the reply; with no return value the
//! reply is the packet echoed (the paper's acknowledgement). Every problem gets an
//! `<ERR#...>` line and the connection carries on, except an oversize line, an HTTP
//! request line (a browser pointed at this port: closing stops a web page from smuggling
//! packets in a request body) and a failed authentication, after which the connection
//! is closed.
//!
//! With an access token (`--token`), the first line of every connection must be
//! `<AUTH#TOKEN>`, answered `<AUTH#OK>`, within [`AUTH_TIMEOUT`]; anything else is
//! answered with an `<ERR#...>` and the connection closed. Without a token, an
//! `<AUTH#...>` line is answered `<AUTH#OK>` too, so a client may always authenticate.

use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;

use gantry_protocol::{LineDecoder, LineError, Packet, encode_error, parse_packet};
use gantry_sim_core::Value;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::{Semaphore, oneshot, watch};
use tokio::time::Instant;

use crate::auth::AccessToken;
use crate::sim_thread::{PacketOutcome, Request, SimHandle};

/// Time a connection has, from accept, to authenticate when a token is set. Shorter than
/// the idle timeout and counted once (not per read), so connections that never
/// authenticate cannot hold the connection slots for long.
pub const AUTH_TIMEOUT: Duration = Duration::from_secs(10);

/// The reply to a correct `<AUTH#TOKEN>` line.
pub const AUTH_OK: &str = "<AUTH#OK>";

/// Limits of the text channel.
#[derive(Debug, Clone)]
pub struct TextConfig {
    /// Most simultaneous connections; the next one gets an `<ERR#...>` and is closed.
    pub max_connections: usize,
    /// A connection that sends nothing for this long is closed.
    pub idle_timeout: Duration,
    /// Longest line in bytes.
    pub max_line: usize,
}

impl Default for TextConfig {
    fn default() -> Self {
        Self {
            max_connections: 256,
            idle_timeout: Duration::from_secs(60),
            max_line: 4096,
        }
    }
}

/// Accepts connections until `shutdown` turns true. With `token`, each connection must
/// authenticate first (see the module documentation).
pub async fn serve(
    listener: TcpListener,
    sim: SimHandle,
    cfg: TextConfig,
    token: Option<AccessToken>,
    mut shutdown: watch::Receiver<bool>,
) {
    let slots = Arc::new(Semaphore::new(cfg.max_connections));
    let mut next_id: i64 = 0;
    loop {
        tokio::select! {
            _ = shutdown.changed() => break,
            accepted = listener.accept() => match accepted {
                Ok((sock, peer)) => {
                    next_id += 1;
                    match slots.clone().try_acquire_owned() {
                        Ok(permit) => {
                            let (sim, cfg, token, shutdown) = (sim.clone(), cfg.clone(), token.clone(), shutdown.clone());
                            tokio::spawn(async move {
                                let authenticated = token.is_none();
                                let client = Client { id: next_id, peer, token, authenticated };
                                connection(sock, client, sim, cfg, shutdown).await;
                                drop(permit);
                            });
                        }
                        Err(_) => {
                            tracing::warn!("text channel: refusing {peer}: {} connections already open", cfg.max_connections);
                            let msg = format!(
                                "{}\n",
                                encode_error(&format!("too many connections (limit {}); close one and retry", cfg.max_connections))
                            );
                            tokio::spawn(async move {
                                let mut sock = sock;
                                let _ = tokio::time::timeout(Duration::from_secs(1), sock.write_all(msg.as_bytes())).await;
                            });
                        }
                    }
                }
                Err(e) => {
                    // Out of file descriptors and the like: back off instead of spinning.
                    tracing::warn!("text channel: accept failed: {e}");
                    tokio::time::sleep(Duration::from_millis(50)).await;
                }
            }
        }
    }
}

/// Who is on the other end of a connection.
struct Client {
    /// `packet.client` for scripts.
    id: i64,
    /// For log lines.
    peer: SocketAddr,
    /// The token this connection must present first, if one is set.
    token: Option<AccessToken>,
    /// Whether it has (always true without a token).
    authenticated: bool,
}

/// What the connection does with one received line.
enum Verdict {
    /// Send this reply (with its newline) and read on.
    Reply(String),
    /// Send this reply and close the connection.
    Close(String),
}

async fn connection(
    sock: TcpStream,
    mut client: Client,
    sim: SimHandle,
    cfg: TextConfig,
    mut shutdown: watch::Receiver<bool>,
) {
    let _ = sock.set_nodelay(true);
    let (mut rd, mut wr) = sock.into_split();
    let mut decoder = LineDecoder::with_max_len(cfg.max_line);
    let mut buf: Vec<u8> = Vec::with_capacity(512);
    let mut chunk = [0u8; 4096];
    let auth_deadline = Instant::now() + AUTH_TIMEOUT;
    let mut first = true;
    loop {
        loop {
            let reply = match decoder.decode(&mut buf) {
                Ok(Some(line)) => {
                    let verdict = if first { first_line(&line, &mut client) } else { None };
                    first = false;
                    match verdict {
                        Some(Verdict::Reply(r)) => r,
                        Some(Verdict::Close(r)) => {
                            let _ = wr.write_all(r.as_bytes()).await;
                            return;
                        }
                        None => handle_line(&line, &client, &sim).await,
                    }
                }
                Ok(None) => break,
                Err(LineError::TooLong { max }) => {
                    let msg = format!(
                        "{}\n",
                        encode_error(&format!("line longer than {max} bytes; connection closed"))
                    );
                    let _ = wr.write_all(msg.as_bytes()).await;
                    return;
                }
                Err(e @ LineError::InvalidUtf8 { .. }) => format!("{}\n", encode_error(&e.to_string())),
            };
            if wr.write_all(reply.as_bytes()).await.is_err() {
                return;
            }
        }
        let deadline = if client.authenticated {
            Instant::now() + cfg.idle_timeout
        } else {
            auth_deadline.min(Instant::now() + cfg.idle_timeout)
        };
        tokio::select! {
            _ = shutdown.changed() => return,
            read = tokio::time::timeout_at(deadline, rd.read(&mut chunk)) => match read {
                Err(_) if !client.authenticated => {
                    let limit = AUTH_TIMEOUT.min(cfg.idle_timeout);
                    tracing::warn!("text channel: closing {}: no access token within {limit:?}", client.peer);
                    let msg = format!(
                        "{}\n",
                        encode_error(&format!("access token required within {limit:?}; connection closed"))
                    );
                    let _ = wr.write_all(msg.as_bytes()).await;
                    return;
                }
                // Idle too long, closed by the peer (a half packet is dropped), or broken.
                Err(_) | Ok(Ok(0)) | Ok(Err(_)) => return,
                Ok(Ok(n)) => buf.extend_from_slice(&chunk[..n]),
            }
        }
    }
}

/// Checks the first line of a connection: refuses HTTP, and with a token requires
/// `<AUTH#TOKEN>`. `None`: an ordinary line, handled as any other.
fn first_line(line: &str, client: &mut Client) -> Option<Verdict> {
    if is_http_request(line) {
        tracing::warn!("text channel: closing {}: it sent an HTTP request", client.peer);
        return Some(Verdict::Close(format!(
            "{}\n",
            encode_error("this is gantry's text channel, not HTTP (the viewer has its own port); connection closed")
        )));
    }
    let token = client.token.as_ref().filter(|_| !client.authenticated)?;
    let verdict = match auth_request(line) {
        Some(candidate) if token.matches(candidate.as_bytes()) => {
            client.authenticated = true;
            return Some(Verdict::Reply(format!("{AUTH_OK}\n")));
        }
        Some(_) => "wrong access token; connection closed",
        None => "access token required: send <AUTH#TOKEN> as the first line; connection closed",
    };
    // The peer and the reason, never what was sent: it may be a near-miss token.
    tracing::warn!("text channel: closing {}: {verdict}", client.peer);
    Some(Verdict::Close(format!("{}\n", encode_error(verdict))))
}

/// The reply line (with its newline) to one received line after the first.
async fn handle_line(line: &str, client: &Client, sim: &SimHandle) -> String {
    if line.trim().is_empty() {
        // CoppeliaSim's server echoes whatever it received, an empty line included.
        return "\n".into();
    }
    if let Some(candidate) = auth_request(line) {
        // Authenticated already, or no token is set: a repeated `<AUTH#...>` is
        // acknowledged when right and answered with an error (nothing closes) when wrong.
        return match &client.token {
            Some(t) if !t.matches(candidate.as_bytes()) => format!("{}\n", encode_error("wrong access token")),
            _ => format!("{AUTH_OK}\n"),
        };
    }
    format!("{}\n", deliver(line, client.id, sim).await)
}

/// The token offered by an `<AUTH#TOKEN>` line (code case-insensitive, spaces around
/// the parts tolerated as in other packets), or `None` for any other line.
fn auth_request(line: &str) -> Option<&str> {
    let inner = line.trim().strip_prefix('<')?.strip_suffix('>')?;
    let (code, token) = inner.split_once('#')?;
    code.trim().eq_ignore_ascii_case("AUTH").then(|| token.trim())
}

/// Whether `line` is an HTTP request line such as `GET / HTTP/1.1`.
fn is_http_request(line: &str) -> bool {
    let mut parts = line.trim_end().split(' ');
    match (parts.next(), parts.next(), parts.next(), parts.next()) {
        (Some(method), Some(_target), Some(version), None) => {
            !method.is_empty() && method.bytes().all(|b| b.is_ascii_uppercase()) && version.starts_with("HTTP/")
        }
        _ => false,
    }
}

/// Parses one packet line, delivers it to the scripts' `sysCall_packet` on the
/// simulation thread and returns the reply without its newline: the hook's string, the
/// line echoed when the hook returns nothing, or an `<ERR#...>`. The viewer's joint and
/// IK panels use this too, so both transports behave the same.
pub async fn deliver(line: &str, client: i64, sim: &SimHandle) -> String {
    let packet = match parse_packet(line) {
        Ok(p) => p,
        Err(e) => return encode_error(&e.to_string()),
    };
    let (reply, rx) = oneshot::channel();
    if let Err(e) = sim.send(Request::Packet {
        packet: packet_value(&packet, client),
        reply,
    }) {
        return encode_error(&e.to_string());
    }
    match rx.await {
        Ok(PacketOutcome::Reply(s)) => s.trim_end_matches(['\r', '\n']).to_owned(),
        Ok(PacketOutcome::Handled) => line.to_owned(),
        Ok(PacketOutcome::NoHandler) => {
            encode_error("no script handles packets: attach a script that defines sysCall_packet(packet)")
        }
        Ok(PacketOutcome::Error(e)) => encode_error(&format!("script error: {}", e.lines().next().unwrap_or_default())),
        Err(_) => encode_error("the simulation has ended"),
    }
}

/// The packet as the table scripts receive.
pub fn packet_value(p: &Packet, client: i64) -> Value {
    let fields = p
        .fields
        .iter()
        .map(|f| (Value::Str(f.key.clone()), Value::Float(f.value)))
        .collect();
    let ordered = p
        .fields
        .iter()
        .map(|f| {
            Value::Map(vec![
                (Value::from("key"), Value::Str(f.key.clone())),
                (Value::from("value"), Value::Float(f.value)),
            ])
        })
        .collect();
    Value::Map(vec![
        (Value::from("code"), Value::Str(p.code.clone())),
        (Value::from("fields"), Value::Map(fields)),
        (Value::from("ordered"), Value::Array(ordered)),
        (Value::from("raw"), Value::Str(p.raw.clone())),
        (Value::from("client"), Value::Int(client)),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auth_lines_are_recognised() {
        assert_eq!(auth_request("<AUTH#abc123>"), Some("abc123"));
        assert_eq!(auth_request(" < auth # abc123 > "), Some("abc123"));
        assert_eq!(auth_request("<AUTH#>"), Some(""));
        assert_eq!(auth_request("<FK#J1=0>"), None);
        assert_eq!(auth_request("AUTH#abc123"), None);
        assert_eq!(auth_request("<AUTHX#abc123>"), None);
    }

    #[test]
    fn http_request_lines_are_recognised() {
        assert!(is_http_request("GET / HTTP/1.1"));
        assert!(is_http_request("POST /x?y=1 HTTP/1.0\r"));
        assert!(!is_http_request("<FK#J1=0>"));
        assert!(!is_http_request("get / HTTP/1.1"));
        assert!(!is_http_request("GET /"));
        assert!(!is_http_request(""));
    }

    fn client(token: Option<&str>) -> Client {
        Client {
            id: 1,
            peer: SocketAddr::from(([127, 0, 0, 1], 1)),
            token: token.map(|t| AccessToken::new(t).expect("valid")),
            authenticated: token.is_none(),
        }
    }

    #[test]
    fn the_first_line_gate() {
        let mut c = client(Some("right-token"));
        assert!(matches!(first_line("<AUTH#right-token>", &mut c), Some(Verdict::Reply(r)) if r == "<AUTH#OK>\n"));
        assert!(c.authenticated);
        let mut c = client(Some("right-token"));
        assert!(
            matches!(first_line("<AUTH#wrong-token>", &mut c), Some(Verdict::Close(r)) if r.contains("wrong access token"))
        );
        assert!(
            matches!(first_line("<FK#J1=0>", &mut c), Some(Verdict::Close(r)) if r.contains("access token required"))
        );
        let mut open = client(None);
        assert!(
            first_line("<FK#J1=0>", &mut open).is_none(),
            "no token: an ordinary line"
        );
        assert!(matches!(first_line("GET / HTTP/1.1", &mut open), Some(Verdict::Close(r)) if r.contains("not HTTP")));
    }
}
