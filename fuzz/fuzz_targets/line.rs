//! Line framer: arbitrary bytes in arbitrary chunk sizes never panic, never yield a line
//! over the limit, and keep the buffer bounded.
#![no_main]

use gantry_protocol::LineDecoder;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // The first byte picks the limit, the second the chunk sizes, so small limits
    // (where the edge cases are) get exercised as much as the default.
    let [max, seed, rest @ ..] = data else {
        return;
    };
    let max = usize::from(*max % 64);
    let mut seed = u32::from(*seed) | 1;
    let mut dec = LineDecoder::with_max_len(max);
    let mut buf = Vec::new();
    let mut input = rest;
    while !input.is_empty() {
        // xorshift32 for chunk sizes 1..=16.
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        let n = (seed as usize % 16 + 1).min(input.len());
        let (chunk, tail) = input.split_at(n);
        input = tail;
        buf.extend_from_slice(chunk);
        loop {
            match dec.decode(&mut buf) {
                Ok(Some(line)) => {
                    assert!(line.len() <= max);
                    assert!(!line.contains(['\r', '\n']));
                }
                Ok(None) => break,
                Err(_) => {}
            }
        }
        // A partial line, a possible CR awaiting LF, and one chunk's worth at most.
        assert!(buf.len() <= max + 1, "buffer grew to {}", buf.len());
    }
});
