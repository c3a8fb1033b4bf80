//! CBOR decoder: never panics; whatever decodes re-encodes and decodes to the same value.
#![no_main]

use gantry_protocol::{Value, cbor};
use libfuzzer_sys::fuzz_target;

/// Structural equality with floats compared bitwise, so NaN equals itself.
fn same(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Float(x), Value::Float(y)) => x.to_bits() == y.to_bits(),
        (Value::Array(x), Value::Array(y)) => x.len() == y.len() && x.iter().zip(y).all(|(a, b)| same(a, b)),
        (Value::Map(x), Value::Map(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|((ka, va), (kb, vb))| same(ka, kb) && same(va, vb))
        }
        _ => a == b,
    }
}

fuzz_target!(|data: &[u8]| {
    let Ok(v) = cbor::decode(data) else {
        return;
    };
    let again = cbor::decode(&cbor::to_vec(&v)).expect("an encoded value must decode");
    assert!(same(&v, &again), "{v:?} != {again:?}");
});
