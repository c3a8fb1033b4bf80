//! [`Value`] to little-endian CDR: the writing half of the codec.
//!
//! Writes straight into the caller's buffer: no intermediate values, no allocation per
//! element (field paths for errors live on the stack, see [`Path`]), and byte arrays
//! given as [`Value::Bytes`] or [`Value::Str`] are copied in one go.

use super::EncodeError;
use super::cdr::pad;
use super::definition::Arity;
use super::field::{Field, Kind};
use super::msg_type::MsgType;
use super::path::Path;
use super::primitive::Primitive;
use super::registry::MAX_DEPTH;
use super::registry::nested;
use crate::Value;

/// Appends one message body to a buffer.
pub(crate) struct Encoder<'a> {
    out: &'a mut Vec<u8>,
    /// Index in `out` of body offset 0, which alignment counts from.
    origin: usize,
    /// The top-level type, for error messages.
    top: &'a str,
}

impl<'a> Encoder<'a> {
    pub(crate) fn new(out: &'a mut Vec<u8>, origin: usize, top: &'a str) -> Encoder<'a> {
        Encoder { out, origin, top }
    }

    /// Writes `value` as the top-level message `ty`.
    pub(crate) fn message(&mut self, ty: &MsgType, value: &Value) -> Result<(), EncodeError> {
        self.struct_(ty, value, &Path::Root, 1)
    }

    /// Pads with zeros to a multiple of `n` from the body's start.
    fn align(&mut self, n: usize) {
        pad(self.out, self.origin, n);
    }

    fn wrong(&self, path: &Path, expected: &'static str, got: &Value) -> EncodeError {
        EncodeError::WrongType {
            location: path.location(self.top),
            expected,
            got: got.type_name().to_owned(),
        }
    }

    /// A message: a map of field values (missing ones default), an empty array (an empty
    /// Lua table), or nil (all defaults).
    fn struct_(&mut self, ty: &MsgType, value: &Value, path: &Path, depth: usize) -> Result<(), EncodeError> {
        if depth > MAX_DEPTH {
            return Err(EncodeError::TooDeep {
                location: path.location(self.top),
                max: MAX_DEPTH,
            });
        }
        // A time or duration may be given as a number of seconds, as ROS 1's plugin
        // took it (old scripts stamp headers with `simROS.getTime()`).
        let from_seconds;
        let value = match value.as_f64() {
            Some(t)
                if matches!(
                    ty.name(),
                    "builtin_interfaces/msg/Time" | "builtin_interfaces/msg/Duration"
                ) =>
            {
                from_seconds = seconds(t).ok_or_else(|| self.wrong(path, "a finite number of seconds", value))?;
                &from_seconds
            }
            _ => value,
        };
        let pairs: &[(Value, Value)] = match value {
            Value::Map(pairs) => pairs,
            Value::Array(items) if items.is_empty() => &[],
            Value::Nil => &[],
            other => return Err(self.wrong(path, "a message (table)", other)),
        };
        // Unknown keys first, so a misspelt field is reported as such rather than
        // silently defaulted.
        for (key, _) in pairs {
            let Value::Str(key) = key else {
                return Err(EncodeError::NonStringKey {
                    location: path.location(self.top),
                    got: key.type_name(),
                });
            };
            // ROS 1's Header had a sequence number; ROS 2 dropped it. ROS 1 scripts
            // still set it, so it is ignored rather than refused.
            if ty.name() == "std_msgs/msg/Header" && key == "seq" {
                continue;
            }
            if !ty.fields().iter().any(|f| f.name == *key) {
                return Err(EncodeError::UnknownField {
                    msg_type: self.top.to_owned(),
                    field: path.field(key).to_string(),
                    fields: ty.field_list(),
                });
            }
        }
        if ty.fields().is_empty() {
            // The C/DDS mapping gives empty structures one `uint8` member.
            self.out.push(0);
            return Ok(());
        }
        for f in ty.fields() {
            let v = pairs
                .iter()
                .find(|(k, _)| k.as_str() == Some(f.name.as_str()))
                .map_or(&Value::Nil, |(_, v)| v);
            self.field(f, v, &path.field(&f.name), depth)?;
        }
        Ok(())
    }

    fn field(&mut self, f: &Field, v: &Value, path: &Path, depth: usize) -> Result<(), EncodeError> {
        match f.arity {
            Arity::Single => self.element(f.kind, v, f.default.as_ref(), path, depth),
            Arity::Fixed(n) => self.array(f.kind, v, Some(n), path, depth),
            Arity::Sequence => self.array(f.kind, v, None, path, depth),
        }
    }

    fn element(
        &mut self,
        kind: Kind,
        v: &Value,
        default: Option<&Value>,
        path: &Path,
        depth: usize,
    ) -> Result<(), EncodeError> {
        match kind {
            Kind::Message(i) => self.struct_(nested(i), v, path, depth + 1),
            Kind::Primitive(p) => match (v, default) {
                (Value::Nil, Some(d)) => self.primitive(p, d, path),
                _ => self.primitive(p, v, path),
            },
        }
    }

    /// A fixed array (`fixed` = its size) or a sequence.
    fn array(
        &mut self,
        kind: Kind,
        v: &Value,
        fixed: Option<usize>,
        path: &Path,
        depth: usize,
    ) -> Result<(), EncodeError> {
        if let Kind::Primitive(p) = kind
            && p.is_byte_like()
        {
            let raw = match v {
                Value::Bytes(b) => Some(b.as_slice()),
                Value::Str(s) => Some(s.as_bytes()),
                _ => None,
            };
            if let Some(raw) = raw {
                self.length(raw.len(), fixed, path)?;
                self.out.extend_from_slice(raw);
                return Ok(());
            }
        }
        let items: &[Value] = match v {
            Value::Array(items) => items,
            Value::Map(pairs) if pairs.is_empty() => &[],
            Value::Nil => {
                // All defaults: no elements, or a fixed array of default elements.
                self.length(fixed.unwrap_or(0), fixed, path)?;
                for i in 0..fixed.unwrap_or(0) {
                    self.element(kind, &Value::Nil, None, &path.index(i), depth)?;
                }
                return Ok(());
            }
            other => return Err(self.wrong(path, "an array", other)),
        };
        self.length(items.len(), fixed, path)?;
        let size = match kind {
            Kind::Primitive(p) => p.size(),
            Kind::Message(i) => nested(i).min_size(),
        };
        self.out.reserve(items.len().saturating_mul(size));
        for (i, item) in items.iter().enumerate() {
            self.element(kind, item, None, &path.index(i), depth)?;
        }
        Ok(())
    }

    /// Checks a fixed array's length, or writes a sequence's count.
    fn length(&mut self, len: usize, fixed: Option<usize>, path: &Path) -> Result<(), EncodeError> {
        match fixed {
            Some(n) if n != len => Err(EncodeError::WrongLength {
                location: path.location(self.top),
                expected: n,
                got: len,
            }),
            Some(_) => Ok(()),
            None => self.count(len, path),
        }
    }

    /// A `u32` length prefix.
    fn count(&mut self, len: usize, path: &Path) -> Result<(), EncodeError> {
        let n = u32::try_from(len).map_err(|_| EncodeError::TooLong {
            location: path.location(self.top),
            len,
        })?;
        self.align(4);
        self.out.extend_from_slice(&n.to_le_bytes());
        Ok(())
    }

    /// One builtin value; nil is the type's zero.
    fn primitive(&mut self, p: Primitive, v: &Value, path: &Path) -> Result<(), EncodeError> {
        match p {
            Primitive::Bool => match v {
                Value::Bool(b) => self.out.push(u8::from(*b)),
                Value::Nil => self.out.push(0),
                other => return Err(self.wrong(path, "a boolean", other)),
            },
            Primitive::String => {
                let s = match v {
                    Value::Str(s) => s.as_str(),
                    Value::Bytes(b) => std::str::from_utf8(b).map_err(|_| EncodeError::WrongType {
                        location: path.location(self.top),
                        expected: "a string",
                        got: "bytes that are not UTF-8".to_owned(),
                    })?,
                    Value::Nil => "",
                    other => return Err(self.wrong(path, "a string", other)),
                };
                // Length counts the terminating NUL.
                self.count(s.len().saturating_add(1), path)?;
                self.out.extend_from_slice(s.as_bytes());
                self.out.push(0);
            }
            Primitive::Float32 | Primitive::Float64 => {
                let x = match v {
                    Value::Nil => 0.0,
                    other => other.as_f64().ok_or_else(|| self.wrong(path, "a number", other))?,
                };
                if p == Primitive::Float32 {
                    self.align(4);
                    // Narrowing is the point: the field is single precision.
                    self.out.extend_from_slice(&(x as f32).to_le_bytes());
                } else {
                    self.align(8);
                    self.out.extend_from_slice(&x.to_le_bytes());
                }
            }
            _ => {
                let i = self.integer(p, v, path)?;
                let size = p.size();
                self.align(size);
                // Two's complement: the low `size` bytes are the value in the narrower
                // type, signed or not, once the range is checked.
                self.out.extend_from_slice(&i.to_le_bytes()[..size]);
            }
        }
        Ok(())
    }

    /// An integer value checked against `p`'s range.
    fn integer(&self, p: Primitive, v: &Value, path: &Path) -> Result<i64, EncodeError> {
        let out_of_range = |value: String| EncodeError::OutOfRange {
            location: path.location(self.top),
            value,
            ty: p.name(),
        };
        let i = match *v {
            Value::Nil => 0,
            Value::Int(i) => i,
            // A fraction is dropped (toward zero), as CoppeliaSim's plugins convert a
            // Lua number for an integer field: scripts compute `nanosec` as
            // `(t - sec) * 1e9` and publish it as it comes.
            Value::Float(f) if f.is_finite() => {
                let whole = f.trunc();
                Value::Float(whole)
                    .as_i64()
                    .ok_or_else(|| out_of_range(format!("{f}")))?
            }
            Value::Float(f) => {
                return Err(EncodeError::WrongType {
                    location: path.location(self.top),
                    expected: "an integer",
                    got: format!("{f}"),
                });
            }
            ref other => return Err(self.wrong(path, "an integer", other)),
        };
        let (lo, hi) = p.int_range().unwrap_or((i64::MIN, i64::MAX));
        if (lo..=hi).contains(&i) {
            Ok(i)
        } else {
            Err(out_of_range(i.to_string()))
        }
    }
}

/// `{sec, nanosec}` of `t` seconds (`nanosec` in `0..1e9`, so a negative duration has a
/// negative `sec`); `None` for a time that is not finite or beyond `i32` seconds.
fn seconds(t: f64) -> Option<Value> {
    if !t.is_finite() {
        return None;
    }
    let mut sec = t.floor();
    let mut nanosec = ((t - sec) * 1e9).round();
    if nanosec >= 1e9 {
        sec += 1.0;
        nanosec = 0.0;
    }
    if sec < f64::from(i32::MIN) || sec > f64::from(i32::MAX) {
        return None;
    }
    // Both in range, checked above.
    Some(Value::Map(vec![
        (Value::Str("sec".into()), Value::Int(sec as i64)),
        (Value::Str("nanosec".into()), Value::Int(nanosec as i64)),
    ]))
}
