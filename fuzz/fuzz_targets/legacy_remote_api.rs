//! Legacy remote API codec: any byte stream, read packet by packet, never panics; the
//! messages it yields do not depend on how the stream is split; every message decodes or
//! gives an error, and a decoded one encodes back to the same commands.
#![no_main]

use gantry_protocol::legacy_remote_api::{self as legacy, PacketReader, SplitAssembler};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut whole = PacketReader::new();
    whole.feed(data);
    let mut split = PacketReader::new();
    let (a, b) = data.split_at(data.len() / 2);
    split.feed(a);
    let mut early = Vec::new();
    while let Ok(Some(m)) = split.next_message() {
        early.push(m);
    }
    split.feed(b);
    let mut assembler = SplitAssembler::default();
    loop {
        let m = whole.next_message();
        let s = if early.is_empty() { split.next_message() } else { Ok(Some(early.remove(0))) };
        assert_eq!(m, s);
        let Ok(Some(message)) = m else { break };
        assert!(message.len() <= legacy::MAX_MESSAGE_LEN);
        check(&message, &mut assembler);
    }
    // The bytes as a bare message too, so the message decoder is fuzzed without packets.
    check(data, &mut assembler);
});

fn check(message: &[u8], assembler: &mut SplitAssembler) {
    let Ok(decoded) = legacy::decode_message(message) else { return };
    let again = legacy::decode_message(&legacy::encode_message(&decoded.header, &decoded.commands))
        .expect("an encoded message decodes");
    assert_eq!(again.commands, decoded.commands);
    for chunk in decoded.chunks {
        let _ = assembler.add(chunk);
    }
}
