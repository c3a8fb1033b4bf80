//! Typed reads from a chunk payload: little-endian integers, f32/f64 values and the
//! length-prefixed strings, each checked against the bytes that remain.
//!
//! Most values exist in two variants since CoppeliaSim 4.5/4.6 moved to doubles: an older
//! f32 chunk (`Cfq`, `Pmr`, `Mas`, ...) and a newer f64 one (`_fq`, `_mr`, `_as`, ...).
//! [`Fields::reals`] reads either into f64, so each reader handles both tags with one arm.

use crate::chunk::{At, Chunk};
use crate::error::ReadError;

/// A cursor over one chunk's payload.
pub struct Fields<'a, 'p> {
    bytes: &'a [u8],
    pos: usize,
    at: At<'p>,
}

impl<'a, 'p> Fields<'a, 'p> {
    /// Reads the payload of `chunk`, found inside `parent`.
    pub fn new(chunk: &Chunk<'a>, parent: &'p At<'p>) -> Self {
        Fields {
            bytes: chunk.payload,
            pos: 0,
            at: parent.child(chunk.tag, chunk.offset),
        }
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], ReadError> {
        let end = self.pos.checked_add(n).filter(|&end| end <= self.bytes.len());
        let Some(end) = end else {
            return Err(self.at.value_error(format!(
                "payload of {} bytes is too short: needs {} more at byte {}",
                self.bytes.len(),
                n,
                self.pos
            )));
        };
        let out = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(out)
    }

    fn array<const N: usize>(&mut self) -> Result<[u8; N], ReadError> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.take(N)?);
        Ok(a)
    }

    /// A byte.
    pub fn u8(&mut self) -> Result<u8, ReadError> {
        Ok(self.take(1)?[0])
    }

    /// A little-endian u16.
    pub fn u16(&mut self) -> Result<u16, ReadError> {
        Ok(u16::from_le_bytes(self.array()?))
    }

    /// A little-endian i32.
    pub fn i32(&mut self) -> Result<i32, ReadError> {
        Ok(i32::from_le_bytes(self.array()?))
    }

    /// A little-endian u64.
    pub fn u64(&mut self) -> Result<u64, ReadError> {
        Ok(u64::from_le_bytes(self.array()?))
    }

    /// A little-endian f32, widened.
    pub fn f32(&mut self) -> Result<f64, ReadError> {
        Ok(f64::from(f32::from_le_bytes(self.array()?)))
    }

    /// A little-endian f64.
    pub fn f64(&mut self) -> Result<f64, ReadError> {
        Ok(f64::from_le_bytes(self.array()?))
    }

    /// `N` reals, stored as f64 when `double` and as f32 otherwise.
    pub fn reals<const N: usize>(&mut self, double: bool) -> Result<[f64; N], ReadError> {
        let mut out = [0.0; N];
        for v in &mut out {
            *v = if double { self.f64()? } else { self.f32()? };
        }
        Ok(out)
    }

    /// An i32 length then that many bytes, as text (invalid UTF-8 replaced).
    pub fn string(&mut self) -> Result<String, ReadError> {
        let len = self.i32()?;
        let Ok(len) = usize::try_from(len) else {
            return Err(self.at.value_error(format!("string length {len} is negative")));
        };
        let bytes = self.take(len)?;
        Ok(String::from_utf8_lossy(bytes).into_owned())
    }
}

/// Whether a tag is the f64 variant of a pair: the newer tags start with `_`.
pub fn is_double(tag: [u8; 3]) -> bool {
    tag[0] == b'_'
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_values_and_refuses_short_payloads() {
        let mut payload = Vec::new();
        payload.extend_from_slice(&7i32.to_le_bytes());
        payload.extend_from_slice(&1.5f32.to_le_bytes());
        payload.extend_from_slice(&(-2.25f64).to_le_bytes());
        payload.extend_from_slice(&3i32.to_le_bytes());
        payload.extend_from_slice(b"abc");
        let top = At::top();
        let chunk = Chunk {
            tag: *b"Tst",
            payload: &payload,
            offset: 40,
        };
        let mut f = Fields::new(&chunk, &top);
        assert_eq!(f.i32().unwrap(), 7);
        assert_eq!(f.reals::<1>(false).unwrap(), [1.5]);
        assert_eq!(f.reals::<1>(true).unwrap(), [-2.25]);
        assert_eq!(f.string().unwrap(), "abc");
        let err = f.u8().unwrap_err();
        assert!(err.to_string().contains("Tst (body byte 40)"), "{err}");

        // A string whose length runs past the payload.
        let mut payload = 1000i32.to_le_bytes().to_vec();
        payload.extend_from_slice(b"short");
        let chunk = Chunk {
            tag: *b"Nme",
            payload: &payload,
            offset: 0,
        };
        assert!(Fields::new(&chunk, &top).string().is_err());
        let chunk = Chunk {
            tag: *b"Nme",
            payload: &(-1i32).to_le_bytes(),
            offset: 0,
        };
        assert!(Fields::new(&chunk, &top).string().is_err());
    }
}
