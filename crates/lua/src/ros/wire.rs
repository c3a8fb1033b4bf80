//! The bytes around ROS 2 messages that more than one `simROS2` feature writes: the
//! request header of rmw_cyclonedds' services, times as `builtin_interfaces/Time`, and
//! encoding a whole message.

use gantry_protocol::Value;
use gantry_protocol::ros::{EncodeError, MsgType};

/// `builtin_interfaces/Time` of `t` seconds (negative and non-finite times are 0).
pub(crate) fn time_value(t: f64) -> Value {
    let t = if t.is_finite() && t > 0.0 { t } else { 0.0 };
    let sec = t.floor();
    let mut nanosec = ((t - sec) * 1e9).round();
    let mut sec = sec;
    if nanosec >= 1e9 {
        sec += 1.0;
        nanosec = 0.0;
    }
    Value::Map(vec![
        (
            Value::Str("sec".into()),
            Value::Int(sec.min(f64::from(i32::MAX)) as i64),
        ),
        (Value::Str("nanosec".into()), Value::Int(nanosec as i64)),
    ])
}

/// `v` encoded as `ty` (the CDR body, little-endian).
pub(crate) fn encode(ty: &MsgType, v: &Value) -> Result<Vec<u8>, EncodeError> {
    let mut body = Vec::new();
    ty.encode_into(v, &mut body, 0)?;
    Ok(body)
}

/// The 16-byte request header of rmw_cyclonedds: the client's id and the request's
/// sequence number, little-endian.
pub(crate) fn request_header(guid: u64, seq: i64) -> Vec<u8> {
    let mut b = Vec::with_capacity(64);
    b.extend_from_slice(&guid.to_le_bytes());
    b.extend_from_slice(&seq.to_le_bytes());
    b
}

/// A header read back in the byte order of its sample.
pub(crate) fn read_header(body: &[u8], little_endian: bool) -> Option<(u64, i64)> {
    let g: [u8; 8] = body.get(0..8)?.try_into().ok()?;
    let s: [u8; 8] = body.get(8..16)?.try_into().ok()?;
    Some(if little_endian {
        (u64::from_le_bytes(g), i64::from_le_bytes(s))
    } else {
        (u64::from_be_bytes(g), i64::from_be_bytes(s))
    })
}
