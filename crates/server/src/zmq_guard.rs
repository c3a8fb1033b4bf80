//! The guard in front of the `zeromq` crate: the ZMQ remote API's public TCP port,
//! which checks the ZMTP framing of everything a peer sends before the crate sees it.
//!
//! The crate's decoder reserves memory for whatever frame length a peer announces, and
//! has no size limit to set: nine bytes announcing a 2^50-byte frame abort the whole
//! process. So the ROUTER socket listens on an internal loopback port, and for each
//! client the guard opens a connection to it and copies bytes both ways. Replies pass
//! untouched. Requests are followed through ZMTP 3.x framing as they stream (the
//! 64-byte greeting, then frames of a flags byte, a 1- or 8-byte big-endian length and
//! a body) and forwarded as they arrive, so a frame is never buffered here. A frame or
//! message over the limits, reserved flag bits or a greeting that is not ZMTP 3 close
//! that connection, with a warning naming the peer; every other client goes on.
//!
//! [`FrameGuard`] is the pure part (bytes in, verdict out, no socket); [`serve`] is the
//! accept loop and the relay. Non-goals: reading the ZMTP handshake commands or the
//! CBOR inside messages (the crate and [`crate::zmq`] do that), and limiting how many
//! clients connect (each costs two sockets and two small tasks here).

use std::net::SocketAddr;
use std::time::Duration;

use tokio::io::{AsyncReadExt, AsyncWriteExt, BufReader};
use tokio::net::tcp::{OwnedReadHalf, OwnedWriteHalf};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::watch;

/// Longest frame a peer may announce, in bytes. The largest legitimate request is one
/// CBOR argument list (a pose, a joint list, at most an image for
/// `setVisionSensorImg`: 786,432 bytes at the largest sensor resolution, 512×512 RGB),
/// far below this. It also bounds what the crate reserves for a frame that is
/// announced and never sent.
pub const MAX_FRAME_LEN: u64 = 16 * 1024 * 1024;

/// Most bytes in one multipart message. The crate keeps a message's frames until the
/// last one, so many frames under [`MAX_FRAME_LEN`] must not add up without bound.
pub const MAX_MESSAGE_LEN: u64 = MAX_FRAME_LEN;

/// Most frames in one multipart message. A REQ client sends two (the empty delimiter
/// and the request). The crate keeps every frame of a message until the last one, at
/// least a few dozen bytes each however short, so endless empty frames would grow
/// memory as surely as one long frame.
pub const MAX_MESSAGE_FRAMES: u32 = 64;

/// Length of the ZMTP 3 greeting.
const GREETING_LEN: u8 = 64;

/// Bytes read from a client at a time, in one buffer reused for the whole connection.
const READ_BUF_LEN: usize = 64 * 1024;

/// Frame flags (ZMTP 3.1, RFC 23): bit 0 "more frames follow", bit 1 "8-byte length",
/// bit 2 "command"; the others are reserved and must be zero.
const FLAG_MORE: u8 = 0b001;
const FLAG_LONG: u8 = 0b010;
const FLAG_COMMAND: u8 = 0b100;
const FLAGS_RESERVED: u8 = !(FLAG_MORE | FLAG_LONG | FLAG_COMMAND);

/// How a peer broke ZMTP 3 framing or the limits; the connection is closed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum Violation {
    /// The greeting is not ZMTP 3: byte 0 must be 0xFF, byte 9 0x7F, byte 10 (the
    /// major version) 3.
    #[error("not a ZMTP 3 greeting: byte {offset} is {byte:#04x}")]
    Greeting {
        /// Position in the greeting.
        offset: u8,
        /// The byte found there.
        byte: u8,
    },
    /// A frame's flags set reserved bits.
    #[error("frame flags {0:#04x} set reserved bits")]
    Flags(u8),
    /// A frame announced more than [`MAX_FRAME_LEN`] bytes.
    #[error("a frame of {0} bytes was announced; the limit is {MAX_FRAME_LEN}")]
    FrameTooLong(u64),
    /// A multipart message grew past [`MAX_MESSAGE_LEN`] bytes.
    #[error("a message of more than {MAX_MESSAGE_LEN} bytes was sent")]
    MessageTooLong,
    /// A multipart message grew past [`MAX_MESSAGE_FRAMES`] frames.
    #[error("a message of more than {MAX_MESSAGE_FRAMES} frames was sent")]
    TooManyFrames,
}

/// Where the guard is in the stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    /// Inside the greeting, `seen` bytes in.
    Greeting { seen: u8 },
    /// Expecting a frame's flags byte.
    Flags,
    /// Reading a frame's length: `left` bytes to go, big-endian value so far in `len`.
    Length { flags: u8, left: u8, len: u64 },
    /// Inside a frame's body, `left` bytes to go.
    Body { left: u64 },
}

/// Follows the ZMTP 3 framing of one peer's bytes, however they are split into reads,
/// and says whether they may be forwarded. Memory and time are constant per byte: a
/// body is skipped by its length, never looked at.
#[derive(Debug, Clone)]
pub struct FrameGuard {
    state: State,
    /// Bytes announced so far by the frames of the message being received.
    message_len: u64,
    /// Frames of the message being received, the current one included.
    message_frames: u32,
}

impl Default for FrameGuard {
    fn default() -> Self {
        Self::new()
    }
}

impl FrameGuard {
    /// A guard for a new connection (expecting the greeting).
    pub fn new() -> Self {
        Self {
            state: State::Greeting { seen: 0 },
            message_len: 0,
            message_frames: 0,
        }
    }

    /// Checks the next bytes the peer sent. `Ok` means forward them all; after an
    /// error the connection must be closed (the guard stays in the failed position).
    ///
    /// # Errors
    /// The first [`Violation`] in `bytes`.
    pub fn check(&mut self, mut bytes: &[u8]) -> Result<(), Violation> {
        while let Some(&byte) = bytes.first() {
            match self.state {
                State::Greeting { seen } => {
                    let take = usize::from(GREETING_LEN - seen).min(bytes.len());
                    for (i, &b) in bytes[..take].iter().enumerate() {
                        // `take` is at most 64, so the offset fits in a u8.
                        let offset = seen + i as u8;
                        let expected = match offset {
                            0 => Some(0xff),
                            9 => Some(0x7f),
                            10 => Some(3),
                            _ => None,
                        };
                        if expected.is_some_and(|e| e != b) {
                            return Err(Violation::Greeting { offset, byte: b });
                        }
                    }
                    let seen = seen + take as u8;
                    self.state = if seen == GREETING_LEN {
                        State::Flags
                    } else {
                        State::Greeting { seen }
                    };
                    bytes = &bytes[take..];
                }
                State::Flags => {
                    if byte & FLAGS_RESERVED != 0 {
                        return Err(Violation::Flags(byte));
                    }
                    let left = if byte & FLAG_LONG != 0 { 8 } else { 1 };
                    self.state = State::Length {
                        flags: byte,
                        left,
                        len: 0,
                    };
                    bytes = &bytes[1..];
                }
                State::Length { flags, left, len } => {
                    // At most 8 bytes are shifted in, so this never overflows.
                    let len = len << 8 | u64::from(byte);
                    bytes = &bytes[1..];
                    self.state = if left > 1 {
                        State::Length {
                            flags,
                            left: left - 1,
                            len,
                        }
                    } else {
                        self.frame(flags, len)?
                    };
                }
                State::Body { left } => {
                    let take = usize::try_from(left).unwrap_or(usize::MAX).min(bytes.len());
                    // `take` is at most `left`, so this cannot underflow.
                    let left = left - take as u64;
                    self.state = if left == 0 { State::Flags } else { State::Body { left } };
                    bytes = &bytes[take..];
                }
            }
        }
        Ok(())
    }

    /// A frame header is complete: checks the limits and returns the next state.
    fn frame(&mut self, flags: u8, len: u64) -> Result<State, Violation> {
        if len > MAX_FRAME_LEN {
            return Err(Violation::FrameTooLong(len));
        }
        // Commands (READY, PING...) stand alone; the crate does not keep them.
        if flags & FLAG_COMMAND == 0 {
            self.message_frames += 1;
            self.message_len += len;
            if self.message_frames > MAX_MESSAGE_FRAMES {
                return Err(Violation::TooManyFrames);
            }
            if self.message_len > MAX_MESSAGE_LEN {
                return Err(Violation::MessageTooLong);
            }
            if flags & FLAG_MORE == 0 {
                self.message_frames = 0;
                self.message_len = 0;
            }
        }
        Ok(if len == 0 {
            State::Flags
        } else {
            State::Body { left: len }
        })
    }
}

/// Accepts clients on `listener` (the public port) and relays each to the ROUTER
/// socket at `internal`, until `shutdown` turns true. Connections already open end
/// when the ROUTER socket closes.
pub async fn serve(listener: TcpListener, internal: SocketAddr, mut shutdown: watch::Receiver<bool>) {
    loop {
        tokio::select! {
            _ = shutdown.changed() => break,
            accepted = listener.accept() => match accepted {
                Ok((client, peer)) => {
                    tokio::spawn(relay(client, peer, internal));
                }
                Err(e) => {
                    // Out of file descriptors, usually: back off rather than spin.
                    tracing::warn!("zmq remote API: accept failed: {e}");
                    tokio::time::sleep(Duration::from_millis(10)).await;
                }
            }
        }
    }
}

/// Why a client's side of a relay ended.
enum UpEnd {
    /// The client closed or the connection failed; not worth a warning.
    Io,
    /// The client broke the framing or a limit.
    Violation(Violation),
}

/// Relays one client: replies are copied as they come, requests are checked by a
/// [`FrameGuard`] first. One task per direction.
async fn relay(client: TcpStream, peer: SocketAddr, internal: SocketAddr) {
    let server = match TcpStream::connect(internal).await {
        Ok(s) => s,
        Err(e) => {
            tracing::warn!("zmq remote API: cannot reach the internal endpoint {internal} for {peer}: {e}");
            return;
        }
    };
    // Each request and reply is one small write; Nagle would hold them back.
    if let Err(e) = client.set_nodelay(true).and_then(|()| server.set_nodelay(true)) {
        tracing::debug!("zmq remote API: TCP_NODELAY for {peer}: {e}");
    }
    let (client_rx, client_tx) = client.into_split();
    let (server_rx, server_tx) = server.into_split();
    let mut down = tokio::spawn(copy_replies(server_rx, client_tx));
    tokio::select! {
        end = forward_requests(client_rx, server_tx) => match end {
            // The client stopped sending: its replies may still be on their way, and
            // the crate closes its side once it has seen the end of the stream.
            UpEnd::Io => {
                let _ = down.await;
            }
            UpEnd::Violation(v) => {
                tracing::warn!("zmq remote API: closing the connection from {peer}: {v}");
                down.abort();
            }
        },
        // The crate closed the connection: so does the client's.
        _ = &mut down => {}
    }
}

/// Server to client: plain copy, then a clean end of stream.
async fn copy_replies(from: OwnedReadHalf, mut to: OwnedWriteHalf) {
    let mut from = BufReader::with_capacity(READ_BUF_LEN, from);
    let _ = tokio::io::copy_buf(&mut from, &mut to).await;
    let _ = to.shutdown().await;
}

/// Client to server: each read is checked, then forwarded whole.
async fn forward_requests(mut from: OwnedReadHalf, mut to: OwnedWriteHalf) -> UpEnd {
    let mut guard = FrameGuard::new();
    let mut buf = vec![0; READ_BUF_LEN];
    loop {
        let n = match from.read(&mut buf).await {
            Ok(0) | Err(_) => {
                let _ = to.shutdown().await;
                return UpEnd::Io;
            }
            Ok(n) => n,
        };
        if let Err(v) = guard.check(&buf[..n]) {
            return UpEnd::Violation(v);
        }
        if to.write_all(&buf[..n]).await.is_err() {
            return UpEnd::Io;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ZMTP 3.1 greeting with the NULL mechanism.
    fn greeting() -> Vec<u8> {
        let mut g = vec![0u8; 64];
        g[0] = 0xff;
        g[9] = 0x7f;
        g[10] = 3;
        g[11] = 1;
        g[12..16].copy_from_slice(b"NULL");
        g
    }

    /// One frame with `flags` (the LONG bit is chosen from the length) and `body`.
    fn frame(flags: u8, body: &[u8]) -> Vec<u8> {
        let mut f = Vec::new();
        if body.len() > 255 {
            f.push(flags | FLAG_LONG);
            f.extend_from_slice(&(body.len() as u64).to_be_bytes());
        } else {
            f.push(flags);
            f.push(body.len() as u8);
        }
        f.extend_from_slice(body);
        f
    }

    /// A header alone, announcing `len` bytes with an 8-byte length.
    fn long_header(flags: u8, len: u64) -> Vec<u8> {
        let mut h = vec![flags | FLAG_LONG];
        h.extend_from_slice(&len.to_be_bytes());
        h
    }

    /// What a REQ client sends: greeting, READY, then two requests (delimiter +
    /// payload), one short and one long, with bodies full of bytes that look like
    /// headers.
    fn session() -> Vec<u8> {
        let mut ready = b"\x05READY\x0bSocket-Type\x00\x00\x00\x03REQ".to_vec();
        ready.extend_from_slice(b"\x08Identity\x00\x00\x00\x00");
        [
            greeting(),
            frame(FLAG_COMMAND, &ready),
            frame(FLAG_MORE, &[]),
            frame(0, &[0xff; 40]),
            frame(FLAG_MORE, &[]),
            frame(0, &[0x06; 1000]),
            frame(FLAG_COMMAND, b"\x04PING\x00\x00"),
        ]
        .concat()
    }

    /// Feeds `bytes` in pieces of the given lengths (the rest in one piece).
    fn check_split(bytes: &[u8], cuts: &[usize]) -> Result<(), Violation> {
        let mut g = FrameGuard::new();
        let mut rest = bytes;
        for &c in cuts {
            let (head, tail) = rest.split_at(c.min(rest.len()));
            g.check(head)?;
            rest = tail;
        }
        g.check(rest)
    }

    /// `bytes` must give `expected` however they are split in two, and byte by byte.
    fn assert_every_split(bytes: &[u8], expected: Result<(), Violation>) {
        for cut in 0..=bytes.len() {
            assert_eq!(check_split(bytes, &[cut]), expected, "split at {cut}");
        }
        assert_eq!(check_split(bytes, &vec![1; bytes.len()]), expected, "byte by byte");
    }

    #[test]
    fn a_client_session_passes_however_it_is_split() {
        assert_every_split(&session(), Ok(()));
        // Three pieces at every pair of boundaries, over a shorter session.
        let s = [greeting(), frame(FLAG_MORE, &[]), frame(0, &[1, 2, 3])].concat();
        for a in 0..=s.len() {
            for b in 0..=s.len() - a {
                assert_eq!(check_split(&s, &[a, b]), Ok(()), "pieces {a}, {b}");
            }
        }
    }

    #[test]
    fn frames_up_to_the_limit_pass_and_longer_ones_are_refused() {
        let g = greeting();
        // The header of a frame at the limit passes (its body would follow).
        assert_every_split(&[g.clone(), long_header(0, MAX_FRAME_LEN)].concat(), Ok(()));
        for flags in [0, FLAG_MORE, FLAG_COMMAND] {
            assert_every_split(
                &[g.clone(), long_header(flags, MAX_FRAME_LEN + 1)].concat(),
                Err(Violation::FrameTooLong(MAX_FRAME_LEN + 1)),
            );
        }
        // The report that crashed gantry: a command frame announcing 2^50 bytes.
        let mut crash = g.clone();
        crash.push(0x06);
        crash.extend_from_slice(&(1u64 << 50).to_be_bytes());
        assert_every_split(&crash, Err(Violation::FrameTooLong(1 << 50)));
        assert_every_split(
            &[g, long_header(0, u64::MAX)].concat(),
            Err(Violation::FrameTooLong(u64::MAX)),
        );
    }

    #[test]
    fn a_whole_body_is_skipped_even_when_it_looks_like_headers() {
        let body = vec![0xfe; 70_000];
        let bytes = [greeting(), frame(0, &body), frame(0, &[0xff; 255])].concat();
        assert_every_split(&bytes[..200], Ok(()));
        assert_eq!(check_split(&bytes, &[100, 30_000, 39_000]), Ok(()));
        // After the body, a header is expected again.
        let mut g = FrameGuard::new();
        assert_eq!(g.check(&bytes), Ok(()));
        assert_eq!(g.state, State::Flags);
    }

    #[test]
    fn reserved_flag_bits_are_refused() {
        for bit in 3..8 {
            let flags = 1u8 << bit;
            assert_every_split(&[greeting(), vec![flags, 0]].concat(), Err(Violation::Flags(flags)));
        }
        // Also after valid frames, and with valid bits set too.
        let bytes = [session(), vec![0x86, 0]].concat();
        assert_every_split(&bytes, Err(Violation::Flags(0x86)));
    }

    #[test]
    fn a_greeting_that_is_not_zmtp_3_is_refused() {
        for (offset, byte) in [(0u8, 0x13u8), (9, 0x00), (10, 2), (10, 4)] {
            let mut g = greeting();
            g[usize::from(offset)] = byte;
            assert_every_split(&g, Err(Violation::Greeting { offset, byte }));
        }
        // The rest of the greeting (padding, mechanism, filler) is the crate's business.
        let mut g = greeting();
        g[1..9].fill(0xaa);
        g[40] = 0x55;
        assert_every_split(&g, Ok(()));
    }

    #[test]
    fn messages_are_bounded_in_bytes_and_frames() {
        // Two frames of half the limit fill a message and one more byte is refused.
        // Bodies are skipped by their length, so the test steps over them by putting
        // the guard back where a body ends instead of feeding 16 MiB.
        let half = MAX_MESSAGE_LEN / 2;
        let mut g = FrameGuard::new();
        assert_eq!(g.check(&[greeting(), long_header(FLAG_MORE, half)].concat()), Ok(()));
        g.state = State::Flags;
        assert_eq!(g.check(&long_header(FLAG_MORE, half)), Ok(()));
        g.state = State::Flags;
        assert_eq!(g.check(&[FLAG_MORE, 1]), Err(Violation::MessageTooLong));

        let more = frame(FLAG_MORE, &[]);
        let most = MAX_MESSAGE_FRAMES as usize;
        let ping = frame(FLAG_COMMAND, b"\x04PING\x00\x00");
        // The most frames a message may have, twice: the last frame of a message
        // starts the count again, and commands in between do not count.
        let full = [
            more.repeat(most / 2),
            ping.clone(),
            more.repeat(most / 2 - 1),
            frame(0, &[]),
        ]
        .concat();
        assert_every_split(&[greeting(), full.clone(), full].concat(), Ok(()));
        // One more frame in the same message is refused.
        let over = [greeting(), more.repeat(most), frame(0, &[])].concat();
        assert_every_split(&over, Err(Violation::TooManyFrames));
    }
}
