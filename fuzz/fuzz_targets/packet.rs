//! Packet parser: never panics; whatever parses re-encodes to an equal packet.
#![no_main]

use gantry_protocol::parse_packet;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(line) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(p) = parse_packet(line) else {
        return;
    };
    let encoded = p.encode();
    let q = parse_packet(&encoded).expect("an encoded packet must parse");
    assert_eq!(q.code, p.code);
    assert_eq!(q.fields.len(), p.fields.len());
    for (a, b) in p.fields.iter().zip(&q.fields) {
        assert_eq!(a.key, b.key);
        assert_eq!(a.value.to_bits(), b.value.to_bits(), "{encoded}");
    }
});
