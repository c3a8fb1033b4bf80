//! DAP codec: any byte stream, decoded frame by frame, never panics; frames stay within
//! their bounds and do not depend on how the stream is split; every body parses or gives
//! an error whose response frames back whole.
#![no_main]

use gantry_protocol::dap::{self, MessageError, Outgoing};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut rest = data;
    loop {
        let whole = dap::decode_frame(rest);
        // The transport decodes after every read, so a prefix must give "need more" or the
        // same answer as the whole buffer. (Every prefix is checked in the unit tests; one
        // per frame keeps this fast.)
        let half = dap::decode_frame(&rest[..rest.len() / 2]);
        assert!(half == Ok(None) || half == whole, "{half:?} vs {whole:?}");
        let Ok(Some((body, consumed))) = whole else {
            break;
        };
        assert!(consumed <= rest.len() && body.len() < consumed);
        assert!(body.len() <= dap::MAX_BODY && consumed - body.len() <= dap::MAX_HEADER);
        assert_eq!(body, &rest[consumed - body.len()..consumed]);
        assert_eq!(dap::decode_frame(&rest[..consumed - 1]), Ok(None));
        check_request(body);
        rest = &rest[consumed..];
    }
    // The bytes as a bare body too, so the request parser is fuzzed without the fuzzer
    // first having to find a header with the right length.
    check_request(data);
});

fn check_request(body: &[u8]) {
    let reply = match dap::parse_request(body) {
        // `Default::default()` is `Value::Null`: no body (this crate has no serde_json of its own).
        Ok(req) => Outgoing::ok(req.seq, req.command.name(), Default::default()),
        Err(MessageError::BadArguments { seq, command, why }) => Outgoing::error(seq, &command, why),
        Err(e @ MessageError::Malformed(_)) => Outgoing::error(0, "", e.to_string()),
    };
    // What the transport would send back is one whole frame our own decoder accepts (the
    // command echoed can be as long as the body, hence the size condition).
    let bytes = reply.encode(1);
    match dap::decode_frame(&bytes) {
        Ok(Some((_, consumed))) => assert_eq!(consumed, bytes.len()),
        other => assert!(bytes.len() > dap::MAX_BODY, "{other:?}"),
    }
}
