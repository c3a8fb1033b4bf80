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
//! `<ERR#...>` line and the connection carries on, except an oversize line, after
//! which the connection is closed.

use std::sync::Arc;
use std::time::Duration;

use gantry_protocol::{LineDecoder, LineError, Packet, encode_error, parse_packet};
use gantry_sim_core::Value;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::{Semaphore, oneshot, watch};

use crate::sim_thread::{PacketOutcome, Request, SimHandle};

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

/// Accepts connections until `shutdown` turns true.
pub async fn serve(listener: TcpListener, sim: SimHandle, cfg: TextConfig, mut shutdown: watch::Receiver<bool>) {
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
                            let (sim, cfg, shutdown) = (sim.clone(), cfg.clone(), shutdown.clone());
                            tokio::spawn(async move {
                                connection(sock, next_id, sim, cfg, shutdown).await;
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

async fn connection(sock: TcpStream, id: i64, sim: SimHandle, cfg: TextConfig, mut shutdown: watch::Receiver<bool>) {
    let _ = sock.set_nodelay(true);
    let (mut rd, mut wr) = sock.into_split();
    let mut decoder = LineDecoder::with_max_len(cfg.max_line);
    let mut buf: Vec<u8> = Vec::with_capacity(512);
    let mut chunk = [0u8; 4096];
    loop {
        loop {
            let reply = match decoder.decode(&mut buf) {
                Ok(Some(line)) => handle_line(&line, id, &sim).await,
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
        tokio::select! {
            _ = shutdown.changed() => return,
            read = tokio::time::timeout(cfg.idle_timeout, rd.read(&mut chunk)) => match read {
                // Idle too long, closed by the peer (a half packet is dropped), or broken.
                Err(_) | Ok(Ok(0)) | Ok(Err(_)) => return,
                Ok(Ok(n)) => buf.extend_from_slice(&chunk[..n]),
            }
        }
    }
}

/// The reply line (with its newline) to one received line.
async fn handle_line(line: &str, client: i64, sim: &SimHandle) -> String {
    if line.trim().is_empty() {
        // CoppeliaSim's server echoes whatever it received, an empty line included.
        return "\n".into();
    }
    format!("{}\n", deliver(line, client, sim).await)
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
