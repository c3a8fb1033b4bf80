//! The builtin field types of ROS 2 message definitions and their CDR sizes.

/// A builtin (non-message) field type.
///
/// `byte` is IDL `octet` and `char` is IDL `uint8` in ROS 2; both travel as one unsigned
/// byte, so the codec treats them like `uint8` except for how sequences decode (see
/// [`Primitive::is_octet`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Primitive {
    Bool,
    Byte,
    Char,
    Int8,
    UInt8,
    Int16,
    UInt16,
    Int32,
    UInt32,
    Int64,
    UInt64,
    Float32,
    Float64,
    String,
}

impl Primitive {
    /// The type named `name` in a definition, if it is builtin.
    pub(crate) fn parse(name: &str) -> Option<Primitive> {
        Some(match name {
            "bool" => Primitive::Bool,
            "byte" => Primitive::Byte,
            "char" => Primitive::Char,
            "int8" => Primitive::Int8,
            "uint8" => Primitive::UInt8,
            "int16" => Primitive::Int16,
            "uint16" => Primitive::UInt16,
            "int32" => Primitive::Int32,
            "uint32" => Primitive::UInt32,
            "int64" => Primitive::Int64,
            "uint64" => Primitive::UInt64,
            "float32" => Primitive::Float32,
            "float64" => Primitive::Float64,
            "string" => Primitive::String,
            _ => return None,
        })
    }

    /// The name used in definitions and error messages.
    pub(crate) fn name(self) -> &'static str {
        match self {
            Primitive::Bool => "bool",
            Primitive::Byte => "byte",
            Primitive::Char => "char",
            Primitive::Int8 => "int8",
            Primitive::UInt8 => "uint8",
            Primitive::Int16 => "int16",
            Primitive::UInt16 => "uint16",
            Primitive::Int32 => "int32",
            Primitive::UInt32 => "uint32",
            Primitive::Int64 => "int64",
            Primitive::UInt64 => "uint64",
            Primitive::Float32 => "float32",
            Primitive::Float64 => "float64",
            Primitive::String => "string",
        }
    }

    /// Bytes on the wire and CDR alignment; for `string`, those of its length prefix
    /// (the fewest bytes a string can take: decoders accept a zero length).
    pub(crate) fn size(self) -> usize {
        match self {
            Primitive::Bool | Primitive::Byte | Primitive::Char | Primitive::Int8 | Primitive::UInt8 => 1,
            Primitive::Int16 | Primitive::UInt16 => 2,
            Primitive::Int32 | Primitive::UInt32 | Primitive::Float32 | Primitive::String => 4,
            Primitive::Int64 | Primitive::UInt64 | Primitive::Float64 => 8,
        }
    }

    /// `uint8` and `byte`: sequences and arrays of them are binary data (images, point
    /// clouds), taken from and given back as [`crate::Value::Bytes`] with one copy.
    pub(crate) fn is_octet(self) -> bool {
        matches!(self, Primitive::UInt8 | Primitive::Byte)
    }

    /// One-byte unsigned types, which also accept bytes and strings for whole arrays.
    pub(crate) fn is_byte_like(self) -> bool {
        matches!(self, Primitive::UInt8 | Primitive::Byte | Primitive::Char)
    }

    /// The inclusive range of an integer type (`None` for the others). `uint64` is
    /// limited to `i64`'s range, the integers a [`crate::Value`] can hold.
    pub(crate) fn int_range(self) -> Option<(i64, i64)> {
        Some(match self {
            Primitive::Byte | Primitive::Char | Primitive::UInt8 => (0, i64::from(u8::MAX)),
            Primitive::Int8 => (i64::from(i8::MIN), i64::from(i8::MAX)),
            Primitive::Int16 => (i64::from(i16::MIN), i64::from(i16::MAX)),
            Primitive::UInt16 => (0, i64::from(u16::MAX)),
            Primitive::Int32 => (i64::from(i32::MIN), i64::from(i32::MAX)),
            Primitive::UInt32 => (0, i64::from(u32::MAX)),
            Primitive::Int64 => (i64::MIN, i64::MAX),
            Primitive::UInt64 => (0, i64::MAX),
            _ => return None,
        })
    }
}
