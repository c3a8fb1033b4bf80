//! The errors of the ROS 2 codec, type lookups and name mapping.
//!
//! Encode and decode errors say where: the message type and the path of the field
//! (`sensor_msgs/msg/JointState.position[2]`), since a script author has only that to
//! find the mistake in a table of tables.

use thiserror::Error;

/// Why a [`Value`](crate::Value) cannot be encoded as a message.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum EncodeError {
    /// A map key that is not a field of the message.
    #[error("{msg_type}: field \"{field}\" does not exist (fields: {fields})")]
    UnknownField {
        /// The top-level message type.
        msg_type: String,
        /// The path of the unknown field (`linear.q`).
        field: String,
        /// The fields the message at that place has, comma-separated.
        fields: String,
    },
    /// A map key that is not a string.
    #[error("{location}: field names must be strings, got {got}")]
    NonStringKey {
        /// Type and path of the message (`geometry_msgs/msg/Twist.linear`).
        location: String,
        /// The key's type.
        got: &'static str,
    },
    /// A value of the wrong kind (a string for a number, a number for a message).
    #[error("{location}: expected {expected}, got {got}")]
    WrongType {
        /// Type and path of the field.
        location: String,
        /// What the field takes (`a number`, `an integer`, `a message (table)`).
        expected: &'static str,
        /// What was given.
        got: String,
    },
    /// An integer outside the field's type.
    #[error("{location}: {value} is out of range for {ty}")]
    OutOfRange {
        /// Type and path of the field.
        location: String,
        /// The value as given.
        value: String,
        /// The field's type (`uint8`).
        ty: &'static str,
    },
    /// A fixed-size array given the wrong number of values.
    #[error("{location}: expected {expected} values, got {got}")]
    WrongLength {
        /// Type and path of the field.
        location: String,
        /// The array's size.
        expected: usize,
        /// How many were given.
        got: usize,
    },
    /// A sequence or string longer than CDR's 32-bit length can say.
    #[error("{location}: {len} elements (or bytes) are more than CDR's 32-bit length can count")]
    TooLong {
        /// Type and path of the field.
        location: String,
        /// Its length.
        len: usize,
    },
    /// Message types nested deeper than [`MAX_DEPTH`](super::MAX_DEPTH).
    #[error("{location}: messages nested deeper than {max} levels")]
    TooDeep {
        /// Type and path of the message.
        location: String,
        /// The limit.
        max: usize,
    },
}

/// Why bytes are not a CDR message of the expected type.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum DecodeError {
    /// Fewer than the 4 bytes of the encapsulation header.
    #[error("{msg_type}: CDR input of {len} bytes is shorter than the 4-byte encapsulation header")]
    NoHeader {
        /// The message type.
        msg_type: String,
        /// The input's length.
        len: usize,
    },
    /// An encapsulation other than plain CDR.
    #[error(
        "{msg_type}: unsupported CDR encapsulation {:02x} {:02x}: expected plain CDR, little-endian (00 01) or big-endian (00 00); XCDR2 and parameter lists are not supported",
        id[0],
        id[1]
    )]
    Encapsulation {
        /// The message type.
        msg_type: String,
        /// The encapsulation identifier (the header's first two bytes).
        id: [u8; 2],
    },
    /// The input ends inside a field.
    #[error("{location}: input truncated at body offset {offset} ({need} bytes needed, {left} left)")]
    Truncated {
        /// Type and path of the field.
        location: String,
        /// Where the field starts, after alignment, from the start of the body.
        offset: usize,
        /// Bytes the field needs.
        need: usize,
        /// Bytes left.
        left: usize,
    },
    /// A sequence or string claims more than the rest of the input can hold.
    #[error("{location}: {what} length {count} exceeds the remaining {left} bytes")]
    LengthTooLong {
        /// Type and path of the field.
        location: String,
        /// `sequence` or `string`.
        what: &'static str,
        /// The length read.
        count: u32,
        /// Bytes left after the length.
        left: usize,
    },
    /// A string whose last byte is not NUL.
    #[error("{location}: string is not NUL-terminated")]
    NotTerminated {
        /// Type and path of the field.
        location: String,
    },
    /// A `string` field that is not UTF-8.
    #[error("{location}: string is not valid UTF-8")]
    NotUtf8 {
        /// Type and path of the field.
        location: String,
    },
    /// A `bool` byte other than 0 or 1 (refused, as Fast CDR does, so that a decoded
    /// message re-encodes to the same bytes).
    #[error("{location}: bool byte {value} is neither 0 nor 1")]
    BadBool {
        /// Type and path of the field.
        location: String,
        /// The byte.
        value: u8,
    },
    /// A `uint64` above `i64::MAX`, which a script integer cannot hold.
    #[error("{location}: uint64 value {value} is larger than the largest script integer (2^63-1)")]
    IntegerTooLarge {
        /// Type and path of the field.
        location: String,
        /// The value.
        value: u64,
    },
    /// Message types nested deeper than [`MAX_DEPTH`](super::MAX_DEPTH).
    #[error("{location}: messages nested deeper than {max} levels")]
    TooDeep {
        /// Type and path of the message.
        location: String,
        /// The limit.
        max: usize,
    },
}

/// A message or service type name gantry does not know.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum RosTypeError {
    /// Not in the catalog.
    #[error(
        "unknown {kind} type \"{name}\" ({}known: see docs/ros2.md)",
        did_you_mean(suggestions)
    )]
    Unknown {
        /// `message` or `service`.
        kind: &'static str,
        /// The name asked for.
        name: String,
        /// Known names close to it, best first (may be empty).
        suggestions: Vec<String>,
    },
}

/// `"did you mean a or b? "`, or nothing.
fn did_you_mean(suggestions: &[String]) -> String {
    if suggestions.is_empty() {
        String::new()
    } else {
        format!("did you mean {}? ", suggestions.join(" or "))
    }
}

/// A ROS 2 topic or service name that cannot be mapped to a DDS topic.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum NameError {
    /// Breaks the ROS 2 name rules.
    #[error("invalid ROS 2 name \"{name}\": {reason}")]
    Invalid {
        /// The name given.
        name: String,
        /// Which rule it breaks.
        reason: &'static str,
    },
    /// Uses `~` (private namespace) or `{}` (substitution), which need a node to expand.
    #[error(
        "ROS 2 name \"{name}\" uses {feature}, which gantry does not expand; give the full name (\"/robot/cmd_vel\")"
    )]
    Unsupported {
        /// The name given.
        name: String,
        /// `~` or `{}` substitution.
        feature: &'static str,
    },
}
