//! The one CDR writer: the primitives of plain little-endian CDR (XCDR1) appended to a
//! buffer, for the typed messages of this module, aligned by the same rule
//! (`ros/cdr.rs`) as the dynamic encoder.

use crate::ros::cdr::{CDR_LE_HEADER, pad};

/// Appends one CDR message to a byte buffer.
///
/// A message is the encapsulation header [`CDR_LE_HEADER`] followed by its fields in
/// declaration order. A string is a `uint32` length that counts a terminating NUL, the
/// bytes, then the NUL; a sequence is a `uint32` element count, then the elements.
/// Nested messages add no alignment of their own.
#[derive(Debug, Clone)]
pub struct CdrWriter {
    /// The message so far, header included.
    buf: Vec<u8>,
}

impl Default for CdrWriter {
    fn default() -> Self {
        Self::new()
    }
}

impl CdrWriter {
    /// A message holding only the encapsulation header.
    pub fn new() -> Self {
        Self::with_capacity(64)
    }

    /// [`CdrWriter::new`] with room for `capacity` bytes before it reallocates.
    pub fn with_capacity(capacity: usize) -> Self {
        let mut buf = Vec::with_capacity(capacity.max(CDR_LE_HEADER.len()));
        buf.extend_from_slice(&CDR_LE_HEADER);
        Self { buf }
    }

    fn align(&mut self, n: usize) {
        pad(&mut self.buf, CDR_LE_HEADER.len(), n);
    }

    /// A `uint8` (or `byte`, `char`, `bool`).
    pub fn u8(&mut self, v: u8) {
        self.buf.push(v);
    }

    /// A `uint32`.
    pub fn u32(&mut self, v: u32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// An `int32`.
    pub fn i32(&mut self, v: i32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A `uint64`.
    pub fn u64(&mut self, v: u64) {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// An `int64`.
    pub fn i64(&mut self, v: i64) {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A `uint8[]`: element count, then the bytes (no alignment inside).
    pub fn bytes(&mut self, v: &[u8]) {
        self.sequence_len(v.len());
        self.raw(v);
    }

    /// Bytes of a `uint8[]` whose count was written with [`CdrWriter::sequence_len`],
    /// in parts.
    pub fn raw(&mut self, v: &[u8]) {
        self.buf.extend_from_slice(v);
    }

    /// A `float32`.
    pub fn f32(&mut self, v: f32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A `float64`.
    pub fn f64(&mut self, v: f64) {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A `string`: length with the NUL, bytes, NUL. A string longer than `u32::MAX - 1`
    /// bytes cannot be encoded and is cut there (no published text comes near).
    pub fn string(&mut self, s: &str) {
        let bytes = &s.as_bytes()[..s.len().min(u32::MAX as usize - 1)];
        // Cannot truncate: the length was capped just above.
        self.u32(bytes.len() as u32 + 1);
        self.buf.extend_from_slice(bytes);
        self.buf.push(0);
    }

    /// The element count that starts a sequence (`T[]`); the caller then writes the
    /// elements.
    ///
    /// # Panics
    /// More than `u32::MAX` elements, which CDR cannot express.
    pub fn sequence_len(&mut self, n: usize) {
        self.u32(u32::try_from(n).expect("a CDR sequence holds at most u32::MAX elements"));
    }

    /// A `float64[]`.
    pub fn f64_sequence(&mut self, values: &[f64]) {
        self.sequence_len(values.len());
        for &v in values {
            self.f64(v);
        }
    }

    /// The encoded message, header included.
    pub fn into_bytes(self) -> Vec<u8> {
        self.buf
    }

    /// The bytes so far, header included.
    pub fn as_bytes(&self) -> &[u8] {
        &self.buf
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_empty_message_is_the_little_endian_header() {
        assert_eq!(CdrWriter::new().into_bytes(), vec![0, 1, 0, 0]);
    }

    #[test]
    fn primitives_align_to_their_size_after_the_header() {
        let mut w = CdrWriter::new();
        w.u8(7);
        w.u32(0x0403_0201);
        w.u8(9);
        w.f64(1.0);
        assert_eq!(
            w.into_bytes(),
            vec![
                0, 1, 0, 0, // header
                7, 0, 0, 0, // u8, padded to 4
                1, 2, 3, 4, // u32
                9, 0, 0, 0, 0, 0, 0, 0, // u8, padded to 8 (offset 9 -> 16)
                0, 0, 0, 0, 0, 0, 0xf0, 0x3f, // 1.0
            ]
        );
    }

    #[test]
    fn an_int32_then_a_float64_pads_four_bytes() {
        let mut w = CdrWriter::new();
        w.i32(-1);
        w.f64(-2.0);
        assert_eq!(
            w.into_bytes(),
            vec![
                0, 1, 0, 0, 0xff, 0xff, 0xff, 0xff, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xc0
            ]
        );
    }

    #[test]
    fn strings_count_their_terminating_nul() {
        let mut w = CdrWriter::new();
        w.string("ab");
        w.string("");
        w.f32(1.5);
        assert_eq!(
            w.into_bytes(),
            vec![
                0, 1, 0, 0, // header
                3, 0, 0, 0, b'a', b'b', 0, // "ab"
                0, // pad to 4
                1, 0, 0, 0, 0, // ""
                0, 0, 0, // pad to 4
                0, 0, 0xc0, 0x3f, // 1.5f32
            ]
        );
    }

    #[test]
    fn a_float64_sequence_is_a_count_then_aligned_values() {
        let mut w = CdrWriter::new();
        w.f64_sequence(&[0.5, 0.25]);
        w.f64_sequence(&[]);
        let b = w.into_bytes();
        assert_eq!(&b[4..8], &[2, 0, 0, 0]);
        assert_eq!(&b[8..12], &[0, 0, 0, 0], "pad to 8");
        assert_eq!(&b[12..20], &0.5f64.to_le_bytes());
        assert_eq!(&b[20..28], &0.25f64.to_le_bytes());
        assert_eq!(&b[28..], &[0, 0, 0, 0], "an empty sequence is its count");
    }
}
