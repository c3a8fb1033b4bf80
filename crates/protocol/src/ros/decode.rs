//! CDR to [`Value`]: the reading half of the codec.
//!
//! Total and bounded. Every read checks the bytes left first, so no input panics; every
//! sequence count is checked against the bytes left times the element's smallest wire
//! size before anything is reserved, so a claimed length costs at most what the input
//! can back. Nesting follows the static types (a few levels) and is capped at
//! [`MAX_DEPTH`] all the same.

use super::DecodeError;
use super::definition::Arity;
use super::field::{Field, Kind};
use super::msg_type::MsgType;
use super::path::Path;
use super::primitive::Primitive;
use super::registry::MAX_DEPTH;
use super::registry::nested;
use crate::Value;

/// Reads one message body.
pub(crate) struct Decoder<'a> {
    body: &'a [u8],
    /// Next byte to read; may pass the end after alignment, and then reads fail.
    pos: usize,
    little_endian: bool,
    /// The top-level type, for error messages.
    top: &'a str,
}

impl<'a> Decoder<'a> {
    pub(crate) fn new(body: &'a [u8], pos: usize, little_endian: bool, top: &'a str) -> Decoder<'a> {
        Decoder {
            body,
            pos,
            little_endian,
            top,
        }
    }

    /// Reads the top-level message `ty`. Bytes after it are left alone (padding).
    pub(crate) fn message(&mut self, ty: &MsgType) -> Result<Value, DecodeError> {
        self.struct_(ty, &Path::Root, 1)
    }

    fn left(&self) -> usize {
        self.body.len().saturating_sub(self.pos)
    }

    fn align(&mut self, n: usize) {
        let pad = (n - self.pos % n) % n;
        self.pos = self.pos.saturating_add(pad);
    }

    /// The next `n` bytes.
    fn take(&mut self, n: usize, path: &Path) -> Result<&'a [u8], DecodeError> {
        let start = self.pos;
        match start.checked_add(n).and_then(|end| self.body.get(start..end)) {
            Some(bytes) => {
                self.pos = start + n;
                Ok(bytes)
            }
            None => Err(DecodeError::Truncated {
                location: path.location(self.top),
                offset: start,
                need: n,
                left: self.left(),
            }),
        }
    }

    /// A `u32` (a length or count), aligned, in the input's order.
    fn read_u32(&mut self, path: &Path) -> Result<u32, DecodeError> {
        self.align(4);
        let raw = self.take(4, path)?;
        let b = [raw[0], raw[1], raw[2], raw[3]];
        Ok(if self.little_endian {
            u32::from_le_bytes(b)
        } else {
            u32::from_be_bytes(b)
        })
    }

    fn struct_(&mut self, ty: &MsgType, path: &Path, depth: usize) -> Result<Value, DecodeError> {
        if depth > MAX_DEPTH {
            return Err(DecodeError::TooDeep {
                location: path.location(self.top),
                max: MAX_DEPTH,
            });
        }
        if ty.fields().is_empty() {
            // The placeholder byte of an empty structure. A top-level empty message
            // may also come with no body at all; nested ones must have it, which keeps
            // a sequence of them bounded by the input.
            if depth > 1 || self.left() > 0 {
                self.take(1, path)?;
            }
            return Ok(Value::Map(Vec::new()));
        }
        let mut pairs = Vec::with_capacity(ty.fields().len());
        for f in ty.fields() {
            let v = self.field(f, &path.field(&f.name), depth)?;
            pairs.push((Value::Str(f.name.clone()), v));
        }
        Ok(Value::Map(pairs))
    }

    fn field(&mut self, f: &Field, path: &Path, depth: usize) -> Result<Value, DecodeError> {
        match f.arity {
            Arity::Single => self.element(f.kind, path, depth),
            Arity::Fixed(n) => self.array(f.kind, n, path, depth),
            Arity::Sequence => {
                let count = self.read_u32(path)?;
                let smallest = match f.kind {
                    Kind::Primitive(p) => p.size(),
                    Kind::Message(i) => nested(i).min_size(),
                };
                let left = self.left();
                // u64: `count * smallest` cannot overflow it (u32 times a small size).
                if u64::from(count) * smallest as u64 > left as u64 {
                    return Err(DecodeError::LengthTooLong {
                        location: path.location(self.top),
                        what: "sequence",
                        count,
                        left,
                    });
                }
                self.array(f.kind, count as usize, path, depth)
            }
        }
    }

    fn element(&mut self, kind: Kind, path: &Path, depth: usize) -> Result<Value, DecodeError> {
        match kind {
            Kind::Message(i) => self.struct_(nested(i), path, depth + 1),
            Kind::Primitive(p) => self.primitive(p, path),
        }
    }

    /// `n` elements (already checked against the input for sequences; fixed sizes come
    /// from the static types).
    fn array(&mut self, kind: Kind, n: usize, path: &Path, depth: usize) -> Result<Value, DecodeError> {
        match kind {
            Kind::Primitive(p) if p.is_octet() => Ok(Value::Bytes(self.take(n, path)?.to_vec())),
            Kind::Primitive(p) if p != Primitive::String && p != Primitive::Bool && n > 0 => {
                // Fixed-size numbers: one bounds check for the lot, then convert.
                let size = p.size();
                self.align(size);
                let raw = self.take(n.saturating_mul(size), path)?;
                let mut items = Vec::with_capacity(n);
                for (i, chunk) in raw.chunks_exact(size).enumerate() {
                    items.push(self.number(p, chunk, &path.index(i))?);
                }
                Ok(Value::Array(items))
            }
            _ => {
                let mut items = Vec::with_capacity(n);
                for i in 0..n {
                    items.push(self.element(kind, &path.index(i), depth)?);
                }
                Ok(Value::Array(items))
            }
        }
    }

    fn primitive(&mut self, p: Primitive, path: &Path) -> Result<Value, DecodeError> {
        match p {
            Primitive::Bool => match self.take(1, path)?[0] {
                0 => Ok(Value::Bool(false)),
                1 => Ok(Value::Bool(true)),
                value => Err(DecodeError::BadBool {
                    location: path.location(self.top),
                    value,
                }),
            },
            Primitive::String => self.string(path),
            _ => {
                let size = p.size();
                self.align(size);
                let raw = self.take(size, path)?;
                self.number(p, raw, path)
            }
        }
    }

    /// A number from its `p.size()` raw bytes in the input's order.
    fn number(&self, p: Primitive, raw: &[u8], path: &Path) -> Result<Value, DecodeError> {
        // `raw` is `p.size()` bytes (at most 8); put them in little-endian order.
        let n = raw.len().min(8);
        let mut b8 = [0u8; 8];
        b8[..n].copy_from_slice(&raw[..n]);
        if !self.little_endian {
            b8[..n].reverse();
        }
        let [a0, a1, a2, a3, ..] = b8;
        Ok(match p {
            Primitive::Byte | Primitive::Char | Primitive::UInt8 => Value::Int(i64::from(a0)),
            Primitive::Int8 => Value::Int(i64::from(a0 as i8)),
            Primitive::Int16 => Value::Int(i64::from(i16::from_le_bytes([a0, a1]))),
            Primitive::UInt16 => Value::Int(i64::from(u16::from_le_bytes([a0, a1]))),
            Primitive::Int32 => Value::Int(i64::from(i32::from_le_bytes([a0, a1, a2, a3]))),
            Primitive::UInt32 => Value::Int(i64::from(u32::from_le_bytes([a0, a1, a2, a3]))),
            Primitive::Float32 => Value::Float(f64::from(f32::from_le_bytes([a0, a1, a2, a3]))),
            Primitive::Int64 => Value::Int(i64::from_le_bytes(b8)),
            Primitive::Float64 => Value::Float(f64::from_le_bytes(b8)),
            Primitive::UInt64 => {
                let value = u64::from_le_bytes(b8);
                Value::Int(i64::try_from(value).map_err(|_| DecodeError::IntegerTooLarge {
                    location: path.location(self.top),
                    value,
                })?)
            }
            // Not numbers; `primitive` and `array` route them elsewhere.
            Primitive::Bool | Primitive::String => Value::Nil,
        })
    }

    /// A `string`: `u32` length counting the NUL, the bytes, the NUL. A zero length is
    /// taken as the empty string (some writers send it).
    fn string(&mut self, path: &Path) -> Result<Value, DecodeError> {
        let len = self.read_u32(path)?;
        let left = self.left();
        if len as usize > left {
            return Err(DecodeError::LengthTooLong {
                location: path.location(self.top),
                what: "string",
                count: len,
                left,
            });
        }
        let raw = self.take(len as usize, path)?;
        let Some((&last, text)) = raw.split_last() else {
            return Ok(Value::Str(String::new()));
        };
        if last != 0 {
            return Err(DecodeError::NotTerminated {
                location: path.location(self.top),
            });
        }
        match std::str::from_utf8(text) {
            Ok(s) => Ok(Value::Str(s.to_owned())),
            Err(_) => Err(DecodeError::NotUtf8 {
                location: path.location(self.top),
            }),
        }
    }
}
