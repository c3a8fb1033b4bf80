//! A CBOR (RFC 8949) codec for [`Value`], written here rather than pulled in so that its
//! bounds are ours to guarantee: the ZMQ remote API decodes every peer message with it.
//!
//! Decoding accepts everything the Python (`cbor2`, `cbor`), Lua (`org.conman.cbor`) and
//! C++ clients send, plus the rest of the data model that maps onto [`Value`]: all integer
//! widths, half/single/double floats, definite and indefinite strings, arrays and maps.
//! Tags are skipped (their content is kept). `undefined` becomes `Nil` like `null`.
//!
//! Refused, with an error rather than a guess:
//! * integers outside `i64` (e.g. `2^64-1`): converting them to a float would silently
//!   lose precision on what is most likely a handle or a counter;
//! * simple values other than false/true/null/undefined, and reserved encodings;
//! * nesting deeper than [`MAX_DEPTH`] and more than [`MAX_ITEMS`] items.
//!
//! Encoding is deterministic and compact: shortest integer heads, definite lengths, and
//! floats always as 8-byte doubles (what the Python client sends, and lossless).

use thiserror::Error;

use crate::Value;

/// Deepest nesting of arrays and maps accepted (the top-level item is depth 1).
pub const MAX_DEPTH: usize = 64;
/// Most data items (every array element, map key and map value counts) in one message.
pub const MAX_ITEMS: usize = 1_000_000;

/// Why bytes are not one acceptable CBOR item.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum CborError {
    /// The input ends in the middle of an item.
    #[error("CBOR input truncated at byte {offset}: the message is incomplete")]
    Truncated {
        /// Where more bytes were needed.
        offset: usize,
    },
    /// Bytes follow the single top-level item.
    #[error("{count} unexpected bytes after the CBOR item at byte {offset}; send exactly one item per message")]
    TrailingBytes {
        /// Where the extra bytes start.
        offset: usize,
        /// How many there are.
        count: usize,
    },
    /// An integer does not fit in `i64`.
    #[error("CBOR integer at byte {offset} does not fit in a signed 64-bit integer")]
    IntegerOutOfRange {
        /// Where the integer starts.
        offset: usize,
    },
    /// A text string is not valid UTF-8.
    #[error("CBOR text string at byte {offset} is not valid UTF-8; send binary data as a byte string")]
    InvalidUtf8 {
        /// Where the string (or chunk) starts.
        offset: usize,
    },
    /// A reserved or malformed initial byte.
    #[error("malformed CBOR: byte {byte:#04x} at offset {offset} is reserved or not allowed here")]
    Malformed {
        /// Where the byte is.
        offset: usize,
        /// The initial byte.
        byte: u8,
    },
    /// A break (0xff) outside an indefinite-length item, or between a map key and value.
    #[error("malformed CBOR: unexpected break byte at offset {offset}")]
    UnexpectedBreak {
        /// Where the break is.
        offset: usize,
    },
    /// A chunk of an indefinite-length string is not a definite string of the same type.
    #[error(
        "malformed CBOR: chunk at offset {offset} of an indefinite-length string must be a definite string of the same type"
    )]
    BadChunk {
        /// Where the chunk starts.
        offset: usize,
    },
    /// A simple value with no [`Value`] equivalent (not false/true/null/undefined).
    #[error("unsupported CBOR simple value {value} at offset {offset}; use false, true or null")]
    UnsupportedSimple {
        /// Where it is.
        offset: usize,
        /// The simple value number.
        value: u8,
    },
    /// Arrays and maps nest deeper than [`MAX_DEPTH`].
    #[error("CBOR nesting deeper than {max} levels; flatten the data")]
    TooDeep {
        /// The limit.
        max: usize,
    },
    /// More than [`MAX_ITEMS`] data items.
    #[error("CBOR message has more than {max} items; send smaller messages")]
    TooManyItems {
        /// The limit.
        max: usize,
    },
}

/// Decodes `bytes`, which must hold exactly one CBOR item.
///
/// Total and bounded: never panics, and never allocates more than the input could fill
/// (every element takes at least one byte, so a claimed length is capped by what is left).
/// The caller bounds the input size itself (the transport's message size limit).
pub fn decode(bytes: &[u8]) -> Result<Value, CborError> {
    let mut d = Decoder {
        input: bytes,
        pos: 0,
        items: 0,
    };
    let v = d.item(1)?;
    if d.pos < bytes.len() {
        return Err(CborError::TrailingBytes {
            offset: d.pos,
            count: bytes.len() - d.pos,
        });
    }
    Ok(v)
}

/// Appends the CBOR encoding of `v` to `out`.
///
/// Recursion follows the value's nesting; values from [`decode`] are at most
/// [`MAX_DEPTH`] deep, and callers build their own values shallow.
pub fn encode(v: &Value, out: &mut Vec<u8>) {
    match v {
        Value::Nil => out.push(0xf6),
        Value::Bool(false) => out.push(0xf4),
        Value::Bool(true) => out.push(0xf5),
        Value::Int(i) if *i >= 0 => head(out, 0, i.unsigned_abs()),
        // -1 - i without overflow: for negative i that is the bitwise complement.
        Value::Int(i) => head(out, 1, !*i as u64),
        Value::Float(f) => {
            out.push(0xfb);
            out.extend_from_slice(&f.to_bits().to_be_bytes());
        }
        Value::Str(s) => {
            head(out, 3, s.len() as u64);
            out.extend_from_slice(s.as_bytes());
        }
        Value::Bytes(b) => {
            head(out, 2, b.len() as u64);
            out.extend_from_slice(b);
        }
        Value::Array(items) => {
            head(out, 4, items.len() as u64);
            for item in items {
                encode(item, out);
            }
        }
        Value::Map(pairs) => {
            head(out, 5, pairs.len() as u64);
            for (k, v) in pairs {
                encode(k, out);
                encode(v, out);
            }
        }
    }
}

/// Convenience: the encoding of `v` in a new vector.
pub fn to_vec(v: &Value) -> Vec<u8> {
    let mut out = Vec::new();
    encode(v, &mut out);
    out
}

/// Writes an initial byte plus argument in the shortest form (RFC 8949 §4.2.1).
fn head(out: &mut Vec<u8>, major: u8, n: u64) {
    let m = major << 5;
    if n < 24 {
        out.push(m | n as u8);
    } else if let Ok(n) = u8::try_from(n) {
        out.extend_from_slice(&[m | 24, n]);
    } else if let Ok(n) = u16::try_from(n) {
        out.push(m | 25);
        out.extend_from_slice(&n.to_be_bytes());
    } else if let Ok(n) = u32::try_from(n) {
        out.push(m | 26);
        out.extend_from_slice(&n.to_be_bytes());
    } else {
        out.push(m | 27);
        out.extend_from_slice(&n.to_be_bytes());
    }
}

/// Additional-info value meaning "indefinite length" (or "break" for major type 7).
const INDEFINITE: u8 = 31;
const BREAK: u8 = 0xff;

/// The decoded initial byte and argument of an item.
struct Head {
    /// Offset of the initial byte.
    offset: usize,
    major: u8,
    /// Low five bits of the initial byte.
    info: u8,
    /// The argument; meaningless when `info` is [`INDEFINITE`].
    arg: u64,
}

struct Decoder<'a> {
    input: &'a [u8],
    pos: usize,
    items: usize,
}

impl Decoder<'_> {
    fn remaining(&self) -> usize {
        self.input.len().saturating_sub(self.pos)
    }

    fn take(&mut self, n: usize) -> Result<&[u8], CborError> {
        let end = self
            .pos
            .checked_add(n)
            .filter(|&e| e <= self.input.len())
            .ok_or(CborError::Truncated {
                offset: self.input.len(),
            })?;
        let s = self.input.get(self.pos..end).ok_or(CborError::Truncated {
            offset: self.input.len(),
        })?;
        self.pos = end;
        Ok(s)
    }

    fn take_array<const N: usize>(&mut self) -> Result<[u8; N], CborError> {
        let s = self.take(N)?;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        Ok(a)
    }

    fn peek(&self) -> Option<u8> {
        self.input.get(self.pos).copied()
    }

    fn head(&mut self) -> Result<Head, CborError> {
        let offset = self.pos;
        let [byte] = self.take_array::<1>()?;
        let (major, info) = (byte >> 5, byte & 0x1f);
        let arg = match info {
            0..=23 => u64::from(info),
            24 => u64::from(self.take_array::<1>()?[0]),
            25 => u64::from(u16::from_be_bytes(self.take_array()?)),
            26 => u64::from(u32::from_be_bytes(self.take_array()?)),
            27 => u64::from_be_bytes(self.take_array()?),
            // Indefinite length exists only for strings, arrays and maps; for major 7 it
            // is the break byte, which only the container loops may consume.
            INDEFINITE if matches!(major, 2..=5) => 0,
            INDEFINITE if major == 7 => return Err(CborError::UnexpectedBreak { offset }),
            _ => return Err(CborError::Malformed { offset, byte }),
        };
        Ok(Head {
            offset,
            major,
            info,
            arg,
        })
    }

    fn count_item(&mut self) -> Result<(), CborError> {
        self.items += 1;
        if self.items > MAX_ITEMS {
            return Err(CborError::TooManyItems { max: MAX_ITEMS });
        }
        Ok(())
    }

    /// Consumes a break byte if one is next (the end of an indefinite-length item).
    fn at_break(&mut self) -> Result<bool, CborError> {
        match self.peek() {
            Some(BREAK) => {
                self.pos += 1;
                Ok(true)
            }
            Some(_) => Ok(false),
            None => Err(CborError::Truncated { offset: self.pos }),
        }
    }

    /// A length argument as `usize`; a length beyond the address space cannot fit in the
    /// input either, so it is reported as truncation.
    fn len(&self, h: &Head) -> Result<usize, CborError> {
        usize::try_from(h.arg).map_err(|_| CborError::Truncated {
            offset: self.input.len(),
        })
    }

    fn item(&mut self, depth: usize) -> Result<Value, CborError> {
        self.count_item()?;
        // Tags are skipped in a loop, not by recursion, so a long tag chain cannot
        // exhaust the stack; each tag consumes input, so the loop is bounded.
        let h = loop {
            let h = self.head()?;
            if h.major != 6 {
                break h;
            }
        };
        match h.major {
            0 => i64::try_from(h.arg)
                .map(Value::Int)
                .map_err(|_| CborError::IntegerOutOfRange { offset: h.offset }),
            // The value is -1 - arg; arg <= i64::MAX keeps that within i64.
            1 => i64::try_from(h.arg)
                .map(|n| Value::Int(-1 - n))
                .map_err(|_| CborError::IntegerOutOfRange { offset: h.offset }),
            2 => self.bytes(&h).map(Value::Bytes),
            3 => {
                let b = self.bytes(&h)?;
                String::from_utf8(b)
                    .map(Value::Str)
                    .map_err(|_| CborError::InvalidUtf8 { offset: h.offset })
            }
            4 => self.array(&h, depth),
            5 => self.map(&h, depth),
            _ => self.simple(&h),
        }
    }

    /// The payload of a byte or text string (major 2 or 3), joining indefinite chunks.
    fn bytes(&mut self, h: &Head) -> Result<Vec<u8>, CborError> {
        if h.info != INDEFINITE {
            let n = self.len(h)?;
            return Ok(self.take(n)?.to_vec());
        }
        let mut out = Vec::new();
        while !self.at_break()? {
            let chunk = self.head()?;
            if chunk.major != h.major || chunk.info == INDEFINITE {
                return Err(CborError::BadChunk { offset: chunk.offset });
            }
            let n = self.len(&chunk)?;
            let data = self.take(n)?;
            // RFC 8949 §3.2.3: each text chunk must be valid UTF-8 on its own.
            if h.major == 3 && std::str::from_utf8(data).is_err() {
                return Err(CborError::InvalidUtf8 { offset: chunk.offset });
            }
            out.extend_from_slice(data);
        }
        Ok(out)
    }

    fn enter(depth: usize) -> Result<usize, CborError> {
        if depth > MAX_DEPTH {
            return Err(CborError::TooDeep { max: MAX_DEPTH });
        }
        Ok(depth + 1)
    }

    fn array(&mut self, h: &Head, depth: usize) -> Result<Value, CborError> {
        let inner = Self::enter(depth)?;
        if h.info == INDEFINITE {
            let mut items = Vec::new();
            while !self.at_break()? {
                items.push(self.item(inner)?);
            }
            return Ok(Value::Array(items));
        }
        let n = self.len(h)?;
        // Each element is at least one byte, so a lying length cannot over-allocate.
        let mut items = Vec::with_capacity(n.min(self.remaining()));
        for _ in 0..n {
            items.push(self.item(inner)?);
        }
        Ok(Value::Array(items))
    }

    fn map(&mut self, h: &Head, depth: usize) -> Result<Value, CborError> {
        let inner = Self::enter(depth)?;
        if h.info == INDEFINITE {
            let mut pairs = Vec::new();
            while !self.at_break()? {
                let k = self.item(inner)?;
                if self.peek() == Some(BREAK) {
                    return Err(CborError::UnexpectedBreak { offset: self.pos });
                }
                let v = self.item(inner)?;
                pairs.push((k, v));
            }
            return Ok(Value::Map(pairs));
        }
        let n = self.len(h)?;
        // Each pair is at least two bytes.
        let mut pairs = Vec::with_capacity(n.min(self.remaining() / 2));
        for _ in 0..n {
            let k = self.item(inner)?;
            let v = self.item(inner)?;
            pairs.push((k, v));
        }
        Ok(Value::Map(pairs))
    }

    fn simple(&mut self, h: &Head) -> Result<Value, CborError> {
        match h.info {
            20 => Ok(Value::Bool(false)),
            21 => Ok(Value::Bool(true)),
            22 | 23 => Ok(Value::Nil),
            // head() has read 2, 4 or 8 bytes of argument for these; they fit by construction.
            25 => Ok(Value::Float(f16_to_f64(h.arg as u16))),
            26 => Ok(Value::Float(f64::from(f32::from_bits(h.arg as u32)))),
            27 => Ok(Value::Float(f64::from_bits(h.arg))),
            // 0..=19 and one-byte simple values (info 24): no Value equivalent.
            _ => Err(CborError::UnsupportedSimple {
                offset: h.offset,
                value: h.arg as u8,
            }),
        }
    }
}

/// IEEE 754 binary16 to f64, exactly (every half value is representable as a double).
fn f16_to_f64(h: u16) -> f64 {
    let negative = h & 0x8000 != 0;
    let exp = i32::from((h >> 10) & 0x1f);
    let mant = u64::from(h & 0x03ff);
    let sign_bit = u64::from(negative) << 63;
    match exp {
        // Subnormal (or zero): mant * 2^-24.
        0 => {
            let mag = mant as f64 * f64::from_bits(0x3e70_0000_0000_0000); // 2^-24
            if negative { -mag } else { mag }
        }
        // Infinity or NaN; keep the NaN payload in the top mantissa bits.
        31 => f64::from_bits(sign_bit | 0x7ff0_0000_0000_0000 | (mant << 42)),
        // Normal: rebias the exponent from 15 to 1023 and widen the mantissa.
        _ => f64::from_bits(sign_bit | (((exp + 1008) as u64) << 52) | (mant << 42)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hex(s: &str) -> Vec<u8> {
        (0..s.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
            .collect()
    }

    fn s(x: &str) -> Value {
        Value::Str(x.into())
    }
    fn i(x: i64) -> Value {
        Value::Int(x)
    }
    fn arr(v: Vec<Value>) -> Value {
        Value::Array(v)
    }
    fn map(v: Vec<(Value, Value)>) -> Value {
        Value::Map(v)
    }

    /// Bitwise equality, so NaNs compare equal to themselves.
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

    /// RFC 8949 Appendix A vectors that map onto `Value`: (hex, expected, canonical).
    /// `canonical` means our encoder must produce exactly these bytes.
    fn appendix_a() -> Vec<(&'static str, Value, bool)> {
        let one_to_25: Vec<Value> = (1..=25).map(i).collect();
        vec![
            ("00", i(0), true),
            ("01", i(1), true),
            ("0a", i(10), true),
            ("17", i(23), true),
            ("1818", i(24), true),
            ("1819", i(25), true),
            ("1864", i(100), true),
            ("1903e8", i(1000), true),
            ("1a000f4240", i(1_000_000), true),
            ("1b000000e8d4a51000", i(1_000_000_000_000), true),
            ("20", i(-1), true),
            ("29", i(-10), true),
            ("3863", i(-100), true),
            ("3903e7", i(-1000), true),
            ("f90000", Value::Float(0.0), false),
            ("f98000", Value::Float(-0.0), false),
            ("f93c00", Value::Float(1.0), false),
            ("fb3ff199999999999a", Value::Float(1.1), true),
            ("f93e00", Value::Float(1.5), false),
            ("f97bff", Value::Float(65504.0), false),
            ("fa47c35000", Value::Float(100000.0), false),
            ("fa7f7fffff", Value::Float(3.4028234663852886e38), false),
            ("fb7e37e43c8800759c", Value::Float(1.0e300), true),
            ("f90001", Value::Float(5.960464477539063e-8), false),
            ("f90400", Value::Float(0.00006103515625), false),
            ("f9c400", Value::Float(-4.0), false),
            ("fbc010666666666666", Value::Float(-4.1), true),
            ("f97c00", Value::Float(f64::INFINITY), false),
            ("f9fc00", Value::Float(f64::NEG_INFINITY), false),
            ("fa7f800000", Value::Float(f64::INFINITY), false),
            ("faff800000", Value::Float(f64::NEG_INFINITY), false),
            ("fb7ff0000000000000", Value::Float(f64::INFINITY), true),
            ("fbfff0000000000000", Value::Float(f64::NEG_INFINITY), true),
            ("f4", Value::Bool(false), true),
            ("f5", Value::Bool(true), true),
            ("f6", Value::Nil, true),
            ("f7", Value::Nil, false),
            (
                "c074323031332d30332d32315432303a30343a30305a",
                s("2013-03-21T20:04:00Z"),
                false,
            ),
            ("c11a514b67b0", i(1363896240), false),
            ("c1fb41d452d9ec200000", Value::Float(1363896240.5), false),
            ("d74401020304", Value::Bytes(vec![1, 2, 3, 4]), false),
            ("d818456449455446", Value::Bytes(hex("6449455446")), false),
            (
                "d82076687474703a2f2f7777772e6578616d706c652e636f6d",
                s("http://www.example.com"),
                false,
            ),
            ("40", Value::Bytes(vec![]), true),
            ("4401020304", Value::Bytes(vec![1, 2, 3, 4]), true),
            ("60", s(""), true),
            ("6161", s("a"), true),
            ("6449455446", s("IETF"), true),
            ("62225c", s("\"\\"), true),
            ("62c3bc", s("\u{fc}"), true),
            ("63e6b0b4", s("\u{6c34}"), true),
            ("64f0908591", s("\u{10151}"), true),
            ("80", arr(vec![]), true),
            ("83010203", arr(vec![i(1), i(2), i(3)]), true),
            (
                "8301820203820405",
                arr(vec![i(1), arr(vec![i(2), i(3)]), arr(vec![i(4), i(5)])]),
                true,
            ),
            (
                "98190102030405060708090a0b0c0d0e0f101112131415161718181819",
                arr(one_to_25.clone()),
                true,
            ),
            ("a0", map(vec![]), true),
            ("a201020304", map(vec![(i(1), i(2)), (i(3), i(4))]), true),
            (
                "a26161016162820203",
                map(vec![(s("a"), i(1)), (s("b"), arr(vec![i(2), i(3)]))]),
                true,
            ),
            ("826161a161626163", arr(vec![s("a"), map(vec![(s("b"), s("c"))])]), true),
            (
                "a56161614161626142616361436164614461656145",
                map(vec![
                    (s("a"), s("A")),
                    (s("b"), s("B")),
                    (s("c"), s("C")),
                    (s("d"), s("D")),
                    (s("e"), s("E")),
                ]),
                true,
            ),
            ("5f42010243030405ff", Value::Bytes(vec![1, 2, 3, 4, 5]), false),
            ("7f657374726561646d696e67ff", s("streaming"), false),
            ("9fff", arr(vec![]), false),
            (
                "9f018202039f0405ffff",
                arr(vec![i(1), arr(vec![i(2), i(3)]), arr(vec![i(4), i(5)])]),
                false,
            ),
            (
                "9f01820203820405ff",
                arr(vec![i(1), arr(vec![i(2), i(3)]), arr(vec![i(4), i(5)])]),
                false,
            ),
            (
                "83018202039f0405ff",
                arr(vec![i(1), arr(vec![i(2), i(3)]), arr(vec![i(4), i(5)])]),
                false,
            ),
            (
                "83019f0203ff820405",
                arr(vec![i(1), arr(vec![i(2), i(3)]), arr(vec![i(4), i(5)])]),
                false,
            ),
            (
                "9f0102030405060708090a0b0c0d0e0f101112131415161718181819ff",
                arr(one_to_25),
                false,
            ),
            (
                "bf61610161629f0203ffff",
                map(vec![(s("a"), i(1)), (s("b"), arr(vec![i(2), i(3)]))]),
                false,
            ),
            (
                "826161bf61626163ff",
                arr(vec![s("a"), map(vec![(s("b"), s("c"))])]),
                false,
            ),
            (
                "bf6346756ef563416d7421ff",
                map(vec![(s("Fun"), Value::Bool(true)), (s("Amt"), i(-2))]),
                false,
            ),
        ]
    }

    #[test]
    fn rfc8949_appendix_a() {
        for (h, want, canonical) in appendix_a() {
            let bytes = hex(h);
            let got = decode(&bytes).unwrap_or_else(|e| panic!("{h}: {e}"));
            assert!(same(&got, &want), "{h}: got {got:?}, want {want:?}");
            if canonical {
                assert_eq!(to_vec(&want), bytes, "encoding of {want:?}");
            }
        }
    }

    #[test]
    fn half_float_nans_and_subnormals() {
        let Value::Float(f) = decode(&hex("f97e00")).unwrap() else {
            panic!()
        };
        assert!(f.is_nan());
        let Value::Float(f) = decode(&hex("fa7fc00000")).unwrap() else {
            panic!()
        };
        assert!(f.is_nan());
        let Value::Float(f) = decode(&hex("f983ff")).unwrap() else {
            panic!()
        };
        assert_eq!(f, -(1023.0 * 2f64.powi(-24)));
        // Every half value equals what f32 arithmetic gives, checked against a slow formula.
        for h in 0..=u16::MAX {
            let got = f16_to_f64(h);
            let exp = i32::from((h >> 10) & 0x1f);
            let mant = f64::from(h & 0x3ff);
            let mag = match exp {
                0 => mant * 2f64.powi(-24),
                31 if mant == 0.0 => f64::INFINITY,
                31 => f64::NAN,
                _ => (1024.0 + mant) * 2f64.powi(exp - 25),
            };
            let want = if h & 0x8000 != 0 { -mag } else { mag };
            assert!(got == want || (got.is_nan() && want.is_nan()), "{h:#06x}");
        }
    }

    #[test]
    fn integer_limits() {
        for v in [
            i64::MIN,
            i64::MIN + 1,
            -25,
            -24,
            -1,
            0,
            255,
            256,
            65535,
            65536,
            i64::MAX,
        ] {
            assert_eq!(decode(&to_vec(&i(v))).unwrap(), i(v), "{v}");
        }
        assert_eq!(to_vec(&i(i64::MIN)), hex("3b7fffffffffffffff"));
        assert_eq!(
            decode(&hex("1bffffffffffffffff")),
            Err(CborError::IntegerOutOfRange { offset: 0 })
        );
        assert_eq!(
            decode(&hex("1b8000000000000000")),
            Err(CborError::IntegerOutOfRange { offset: 0 })
        );
        assert_eq!(
            decode(&hex("3b8000000000000000")),
            Err(CborError::IntegerOutOfRange { offset: 0 })
        );
    }

    #[test]
    fn errors() {
        use CborError as E;
        let cases: &[(&str, CborError)] = &[
            ("", E::Truncated { offset: 0 }),
            ("0000", E::TrailingBytes { offset: 1, count: 1 }),
            ("1c", E::Malformed { offset: 0, byte: 0x1c }),
            ("1f", E::Malformed { offset: 0, byte: 0x1f }),
            ("df", E::Malformed { offset: 0, byte: 0xdf }),
            ("ff", E::UnexpectedBreak { offset: 0 }),
            ("81ff", E::UnexpectedBreak { offset: 1 }),
            ("bf01ff", E::UnexpectedBreak { offset: 2 }),
            ("62c328", E::InvalidUtf8 { offset: 0 }),
            ("7f61c361bcff", E::InvalidUtf8 { offset: 1 }),
            ("5f6161ff", E::BadChunk { offset: 1 }),
            ("5f5f4001ffff", E::BadChunk { offset: 1 }),
            ("f0", E::UnsupportedSimple { offset: 0, value: 16 }),
            ("f8ff", E::UnsupportedSimple { offset: 0, value: 255 }),
            ("fc", E::Malformed { offset: 0, byte: 0xfc }),
            ("5bffffffffffffffff", E::Truncated { offset: 9 }),
            ("9bffffffffffffffff", E::Truncated { offset: 9 }),
            ("bbffffffffffffffff", E::Truncated { offset: 9 }),
            ("9f", E::Truncated { offset: 1 }),
        ];
        for (h, want) in cases {
            assert_eq!(decode(&hex(h)).as_ref(), Err(want), "{h}");
        }
    }

    #[test]
    fn nesting_limit() {
        let nested = |n: usize| {
            let mut b = vec![0x81; n - 1];
            b.push(0x80);
            b
        };
        assert!(decode(&nested(MAX_DEPTH)).is_ok());
        assert_eq!(
            decode(&nested(MAX_DEPTH + 1)),
            Err(CborError::TooDeep { max: MAX_DEPTH })
        );
        let mut indef = vec![0x9f; 100_000];
        indef.push(0xff);
        assert_eq!(decode(&indef), Err(CborError::TooDeep { max: MAX_DEPTH }));
        let mut maps = [0xa1, 0x00].repeat(MAX_DEPTH + 1);
        maps.push(0x00);
        assert_eq!(decode(&maps), Err(CborError::TooDeep { max: MAX_DEPTH }));
        // A long tag chain is not nesting and must not recurse.
        let mut tags = vec![0xc1; 200_000];
        tags.push(0x01);
        assert_eq!(decode(&tags), Ok(i(1)));
    }

    #[test]
    fn item_limit() {
        let mut b = vec![0x9f];
        b.extend(std::iter::repeat_n(0x00, MAX_ITEMS));
        b.push(0xff);
        assert_eq!(decode(&b), Err(CborError::TooManyItems { max: MAX_ITEMS }));
        let mut b = vec![0x9a];
        b.extend_from_slice(&u32::try_from(MAX_ITEMS - 1).unwrap().to_be_bytes());
        b.extend(std::iter::repeat_n(0x00, MAX_ITEMS - 1));
        assert!(decode(&b).is_ok());
    }

    /// A message exercising every variant; `big` adds a 70 kB byte string.
    fn sample(big: bool) -> Value {
        let mut args = vec![
            i(17),
            i(-1),
            Value::Float(f64::NAN),
            Value::Float(-0.0),
            Value::Nil,
            Value::Bool(true),
            Value::Bytes(vec![0, 255, 7]),
            Value::floats(&[0.5, -0.25, 1.0]),
            map(vec![(i(1), Value::Nil), (Value::Bool(false), arr(vec![]))]),
            s("水"),
            i(i64::MIN),
            i(i64::MAX),
            s(&"x".repeat(300)),
        ];
        if big {
            args.push(Value::Bytes(vec![9; 70_000]));
        }
        map(vec![(s("func"), s("sim.getObjectPosition")), (s("args"), arr(args))])
    }

    #[test]
    fn round_trip() {
        let v = sample(true);
        let bytes = to_vec(&v);
        assert!(same(&decode(&bytes).unwrap(), &v));
        for (h, want, _) in appendix_a() {
            let again = decode(&to_vec(&want)).unwrap();
            assert!(same(&again, &want), "{h}");
        }
    }

    #[test]
    fn every_truncation_is_an_error() {
        let mut inputs: Vec<Vec<u8>> = appendix_a().iter().map(|(h, _, _)| hex(h)).collect();
        inputs.push(to_vec(&sample(false)));
        for full in inputs {
            for n in 0..full.len() {
                assert!(decode(&full[..n]).is_err(), "prefix {n} of {full:02x?}");
            }
        }
    }

    #[test]
    fn lying_lengths_do_not_allocate() {
        // Claims 2^32-1 elements / pairs / bytes with nothing behind them.
        for h in ["9affffffff", "baffffffff", "5affffffff", "7affffffff"] {
            assert_eq!(decode(&hex(h)), Err(CborError::Truncated { offset: 5 }), "{h}");
        }
    }
}
