//! ZMTP decoder: arbitrary bytes, whole or in arbitrary chunks, never panic, decode the
//! same however they are split, never make the decoder wait on more than
//! `MAX_BUFFERED` bytes, and every event re-encodes to bytes that decode to it again.
#![no_main]

use bytes::{Bytes, BytesMut};
use gantry_protocol::zmtp::{self, Command, Decoder, Event, MAX_BUFFERED, SocketType, Violation};
use libfuzzer_sys::fuzz_target;

/// Feeds `pieces` one after the other, decoding after each: the events, then the
/// violation if any.
fn decode<'a>(pieces: impl Iterator<Item = &'a [u8]>) -> (Vec<Event>, Option<Violation>) {
    let mut d = Decoder::new(SocketType::Router);
    let mut buf = BytesMut::new();
    let mut events = Vec::new();
    for piece in pieces {
        buf.extend_from_slice(piece);
        loop {
            match d.decode(&mut buf) {
                Ok(Some(e)) => events.push(e),
                Ok(None) => {
                    assert!(buf.len() < MAX_BUFFERED, "waiting on {} bytes", buf.len());
                    break;
                }
                Err(v) => {
                    assert_eq!(d.decode(&mut buf), Err(v.clone()), "a violation sticks");
                    return (events, Some(v));
                }
            }
        }
    }
    (events, None)
}

/// `data` cut into chunks of 1..=16 bytes by an xorshift32 seeded with `seed`.
fn chunks(data: &[u8], seed: u8) -> Vec<&[u8]> {
    let mut seed = u32::from(seed) | 1;
    let mut rest = data;
    let mut out = Vec::new();
    while !rest.is_empty() {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        let (chunk, tail) = rest.split_at((seed as usize % 16 + 1).min(rest.len()));
        out.push(chunk);
        rest = tail;
    }
    out
}

/// A ZMTP 3 greeting, then `READY` from a REQ socket unless `ready` is false.
fn prefix(ready: bool) -> Vec<u8> {
    let mut out = Vec::new();
    zmtp::encode_greeting(&mut out, false);
    if ready {
        Command::Ready(zmtp::Ready {
            socket_type: SocketType::Req,
            identity: Bytes::new(),
        })
        .encode(&mut out);
    }
    out
}

fuzz_target!(|data: &[u8]| {
    let [seed, rest @ ..] = data else {
        return;
    };
    let whole = decode(std::iter::once(rest));
    assert_eq!(decode(chunks(rest, *seed).into_iter()), whole, "the split changed the outcome");

    for event in &whole.0 {
        // Re-encoded behind what puts a fresh decoder where the event was decoded: the
        // greeting alone for the handshake's command, greeting and READY for the rest.
        let handshake = matches!(event, Event::Command(Command::Ready(_)));
        let mut bytes = prefix(!handshake);
        match event {
            Event::Command(c) => c.encode(&mut bytes),
            Event::Message(frames) => {
                let frames: Vec<&[u8]> = frames.iter().map(|f| &f[..]).collect();
                zmtp::encode_message(&mut bytes, &frames);
            }
        }
        let (mut again, v) = decode(std::iter::once(&bytes[..]));
        assert_eq!(v, None, "{event:?} re-encoded does not decode");
        assert_eq!(again.pop().as_ref(), Some(event));
    }
});
