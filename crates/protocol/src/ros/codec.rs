//! The codec's entry points on [`MsgType`], [`SrvType`] and [`ActionType`]: defaults,
//! encoding and decoding, and the parts of services and actions, which follow nested
//! types through the registry.

use super::action_type::ActionType;
use super::cdr::CDR_LE_HEADER;
use super::decode::Decoder;
use super::definition::Arity;
use super::encode::Encoder;
use super::field::{Field, Kind};
use super::msg_type::MsgType;
use super::primitive::Primitive;
use super::registry::{nested, registry};
use super::srv_type::SrvType;
use super::{DecodeError, EncodeError};
use crate::Value;

impl MsgType {
    /// A [`Value::Map`] with every field at ROS's default: 0, false, "", empty sequences,
    /// nested messages at their defaults, fixed arrays full of zeros, and the declared
    /// defaults (`Quaternion.w` is 1). `uint8`/`byte` arrays are [`Value::Bytes`], as
    /// [`decode`](Self::decode) gives them.
    pub fn default_value(&self) -> Value {
        Value::Map(
            self.fields()
                .iter()
                .map(|f| (Value::Str(f.name.clone()), default_field(f)))
                .collect(),
        )
    }

    /// Encodes `value` as CDR, with the 4-byte encapsulation header [`CDR_LE_HEADER`]
    /// (little-endian plain CDR, what every ROS 2 rmw reads).
    ///
    /// `value` is a [`Value::Map`] of field name to value; missing fields (and `nil`)
    /// take their defaults, unknown ones are an error. See the [module docs](super) for
    /// how each field type maps.
    ///
    /// # Errors
    /// An unknown field, a value of the wrong kind, an integer out of its type's range,
    /// a fixed array of the wrong length; the error names the type and the field path.
    pub fn encode(&self, value: &Value) -> Result<Vec<u8>, EncodeError> {
        let mut out = Vec::with_capacity(CDR_LE_HEADER.len() + self.min_size() + 64);
        out.extend_from_slice(&CDR_LE_HEADER);
        self.encode_into(value, &mut out, CDR_LE_HEADER.len())?;
        Ok(out)
    }

    /// Appends the little-endian CDR body of `value` (no encapsulation header) to `out`,
    /// aligning relative to `origin`, the index in `out` where the body's offset 0 is.
    /// The rmw's service request header (16 bytes of GUID and sequence number) goes
    /// between the encapsulation header and the fields this way.
    ///
    /// On error, `out` may hold part of the body; truncate it to its old length if it is
    /// reused.
    ///
    /// # Errors
    /// As [`encode`](Self::encode).
    pub fn encode_into(&self, value: &Value, out: &mut Vec<u8>, origin: usize) -> Result<(), EncodeError> {
        Encoder::new(out, origin, self.name()).message(self, value)
    }

    /// Decodes CDR bytes that start with the 4-byte encapsulation header: plain CDR,
    /// little-endian (`00 01`) or big-endian (`00 00`); the two option bytes are ignored.
    /// Bytes after the message are ignored too (RTPS pads payloads to 4 bytes).
    ///
    /// Total and bounded: never panics, and never allocates for more elements than the
    /// rest of the input could hold. `uint8[]`/`byte[]` fields decode to [`Value::Bytes`],
    /// other arrays to [`Value::Array`], messages to [`Value::Map`] in field order.
    ///
    /// # Errors
    /// A missing or unsupported encapsulation header, input that ends inside a field, a
    /// length beyond the input, a string that is not NUL-terminated UTF-8, a bool byte
    /// above 1, a `uint64` above `i64::MAX`; the error names the type and field path.
    pub fn decode(&self, bytes: &[u8]) -> Result<Value, DecodeError> {
        let Some((header, body)) = bytes.split_first_chunk::<4>() else {
            return Err(DecodeError::NoHeader {
                msg_type: self.name().to_owned(),
                len: bytes.len(),
            });
        };
        let little_endian = match [header[0], header[1]] {
            [0x00, 0x01] => true,
            [0x00, 0x00] => false,
            id => {
                return Err(DecodeError::Encapsulation {
                    msg_type: self.name().to_owned(),
                    id,
                });
            }
        };
        self.decode_body(body, little_endian, 0)
    }

    /// Decodes a CDR body without the encapsulation header, in the given byte order,
    /// starting at `skip` bytes into `body` (16 after a service request header);
    /// alignment counts from the start of `body`.
    ///
    /// # Errors
    /// As [`decode`](Self::decode); `skip` past the end is a truncation.
    pub fn decode_body(&self, body: &[u8], little_endian: bool, skip: usize) -> Result<Value, DecodeError> {
        if skip > body.len() {
            return Err(DecodeError::Truncated {
                location: self.name().to_owned(),
                offset: 0,
                need: skip,
                left: body.len(),
            });
        }
        Decoder::new(body, skip, little_endian, self.name()).message(self)
    }
}

impl SrvType {
    /// The request's message type, `std_srvs/srv/SetBool_Request`.
    pub fn request(&self) -> &MsgType {
        nested(self.halves().0)
    }

    /// The response's message type, `std_srvs/srv/SetBool_Response`.
    pub fn response(&self) -> &MsgType {
        nested(self.halves().1)
    }

    /// The DDS type name of requests: `std_srvs::srv::dds_::SetBool_Request_`.
    pub fn dds_request_type_name(&self) -> String {
        self.request().dds_type_name()
    }

    /// The DDS type name of responses: `std_srvs::srv::dds_::SetBool_Response_`.
    pub fn dds_response_type_name(&self) -> String {
        self.response().dds_type_name()
    }
}

impl ActionType {
    /// The goal a client sends, `..._Goal`.
    pub fn goal(&self) -> &'static MsgType {
        nested(self.parts().0)
    }

    /// The result a server ends a goal with, `..._Result`.
    pub fn result(&self) -> &'static MsgType {
        nested(self.parts().1)
    }

    /// The progress a server reports, `..._Feedback`.
    pub fn feedback(&self) -> &'static MsgType {
        nested(self.parts().2)
    }

    /// What the feedback topic carries: `goal_id` and `feedback`.
    pub fn feedback_message(&self) -> &'static MsgType {
        nested(self.parts().3)
    }

    /// The send-goal service: request `goal_id`, `goal`; response `accepted`, `stamp`.
    pub fn send_goal(&self) -> &'static SrvType {
        &registry().services[self.parts().4]
    }

    /// The get-result service: request `goal_id`; response `status`, `result`.
    pub fn get_result(&self) -> &'static SrvType {
        &registry().services[self.parts().5]
    }
}

/// The default of one field.
fn default_field(f: &Field) -> Value {
    let one = || default_element(f.kind, f.default.as_ref());
    match (f.arity, f.kind) {
        (Arity::Single, _) => one(),
        (Arity::Fixed(n), Kind::Primitive(p)) if p.is_octet() => Value::Bytes(vec![0; n]),
        (Arity::Fixed(n), _) => Value::Array((0..n).map(|_| one()).collect()),
        (Arity::Sequence, Kind::Primitive(p)) if p.is_octet() => Value::Bytes(Vec::new()),
        (Arity::Sequence, _) => Value::Array(Vec::new()),
    }
}

/// The default of one element: the declared default, else the type's zero.
fn default_element(kind: Kind, declared: Option<&Value>) -> Value {
    match kind {
        Kind::Message(i) => nested(i).default_value(),
        Kind::Primitive(_) if declared.is_some() => declared.cloned().unwrap_or_default(),
        Kind::Primitive(Primitive::Bool) => Value::Bool(false),
        Kind::Primitive(Primitive::String) => Value::Str(String::new()),
        Kind::Primitive(Primitive::Float32 | Primitive::Float64) => Value::Float(0.0),
        Kind::Primitive(_) => Value::Int(0),
    }
}
