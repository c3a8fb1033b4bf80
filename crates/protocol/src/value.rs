//! The small dynamic value that crosses every API boundary.
//!
//! `sim.*` functions take and return [`Value`]s. The Lua host converts Lua values to and
//! from it, and the ZMQ remote API decodes CBOR straight into it, so one implementation of
//! each function serves both front ends. It lives in `protocol` because it is pure data
//! with no I/O; `sim-core` depends on it, never the other way round.

/// A dynamically typed value: the common ground of Lua tables and CBOR items.
///
/// Maps keep insertion order and allow any key type (Lua tables and CBOR maps both do),
/// which also makes encoding deterministic.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Value {
    /// Lua `nil`, CBOR `null` / `undefined`, Python `None`.
    #[default]
    Nil,
    /// A boolean.
    Bool(bool),
    /// An integer (Lua 5.4 integer subtype, CBOR major types 0 and 1 within `i64`).
    Int(i64),
    /// A double-precision float.
    Float(f64),
    /// UTF-8 text.
    Str(String),
    /// A byte string (images, buffers).
    Bytes(Vec<u8>),
    /// A sequence (Lua table with keys `1..n`, CBOR array).
    Array(Vec<Value>),
    /// Key/value pairs in insertion order (Lua table with other keys, CBOR map).
    Map(Vec<(Value, Value)>),
}

impl Value {
    /// A short name of the value's type, for error messages ("expected number, got string").
    pub fn type_name(&self) -> &'static str {
        match self {
            Value::Nil => "nil",
            Value::Bool(_) => "boolean",
            Value::Int(_) | Value::Float(_) => "number",
            Value::Str(_) => "string",
            Value::Bytes(_) => "bytes",
            Value::Array(_) => "array",
            Value::Map(_) => "map",
        }
    }

    /// The value as a float if it is a number (integers convert exactly up to 2^53).
    pub fn as_f64(&self) -> Option<f64> {
        match *self {
            Value::Int(i) => Some(i as f64),
            Value::Float(f) => Some(f),
            _ => None,
        }
    }

    /// The value as an integer if it is an integer, or a float with no fractional part
    /// that fits in `i64` (Lua and Python clients send `3.0` where `3` is meant).
    pub fn as_i64(&self) -> Option<i64> {
        match *self {
            Value::Int(i) => Some(i),
            Value::Float(f) if f.fract() == 0.0 && f >= i64::MIN as f64 && f < i64::MAX as f64 => Some(f as i64),
            _ => None,
        }
    }

    /// The value as text if it is a string.
    pub fn as_str(&self) -> Option<&str> {
        match self {
            Value::Str(s) => Some(s),
            _ => None,
        }
    }

    /// Looks a string key up in a map; `None` for other values or a missing key.
    pub fn get(&self, key: &str) -> Option<&Value> {
        match self {
            Value::Map(pairs) => pairs.iter().find(|(k, _)| k.as_str() == Some(key)).map(|(_, v)| v),
            _ => None,
        }
    }

    /// An array of floats, the shape of positions, quaternions and matrices.
    pub fn floats(values: &[f64]) -> Value {
        Value::Array(values.iter().map(|&f| Value::Float(f)).collect())
    }
}

impl From<bool> for Value {
    fn from(b: bool) -> Self {
        Value::Bool(b)
    }
}
impl From<i64> for Value {
    fn from(i: i64) -> Self {
        Value::Int(i)
    }
}
impl From<i32> for Value {
    fn from(i: i32) -> Self {
        Value::Int(i64::from(i))
    }
}
impl From<f64> for Value {
    fn from(f: f64) -> Self {
        Value::Float(f)
    }
}
impl From<&str> for Value {
    fn from(s: &str) -> Self {
        Value::Str(s.to_owned())
    }
}
impl From<String> for Value {
    fn from(s: String) -> Self {
        Value::Str(s)
    }
}
impl From<Vec<Value>> for Value {
    fn from(v: Vec<Value>) -> Self {
        Value::Array(v)
    }
}
