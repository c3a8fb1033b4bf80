//! ZMTP 3 commands: `READY` (the NULL mechanism's handshake, with the socket type),
//! `ERROR`, and the heartbeat pair `PING`/`PONG` (ZMTP 3.1). Each command owns both
//! directions: [`Command::parse`] from a command frame's body and [`Command::encode`]
//! to a whole frame.
//!
//! A command body is a 1-byte name length, the name, then data; `READY` data is a list
//! of properties, each a 1-byte name length, the name, a 4-byte big-endian value length
//! and the value.

use bytes::{Buf, Bytes};

use super::frame::encode_raw;
use super::rules::Violation;
pub use super::socket_type::SocketType;

/// The properties of a `READY` command that gantry reads; others (application
/// metadata such as `X-...`) are skipped.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Ready {
    /// The sender's socket type.
    pub socket_type: SocketType,
    /// The sender's routing identity (REQ and DEALER peers may set one); empty when
    /// none was sent.
    pub identity: Bytes,
}

/// Longest `Identity` (RFC 37: 0 to 255 bytes).
const MAX_IDENTITY_LEN: usize = 255;
/// Longest `PING` context (ZMTP 3.1: up to 16 bytes, echoed in the `PONG`).
const MAX_PING_CONTEXT: usize = 16;

/// One command.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Command {
    /// `READY`: the NULL handshake; each side sends it once, right after the greeting.
    Ready(Ready),
    /// `ERROR`: the peer refuses the connection and closes it, with a reason.
    Error {
        /// Why (at most 255 bytes; text in practice).
        reason: Bytes,
    },
    /// `PING` (ZMTP 3.1 heartbeat): answered with a `PONG` carrying `context`.
    Ping {
        /// The sender's time-to-live for the connection, in tenths of a second.
        ttl: u16,
        /// Up to 16 bytes to echo.
        context: Bytes,
    },
    /// `PONG`: the answer to a `PING`.
    Pong {
        /// The context of the `PING`.
        context: Bytes,
    },
    /// Any other command (`SUBSCRIBE`, `CANCEL`, or one from a later version): a
    /// ROUTER ignores it.
    Other {
        /// The command's name (1 to 255 bytes).
        name: Bytes,
        /// Its data, unread.
        data: Bytes,
    },
}

/// A [`Violation::MalformedCommand`] for the command named `name`.
fn malformed(name: &[u8], problem: &'static str) -> Violation {
    Violation::MalformedCommand {
        command: String::from_utf8_lossy(name).into_owned(),
        problem,
    }
}

impl Command {
    /// Parses a command frame's body (without the frame header).
    ///
    /// # Errors
    /// [`Violation::MalformedCommand`] for a body that does not hold what its command
    /// needs, and [`Violation::UnknownSocketType`] for a `READY` naming no ZeroMQ
    /// socket type.
    pub fn parse(mut body: Bytes) -> Result<Self, Violation> {
        let name = take_short(&mut body).ok_or_else(|| malformed(b"a", "the name runs past the frame"))?;
        if name.is_empty() {
            return Err(malformed(b"a", "the name is empty"));
        }
        Ok(match &name[..] {
            b"READY" => Command::Ready(parse_ready(body)?),
            b"ERROR" => {
                let reason = take_short(&mut body).ok_or_else(|| malformed(&name, "the reason runs past the frame"))?;
                Command::Error { reason }
            }
            b"PING" => {
                if body.len() < 2 {
                    return Err(malformed(&name, "no time-to-live"));
                }
                let ttl = body.get_u16();
                if body.len() > MAX_PING_CONTEXT {
                    return Err(malformed(&name, "a context longer than 16 bytes"));
                }
                Command::Ping { ttl, context: body }
            }
            b"PONG" => {
                if body.len() > MAX_PING_CONTEXT {
                    return Err(malformed(&name, "a context longer than 16 bytes"));
                }
                Command::Pong { context: body }
            }
            _ => Command::Other { name, data: body },
        })
    }

    /// Appends this command as a whole command frame.
    ///
    /// Values that RFC 37 bounds (an identity or reason over 255 bytes, a context over
    /// 16) are cut to the bound, so the frame is always one a peer accepts.
    pub fn encode(&self, out: &mut Vec<u8>) {
        let mut body = Vec::new();
        match self {
            Command::Ready(ready) => {
                put_short(&mut body, b"READY");
                put_property(&mut body, b"Socket-Type", ready.socket_type.name().as_bytes());
                if !ready.identity.is_empty() {
                    put_property(&mut body, b"Identity", cut(&ready.identity, MAX_IDENTITY_LEN));
                }
            }
            Command::Error { reason } => {
                put_short(&mut body, b"ERROR");
                put_short(&mut body, reason);
            }
            Command::Ping { ttl, context } => {
                put_short(&mut body, b"PING");
                body.extend_from_slice(&ttl.to_be_bytes());
                body.extend_from_slice(cut(context, MAX_PING_CONTEXT));
            }
            Command::Pong { context } => {
                put_short(&mut body, b"PONG");
                body.extend_from_slice(cut(context, MAX_PING_CONTEXT));
            }
            Command::Other { name, data } => {
                put_short(&mut body, if name.is_empty() { b"?" } else { name });
                body.extend_from_slice(data);
            }
        }
        encode_raw(out, &body, false, true);
    }
}

/// The first `max` bytes of `b`.
fn cut(b: &[u8], max: usize) -> &[u8] {
    &b[..b.len().min(max)]
}

/// Takes a 1-byte length and that many bytes; `None` if they run past `body`.
fn take_short(body: &mut Bytes) -> Option<Bytes> {
    let len = usize::from(*body.first()?);
    if body.len() < 1 + len {
        return None;
    }
    body.advance(1);
    Some(body.split_to(len))
}

/// Appends a 1-byte length and `b` (cut to 255 bytes).
fn put_short(out: &mut Vec<u8>, b: &[u8]) {
    let b = cut(b, usize::from(u8::MAX));
    // At most 255 after the cut.
    out.push(b.len() as u8);
    out.extend_from_slice(b);
}

fn put_property(out: &mut Vec<u8>, name: &[u8], value: &[u8]) {
    put_short(out, name);
    // Values gantry writes are at most 255 bytes.
    out.extend_from_slice(&(value.len() as u32).to_be_bytes());
    out.extend_from_slice(value);
}

/// The properties of a `READY` body (after its name).
fn parse_ready(mut body: Bytes) -> Result<Ready, Violation> {
    let bad = |problem| malformed(b"READY", problem);
    let mut socket_type = None;
    let mut identity = Bytes::new();
    while !body.is_empty() {
        let name = take_short(&mut body).ok_or_else(|| bad("a property name runs past the frame"))?;
        if body.len() < 4 {
            return Err(bad("a property has no value length"));
        }
        // Bounded by the frame (MAX_FRAME_LEN), checked against what is left below.
        let len = usize::try_from(body.get_u32()).unwrap_or(usize::MAX);
        if body.len() < len {
            return Err(bad("a property value runs past the frame"));
        }
        let value = body.split_to(len);
        // Property names are case-insensitive (RFC 37).
        if name.eq_ignore_ascii_case(b"Socket-Type") {
            socket_type = Some(
                SocketType::from_name(&value)
                    .ok_or_else(|| Violation::UnknownSocketType(String::from_utf8_lossy(&value).into_owned()))?,
            );
        } else if name.eq_ignore_ascii_case(b"Identity") {
            if value.len() > MAX_IDENTITY_LEN {
                return Err(bad("the identity is longer than 255 bytes"));
            }
            identity = value;
        }
    }
    let socket_type = socket_type.ok_or_else(|| bad("no Socket-Type property"))?;
    Ok(Ready { socket_type, identity })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::zmtp::frame::Header;

    /// The body of a command frame encoded by `c`.
    fn body_of(c: &Command) -> Bytes {
        let mut out = Vec::new();
        c.encode(&mut out);
        let h = Header::parse(&out).unwrap().unwrap();
        assert!(h.command && !h.more);
        assert_eq!(out.len(), h.header_len + h.body_len);
        Bytes::from(out).slice(h.header_len..)
    }

    #[test]
    fn libzmqs_ready_parses() {
        // What libzmq 4.3's REQ socket sends.
        let body = b"\x05READY\x0bSocket-Type\x00\x00\x00\x03REQ\x08Identity\x00\x00\x00\x00";
        assert_eq!(
            Command::parse(Bytes::from_static(body)),
            Ok(Command::Ready(Ready {
                socket_type: SocketType::Req,
                identity: Bytes::new()
            }))
        );
        // Names in any case, other properties skipped, an identity kept.
        let body = b"\x05READY\x07X-Hello\x00\x00\x00\x02hi\x0bsocket-type\x00\x00\x00\x06DEALER\x08IDENTITY\x00\x00\x00\x02id";
        assert_eq!(
            Command::parse(Bytes::from_static(body)),
            Ok(Command::Ready(Ready {
                socket_type: SocketType::Dealer,
                identity: Bytes::from_static(b"id")
            }))
        );
    }

    #[test]
    fn every_command_round_trips() {
        let commands = [
            Command::Ready(Ready {
                socket_type: SocketType::Router,
                identity: Bytes::new(),
            }),
            Command::Ready(Ready {
                socket_type: SocketType::Req,
                identity: Bytes::from_static(b"\x01me"),
            }),
            Command::Error {
                reason: Bytes::from_static(b"invalid socket type"),
            },
            Command::Ping {
                ttl: 300,
                context: Bytes::from_static(b"ctx"),
            },
            Command::Pong { context: Bytes::new() },
            Command::Other {
                name: Bytes::from_static(b"SUBSCRIBE"),
                data: Bytes::from_static(b"topic"),
            },
        ];
        for c in commands {
            assert_eq!(Command::parse(body_of(&c)), Ok(c.clone()), "{c:?}");
        }
    }

    #[test]
    fn values_over_their_bounds_are_cut_when_encoded() {
        let long = Bytes::from(vec![b'x'; 400]);
        let c = Command::Error { reason: long.clone() };
        assert_eq!(
            Command::parse(body_of(&c)),
            Ok(Command::Error {
                reason: long.slice(..255)
            })
        );
        let c = Command::Pong { context: long.clone() };
        assert_eq!(
            Command::parse(body_of(&c)),
            Ok(Command::Pong {
                context: long.slice(..16)
            })
        );
    }

    #[test]
    fn malformed_bodies_are_violations() {
        let cases: [(&[u8], &str); 9] = [
            (b"", "name runs past"),
            (b"\x00", "name is empty"),
            (b"\x09READY", "name runs past"),
            (b"\x05READY", "no Socket-Type"),
            (b"\x05READY\x0bSocket-Type\x00\x00", "no value length"),
            (b"\x05READY\x0bSocket-Type\x00\x00\x00\x09REQ", "value runs past"),
            (b"\x05ERROR\x05oops", "reason runs past"),
            (b"\x04PING\x01", "no time-to-live"),
            (b"\x04PONG01234567890123456", "longer than 16"),
        ];
        for (body, expected) in cases {
            let e = Command::parse(Bytes::copy_from_slice(body)).unwrap_err();
            assert!(e.to_string().contains(expected), "{body:?}: {e}");
        }
        let e = Command::parse(Bytes::from_static(b"\x05READY\x0bSocket-Type\x00\x00\x00\x04NOPE")).unwrap_err();
        assert_eq!(e, Violation::UnknownSocketType("NOPE".into()));
        let mut id = b"\x05READY\x0bSocket-Type\x00\x00\x00\x03REQ\x08Identity\x00\x00\x01\x00".to_vec();
        id.extend_from_slice(&[1; 256]);
        assert!(
            Command::parse(Bytes::from(id))
                .unwrap_err()
                .to_string()
                .contains("identity")
        );
    }

    #[test]
    fn socket_type_compatibility_is_symmetric_and_names_round_trip() {
        for a in SocketType::ALL {
            assert_eq!(SocketType::from_name(a.name().as_bytes()), Some(a));
            for b in SocketType::ALL {
                assert_eq!(a.accepts(b), b.accepts(a), "{a} {b}");
            }
        }
        assert!(SocketType::Router.accepts(SocketType::Req));
        assert!(!SocketType::Router.accepts(SocketType::Pub));
        assert_eq!(SocketType::from_name(b"req"), None);
    }
}
