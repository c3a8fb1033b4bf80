//! [`MsgType`]: one known ROS 2 message type, and its codec entry points.

use super::decode::Decoder;
use super::definition::Arity;
use super::encode::Encoder;
use super::primitive::Primitive;
use super::registry::{Field, Kind, nested};
use super::{DecodeError, EncodeError};
use crate::Value;

/// The 4-byte encapsulation header of little-endian plain CDR (`CDR_LE`, no options),
/// which [`MsgType::encode`] writes.
pub const CDR_LE_HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// A ROS 2 message type known to gantry.
///
/// Obtained from [`message_type`](super::message_type) (or a service's
/// [`request`](super::SrvType::request) and [`response`](super::SrvType::response));
/// lives for the whole program.
#[derive(Debug)]
pub struct MsgType {
    /// `pkg/msg/Type`.
    name: String,
    /// The `.msg` text of its own fields and constants.
    definition: String,
    fields: Vec<Field>,
    /// Fewest bytes one value takes on the wire (padding aside; at least 1), which bounds
    /// what a sequence count may claim.
    min_size: usize,
}

impl MsgType {
    /// A type with its fields resolved (by the registry).
    pub(crate) fn new(name: String, definition: String, fields: Vec<Field>) -> MsgType {
        MsgType {
            name,
            definition,
            fields,
            min_size: 1,
        }
    }

    pub(crate) fn set_min_size(&mut self, size: usize) {
        self.min_size = size;
    }

    pub(crate) fn min_size(&self) -> usize {
        self.min_size
    }

    pub(crate) fn fields(&self) -> &[Field] {
        &self.fields
    }

    /// The field names, comma-separated, for "does not exist" errors.
    pub(crate) fn field_list(&self) -> String {
        let names: Vec<&str> = self.fields.iter().map(|f| f.name.as_str()).collect();
        if names.is_empty() {
            "none".to_owned()
        } else {
            names.join(", ")
        }
    }

    /// The canonical name, `geometry_msgs/msg/Twist` (service halves:
    /// `std_srvs/srv/SetBool_Request`).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The DDS type name the rmw layer registers: `geometry_msgs::msg::dds_::Twist_`.
    pub fn dds_type_name(&self) -> String {
        let mut parts = self.name.rsplitn(2, '/');
        let short = parts.next().unwrap_or_default();
        let scope = parts.next().unwrap_or_default().replace('/', "::");
        format!("{scope}::dds_::{short}_")
    }

    /// The `.msg`-style text of its own fields (and constants), one per line, nested types
    /// by name, as ROS 2 writes them: for documentation and MCAP `ros2msg` schemas.
    pub fn definition(&self) -> &str {
        &self.definition
    }

    /// A [`Value::Map`] with every field at ROS's default: 0, false, "", empty sequences,
    /// nested messages at their defaults, fixed arrays full of zeros, and the declared
    /// defaults (`Quaternion.w` is 1). `uint8`/`byte` arrays are [`Value::Bytes`], as
    /// [`decode`](Self::decode) gives them.
    pub fn default_value(&self) -> Value {
        Value::Map(
            self.fields
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
        let mut out = Vec::with_capacity(CDR_LE_HEADER.len() + self.min_size + 64);
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
        Encoder::new(out, origin, &self.name).message(self, value)
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
                msg_type: self.name.clone(),
                len: bytes.len(),
            });
        };
        let little_endian = match [header[0], header[1]] {
            [0x00, 0x01] => true,
            [0x00, 0x00] => false,
            id => {
                return Err(DecodeError::Encapsulation {
                    msg_type: self.name.clone(),
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
                location: self.name.clone(),
                offset: 0,
                need: skip,
                left: body.len(),
            });
        }
        Decoder::new(body, skip, little_endian, &self.name).message(self)
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

#[cfg(test)]
mod tests {
    use super::super::message_type;
    use super::*;

    #[test]
    fn dds_names() {
        let t = message_type("geometry_msgs/msg/Twist").unwrap();
        assert_eq!(t.dds_type_name(), "geometry_msgs::msg::dds_::Twist_");
        assert_eq!(t.definition(), "Vector3 linear\nVector3 angular\n");
    }

    #[test]
    fn defaults_follow_the_definitions() {
        let q = message_type("geometry_msgs/msg/Quaternion").unwrap().default_value();
        assert_eq!(q.get("w"), Some(&Value::Float(1.0)));
        assert_eq!(q.get("x"), Some(&Value::Float(0.0)));
        let info = message_type("sensor_msgs/msg/CameraInfo").unwrap().default_value();
        assert_eq!(info.get("k"), Some(&Value::floats(&[0.0; 9])));
        assert_eq!(info.get("d"), Some(&Value::Array(vec![])));
        assert_eq!(
            info.get("roi").and_then(|r| r.get("do_rectify")),
            Some(&Value::Bool(false))
        );
        let img = message_type("sensor_msgs/msg/Image").unwrap().default_value();
        assert_eq!(img.get("data"), Some(&Value::Bytes(vec![])));
        assert_eq!(img.get("encoding"), Some(&Value::Str(String::new())));
        assert_eq!(
            img.get("header")
                .and_then(|h| h.get("stamp"))
                .and_then(|s| s.get("nanosec")),
            Some(&Value::Int(0))
        );
    }
}
