//! Remote API request and reply decoders: never panic on any frame.
#![no_main]

use gantry_protocol::remote_api;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(r) = remote_api::decode_request(data) {
        assert!(r.args.len() <= data.len().max(remote_api::MAX_ARGS_L as usize));
    }
    let _ = remote_api::decode_reply(data);
});
