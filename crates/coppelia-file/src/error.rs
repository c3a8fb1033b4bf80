//! The reader's error type: what was wrong, and where.
//!
//! Offsets count bytes of the *decoded* body (the chunk stream after Huffman decoding),
//! except for [`ReadError::Header`] and [`ReadError::Huffman`], which count bytes of the
//! file itself. A chunk path such as `SHP/Ge2/Gsg/Geo/Vev` names the chain of tags from
//! the top level down to the chunk that failed.

use thiserror::Error;

/// Why a file could not be read.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ReadError {
    /// The 1,021-byte header is missing, short or not a CoppeliaSim header.
    #[error("not a CoppeliaSim scene or model file: {0}")]
    Header(String),
    /// The file was written with a serialization version CoppeliaSim itself no longer
    /// reads (it reads 18 and later, i.e. V-REP 3.2 from 2014 on).
    #[error(
        "serialization version {version} is too old (CoppeliaSim reads {min} and later); \
         re-save the file with CoppeliaSim 4.x"
    )]
    UnsupportedVersion {
        /// The version in the header.
        version: i32,
        /// The oldest version this reader accepts.
        min: i32,
    },
    /// The header names a compression method other than Huffman (1).
    #[error("compression method {0} is not supported (only 1, Huffman)")]
    UnsupportedCompression(u8),
    /// The header's decoded length is negative, beyond the reader's cap or impossible for
    /// the number of compressed bytes that follow.
    #[error("decoded body length {len} is out of bounds ({why})")]
    BodyLength {
        /// The length in the header.
        len: i64,
        /// Which bound it broke.
        why: &'static str,
    },
    /// The Huffman tree or the coded data is corrupt.
    #[error("corrupt Huffman data at file byte {offset}: {why}")]
    Huffman {
        /// Byte of the file (header included) where the problem was found.
        offset: usize,
        /// What was wrong.
        why: &'static str,
    },
    /// The chunk stream is malformed: a chunk runs past its container, a length is
    /// negative, an object lacks its end marker, nesting is too deep.
    #[error("malformed chunk stream at {path} (body byte {offset}): {why}")]
    Chunk {
        /// Tags from the top level to the chunk.
        path: String,
        /// Byte of the decoded body.
        offset: usize,
        /// What was wrong.
        why: String,
    },
    /// A chunk the reader decodes has a payload too short for its fields, or a value
    /// that cannot be valid (a vertex buffer whose length is not a whole number of
    /// vertices, an index beyond the vertices, a buffer number that does not exist).
    #[error("bad value in {path} (body byte {offset}): {why}")]
    Value {
        /// Tags from the top level to the chunk.
        path: String,
        /// Byte of the decoded body.
        offset: usize,
        /// What was wrong.
        why: String,
    },
    /// More elements than the reader's caps allow (see the `MAX_*` constants).
    #[error("too many {what}: more than {max}")]
    TooMany {
        /// What was counted.
        what: &'static str,
        /// The cap.
        max: usize,
    },
}
