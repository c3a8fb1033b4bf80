//! The streaming decoder: one peer's bytes, however they are split into reads, turned
//! into handshake checks, commands and whole messages.
//!
//! Each call looks at the front of the receive buffer: it checks every frame header
//! that is visible (so an oversize announcement is refused before its body arrives),
//! and only when a whole command or message is in does it take those bytes off the
//! buffer. A message's frames are cut out of the buffer without copying
//! ([`BytesMut::split_to`]). Re-reading a partial message's headers on the next call
//! costs at most [`MAX_MESSAGE_FRAMES`] header reads, so the decoder keeps no state
//! inside a message and cannot disagree with itself about where one ends.

use bytes::{Buf, Bytes, BytesMut};

use super::command::Command;
use super::frame::Header;
use super::greeting::{GREETING_LEN, check_greeting};
use super::rules::{FLAG_COMMAND, FLAGS_RESERVED, MAX_MESSAGE_FRAMES, MAX_MESSAGE_LEN, Violation};
use super::socket_type::SocketType;

/// What the decoder produced.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Event {
    /// A command. The first one is always the peer's `READY` (or an `ERROR`, after
    /// which the peer closes); a `READY` is only ever returned once.
    Command(Command),
    /// A whole message, its frames in order (at least one).
    Message(Vec<Bytes>),
}

/// Where a connection is.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Phase {
    /// Waiting for the peer's 64-byte greeting.
    Greeting,
    /// Greeting done: the next frame must be the `READY` command.
    Handshake,
    /// Handshake done: commands and messages.
    Traffic,
}

/// What is at the front of the buffer in the traffic phase.
enum Item {
    /// A command frame: its header length and body length.
    Command { header_len: usize, body_len: usize },
    /// A whole message of `frames` frames.
    Message { frames: usize },
}

/// Follows one peer's ZMTP 3 stream. See the [module docs](super) for the contract.
#[derive(Debug, Clone)]
pub struct Decoder {
    /// Our socket type: the peer's `READY` must name one that may talk to it.
    local: SocketType,
    /// Where the stream is; it stays where a violation was found.
    phase: Phase,
    /// The violation found, returned again by every later call.
    failed: Option<Violation>,
}

impl Decoder {
    /// A decoder for a new connection of a `local` socket (expecting the greeting).
    pub fn new(local: SocketType) -> Self {
        Self {
            local,
            phase: Phase::Greeting,
            failed: None,
        }
    }

    /// Whether the handshake (greeting and `READY`) is done.
    pub fn is_ready(&self) -> bool {
        self.phase == Phase::Traffic
    }

    /// Whether the peer's greeting is in but its `READY` is not: the peer then reads
    /// commands, so an `ERROR` command can tell it why it is refused.
    pub fn in_handshake(&self) -> bool {
        self.phase == Phase::Handshake
    }

    /// Decodes the next event from the front of `buf`, removing the bytes it used.
    /// `Ok(None)` means more bytes are needed, and is only returned while `buf` holds
    /// fewer than [`super::rules::MAX_BUFFERED`] bytes.
    ///
    /// # Errors
    /// The first [`Violation`] in the stream; every later call returns it again.
    pub fn decode(&mut self, buf: &mut BytesMut) -> Result<Option<Event>, Violation> {
        if let Some(v) = &self.failed {
            return Err(v.clone());
        }
        let result = self.step(buf);
        if let Err(v) = &result {
            self.failed = Some(v.clone());
        }
        result
    }

    fn step(&mut self, buf: &mut BytesMut) -> Result<Option<Event>, Violation> {
        loop {
            match self.phase {
                Phase::Greeting => {
                    if !check_greeting(buf)? {
                        return Ok(None);
                    }
                    buf.advance(GREETING_LEN);
                    self.phase = Phase::Handshake;
                }
                Phase::Handshake => {
                    // Refuse a message as soon as its flags byte shows it is one.
                    if let Some(&flags) = buf.first()
                        && flags & FLAGS_RESERVED == 0
                        && flags & FLAG_COMMAND == 0
                    {
                        return Err(Violation::NotReady("a message".into()));
                    }
                    let Some(command) = self.next(buf)? else {
                        return Ok(None);
                    };
                    return match command {
                        Event::Command(Command::Ready(ready)) => {
                            if !self.local.accepts(ready.socket_type) {
                                return Err(Violation::SocketType {
                                    peer: ready.socket_type.name().into(),
                                    local: self.local,
                                });
                            }
                            self.phase = Phase::Traffic;
                            Ok(Some(Event::Command(Command::Ready(ready))))
                        }
                        // The peer refuses us; it closes, and so will the caller.
                        e @ Event::Command(Command::Error { .. }) => Ok(Some(e)),
                        Event::Command(c) => Err(Violation::NotReady(format!("the command {}", name_of(&c)))),
                        Event::Message(_) => Err(Violation::NotReady("a message".into())),
                    };
                }
                Phase::Traffic => {
                    return match self.next(buf)? {
                        Some(Event::Command(Command::Ready(_))) => Err(Violation::ReadyAgain),
                        other => Ok(other),
                    };
                }
            }
        }
    }

    /// The next command or whole message, taken off `buf`.
    fn next(&self, buf: &mut BytesMut) -> Result<Option<Event>, Violation> {
        let Some(item) = scan(buf)? else {
            return Ok(None);
        };
        Ok(Some(match item {
            Item::Command { header_len, body_len } => {
                buf.advance(header_len);
                Event::Command(Command::parse(buf.split_to(body_len).freeze())?)
            }
            Item::Message { frames } => {
                let mut out = Vec::with_capacity(frames);
                for _ in 0..frames {
                    // `scan` saw every one of these headers whole.
                    let Some(h) = Header::parse(buf)? else {
                        return Ok(None);
                    };
                    buf.advance(h.header_len);
                    out.push(buf.split_to(h.body_len).freeze());
                }
                Event::Message(out)
            }
        }))
    }
}

/// The name of a command, for messages.
fn name_of(c: &Command) -> String {
    match c {
        Command::Ready(_) => "READY".into(),
        Command::Error { .. } => "ERROR".into(),
        Command::Ping { .. } => "PING".into(),
        Command::Pong { .. } => "PONG".into(),
        Command::Other { name, .. } => String::from_utf8_lossy(name).into_owned(),
    }
}

/// Measures the command or message at the front of `buf` without taking anything:
/// `Ok(None)` until it is all in. Every visible header is checked, with the message
/// limits, as soon as it is visible.
fn scan(buf: &[u8]) -> Result<Option<Item>, Violation> {
    let mut pos = 0usize;
    let mut frames = 0u32;
    let mut total = 0u64;
    loop {
        let Some(h) = Header::parse(buf.get(pos..).unwrap_or_default())? else {
            return Ok(None);
        };
        if h.command {
            if frames > 0 {
                return Err(Violation::CommandInMessage);
            }
            return Ok((buf.len() >= h.header_len + h.body_len).then_some(Item::Command {
                header_len: h.header_len,
                body_len: h.body_len,
            }));
        }
        frames += 1;
        // Each body is at most MAX_FRAME_LEN and there are at most 65 of them here.
        total += h.body_len as u64;
        if frames > MAX_MESSAGE_FRAMES {
            return Err(Violation::TooManyFrames);
        }
        if total > MAX_MESSAGE_LEN {
            return Err(Violation::MessageTooLong);
        }
        // Bounded by the limits just checked, so no overflow.
        pos += h.header_len + h.body_len;
        if !h.more {
            return Ok((buf.len() >= pos).then_some(Item::Message {
                // At most MAX_MESSAGE_FRAMES.
                frames: frames as usize,
            }));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::zmtp::command::Ready;
    use crate::zmtp::{MAX_BUFFERED, MAX_FRAME_LEN, encode_frame, encode_greeting, encode_message};

    fn greeting() -> Vec<u8> {
        let mut g = Vec::new();
        encode_greeting(&mut g, false);
        g
    }

    fn ready(t: SocketType) -> Vec<u8> {
        let mut out = Vec::new();
        Command::Ready(Ready {
            socket_type: t,
            identity: Bytes::new(),
        })
        .encode(&mut out);
        out
    }

    fn command(c: Command) -> Vec<u8> {
        let mut out = Vec::new();
        c.encode(&mut out);
        out
    }

    fn message(frames: &[&[u8]]) -> Vec<u8> {
        let mut out = Vec::new();
        encode_message(&mut out, frames);
        out
    }

    /// A long header alone, announcing `len` bytes.
    fn long_header(flags: u8, len: u64) -> Vec<u8> {
        [&[flags | 0x02][..], &len.to_be_bytes()].concat()
    }

    /// What a REQ client sends: greeting, READY, then requests (delimiter + payload),
    /// one short and one long with bodies that look like headers, and a PING.
    fn session() -> Vec<u8> {
        [
            greeting(),
            ready(SocketType::Req),
            message(&[b"", &[0xff; 40]]),
            message(&[b"", &[0x06; 1000]]),
            command(Command::Ping {
                ttl: 0,
                context: Bytes::new(),
            }),
        ]
        .concat()
    }

    fn session_events() -> Vec<Event> {
        vec![
            Event::Command(Command::Ready(Ready {
                socket_type: SocketType::Req,
                identity: Bytes::new(),
            })),
            Event::Message(vec![Bytes::new(), Bytes::from(vec![0xff; 40])]),
            Event::Message(vec![Bytes::new(), Bytes::from(vec![0x06; 1000])]),
            Event::Command(Command::Ping {
                ttl: 0,
                context: Bytes::new(),
            }),
        ]
    }

    /// Feeds `bytes` in pieces cut at `cuts` (the rest in one piece), decoding after
    /// each: the events, then the violation if any. Checks the buffer bound on the way.
    fn feed(bytes: &[u8], cuts: &[usize]) -> (Vec<Event>, Option<Violation>) {
        let mut d = Decoder::new(SocketType::Router);
        let mut buf = BytesMut::new();
        let mut events = Vec::new();
        let mut rest = bytes;
        let mut pieces: Vec<&[u8]> = Vec::new();
        for &c in cuts {
            let (head, tail) = rest.split_at(c.min(rest.len()));
            pieces.push(head);
            rest = tail;
        }
        pieces.push(rest);
        for piece in pieces {
            buf.extend_from_slice(piece);
            loop {
                match d.decode(&mut buf) {
                    Ok(Some(e)) => events.push(e),
                    Ok(None) => {
                        assert!(buf.len() < MAX_BUFFERED);
                        break;
                    }
                    Err(v) => {
                        assert_eq!(d.decode(&mut buf), Err(v.clone()), "the violation sticks");
                        return (events, Some(v));
                    }
                }
            }
        }
        (events, None)
    }

    /// `bytes` must give the same outcome however they are split in two, and byte by
    /// byte.
    fn assert_every_split(bytes: &[u8], expected: &(Vec<Event>, Option<Violation>)) {
        for cut in 0..=bytes.len() {
            assert_eq!(&feed(bytes, &[cut]), expected, "split at {cut}");
        }
        assert_eq!(&feed(bytes, &vec![1; bytes.len()]), expected, "byte by byte");
    }

    /// Only the violation of `bytes` fed whole, which must not depend on the split.
    fn violation(bytes: &[u8]) -> Violation {
        let out = feed(bytes, &[]);
        assert_every_split(bytes, &out);
        out.1.expect("a violation")
    }

    #[test]
    fn a_client_session_decodes_the_same_however_it_is_split() {
        let expected = (session_events(), None);
        assert_every_split(&session(), &expected);
        // Three pieces at every pair of boundaries, over a shorter session.
        let s = [greeting(), ready(SocketType::Dealer), message(&[b"abc"])].concat();
        let whole = feed(&s, &[]);
        assert_eq!(whole.0.len(), 2);
        for a in 0..=s.len() {
            for b in 0..=s.len() - a {
                assert_eq!(feed(&s, &[a, b]), whole, "pieces {a}, {b}");
            }
        }
    }

    #[test]
    fn need_more_leaves_the_buffer_alone_and_an_event_takes_exactly_its_bytes() {
        let mut d = Decoder::new(SocketType::Router);
        let mut buf = BytesMut::from(&[greeting(), ready(SocketType::Req)].concat()[..]);
        assert!(matches!(
            d.decode(&mut buf),
            Ok(Some(Event::Command(Command::Ready(_))))
        ));
        assert!(d.is_ready());
        assert!(buf.is_empty());
        let m = message(&[b"", b"payload"]);
        buf.extend_from_slice(&m[..m.len() - 1]);
        assert_eq!(d.decode(&mut buf), Ok(None));
        assert_eq!(buf.len(), m.len() - 1);
        buf.extend_from_slice(&[m[m.len() - 1], 0x00]);
        assert_eq!(
            d.decode(&mut buf),
            Ok(Some(Event::Message(vec![Bytes::new(), Bytes::from_static(b"payload")])))
        );
        assert_eq!(&buf[..], &[0x00], "the next frame's first byte stays");
    }

    #[test]
    fn frames_up_to_the_limit_wait_for_their_body_and_longer_ones_are_refused() {
        let hello = [greeting(), ready(SocketType::Req)].concat();
        // A frame at the limit waits for its body, which is never reserved for.
        let mut d = Decoder::new(SocketType::Router);
        let mut buf = BytesMut::from(&[hello.clone(), long_header(0, MAX_FRAME_LEN)].concat()[..]);
        assert!(d.decode(&mut buf).is_ok());
        assert_eq!(d.decode(&mut buf), Ok(None));
        assert!(buf.capacity() < 4096, "nothing reserved for the announced body");
        for flags in [0, 0x01, 0x04] {
            assert_eq!(
                violation(&[hello.clone(), long_header(flags, MAX_FRAME_LEN + 1)].concat()),
                Violation::FrameTooLong(MAX_FRAME_LEN + 1)
            );
        }
        // The report that crashed gantry through the `zeromq` crate: a command frame
        // announcing 2^50 bytes, right after the greeting.
        let crash = [greeting(), long_header(0x04, 1 << 50)].concat();
        assert_eq!(violation(&crash), Violation::FrameTooLong(1 << 50));
        assert_eq!(
            violation(&[hello, long_header(0, u64::MAX)].concat()),
            Violation::FrameTooLong(u64::MAX)
        );
    }

    #[test]
    fn messages_are_bounded_in_bytes_and_frames() {
        let hello = [greeting(), ready(SocketType::Req)].concat();
        // Two frames of half the limit fill a message; one more byte is refused, as soon
        // as its header is visible and without the bodies having arrived.
        let half = MAX_MESSAGE_LEN / 2;
        let mut d = Decoder::new(SocketType::Router);
        let mut buf = BytesMut::from(&[hello.clone(), long_header(0x01, half)].concat()[..]);
        assert!(d.decode(&mut buf).is_ok());
        assert_eq!(d.decode(&mut buf), Ok(None));
        // Stand-in for the first body: the decoder only needs its length.
        buf.resize(buf.len() + half as usize, 0);
        buf.extend_from_slice(&long_header(0x01, half));
        assert_eq!(d.decode(&mut buf), Ok(None));
        buf.resize(buf.len() + half as usize, 0);
        buf.extend_from_slice(&[0x00, 1]);
        assert_eq!(d.decode(&mut buf), Err(Violation::MessageTooLong));

        let most = MAX_MESSAGE_FRAMES as usize;
        let mut full = Vec::new();
        for _ in 0..most - 1 {
            encode_frame(&mut full, b"", true);
        }
        encode_frame(&mut full, b"x", false);
        // The most frames a message may have, twice: the last frame starts the count
        // again.
        let (events, v) = feed(&[hello.clone(), full.clone(), full].concat(), &[]);
        assert_eq!((events.len(), v), (3, None));
        // One more frame in the same message is refused.
        let over = [hello, b"\x01\x00".repeat(most), vec![0x00, 0]].concat();
        assert_eq!(violation(&over), Violation::TooManyFrames);
    }

    #[test]
    fn flags_and_commands_in_the_wrong_place_are_refused() {
        let hello = [greeting(), ready(SocketType::Req)].concat();
        for bit in 3..8 {
            let flags = 1u8 << bit;
            assert_eq!(
                violation(&[hello.clone(), vec![flags, 0]].concat()),
                Violation::Flags(flags)
            );
        }
        // Also after valid frames, and with valid bits set too.
        assert_eq!(violation(&[session(), vec![0x86, 0]].concat()), Violation::Flags(0x86));
        assert_eq!(
            violation(&[hello.clone(), vec![0x05, 0]].concat()),
            Violation::MoreOnCommand
        );
        let ping = command(Command::Ping {
            ttl: 1,
            context: Bytes::new(),
        });
        assert_eq!(
            violation(&[hello, vec![0x01, 0], ping].concat()),
            Violation::CommandInMessage
        );
    }

    #[test]
    fn the_handshake_is_the_greeting_then_one_compatible_ready() {
        let g = greeting();
        assert_eq!(
            violation(&[g.clone(), message(&[b"", b"hi"])].concat()),
            Violation::NotReady("a message".into())
        );
        // Refused at the first header byte, before the message is whole.
        assert_eq!(
            feed(&[g.clone(), vec![0x01]].concat(), &[]).1,
            Some(Violation::NotReady("a message".into()))
        );
        let ping = command(Command::Ping {
            ttl: 0,
            context: Bytes::new(),
        });
        assert_eq!(
            violation(&[g.clone(), ping].concat()),
            Violation::NotReady("the command PING".into())
        );
        assert_eq!(
            violation(&[g.clone(), ready(SocketType::Pub)].concat()),
            Violation::SocketType {
                peer: "PUB".into(),
                local: SocketType::Router
            }
        );
        assert_eq!(
            violation(&[g.clone(), ready(SocketType::Req), ready(SocketType::Req)].concat()),
            Violation::ReadyAgain
        );
        // An ERROR instead of READY is passed on (the peer refuses us and closes).
        let error = Command::Error {
            reason: Bytes::from_static(b"no"),
        };
        let (events, v) = feed(&[g, command(error.clone())].concat(), &[]);
        assert_eq!((events, v), (vec![Event::Command(error)], None));
        // A greeting that is not ZMTP 3 never gets that far.
        assert_eq!(violation(&[0x13; 70]), Violation::Greeting { offset: 0, byte: 0x13 });
    }
}
