//! ROS 2 CDR decoder: the first byte picks a known message type (services' and actions'
//! parts included), the rest is decoded as that type; it never panics, and whatever decodes re-encodes to bytes that decode to
//! the same value.
#![no_main]

use gantry_protocol::{Value, ros};
use libfuzzer_sys::fuzz_target;

/// Structural equality with floats compared bitwise (any NaN equals any NaN: a
/// `float32` NaN's payload may change when widened to `f64` and narrowed back).
fn same(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Float(x), Value::Float(y)) => x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()),
        (Value::Array(x), Value::Array(y)) => x.len() == y.len() && x.iter().zip(y).all(|(a, b)| same(a, b)),
        (Value::Map(x), Value::Map(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|((ka, va), (kb, vb))| same(ka, kb) && same(va, vb))
        }
        _ => a == b,
    }
}

fuzz_target!(|data: &[u8]| {
    let Some((&pick, bytes)) = data.split_first() else {
        return;
    };
    let mut types: Vec<&ros::MsgType> = ros::known_message_types().collect();
    for s in ros::known_service_types() {
        types.extend([s.request(), s.response()]);
    }
    for a in ros::known_action_types() {
        types.extend([a.feedback_message(), a.send_goal().request(), a.send_goal().response()]);
        types.extend([a.get_result().request(), a.get_result().response()]);
    }
    let t = types[usize::from(pick) % types.len()];
    let Ok(v) = t.decode(bytes) else {
        return;
    };
    let encoded = t
        .encode(&v)
        .unwrap_or_else(|e| panic!("a decoded {} must encode: {e}", t.name()));
    let again = t.decode(&encoded).expect("an encoded value must decode");
    assert!(same(&v, &again), "{}: {v:?} != {again:?}", t.name());
});
