//! The fixed 1,021-byte header at the start of every .ttt and .ttm file.
//!
//! Layout (little-endian): `VREP`, i32 serialization version, i32 oldest version that
//! can read the file, u8 compression method, i32 decoded body length, i32 compilation
//! version, u16 program version (`40100` = 4.1.0), u32 licence code, u8 revision, u8 file
//! type (1 scene, 2 model, 0 in older files), then zero padding up to 1,021 bytes.

use crate::error::ReadError;

/// Bytes of the header; the compressed body starts right after it.
pub const HEADER_LEN: usize = 1021;
/// The oldest serialization version read (CoppeliaSim refuses older files too: before
/// 18, meshes were stored inline in a layout it no longer reads).
pub const MIN_SERIALIZATION_VERSION: i32 = 18;
/// Compression method 1: Marcus Geelnard's static Huffman coding.
pub const COMPRESSION_HUFFMAN: u8 = 1;

const MAGIC: &[u8; 4] = b"VREP";

/// Whether the file holds a whole scene or a model to insert into one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileType {
    /// A scene (`.ttt`).
    Scene,
    /// A model (`.ttm`).
    Model,
    /// Older files leave the field at 0; other values are kept as read.
    Unspecified(u8),
}

/// The facts the header states about the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Header {
    /// Serialization version of the writer (22 for 3.6-4.1, 25 for 4.6+).
    pub serialization_version: i32,
    /// Oldest serialization version that can read the file.
    pub oldest_reader_version: i32,
    /// Compression method of the body (always 1 in files seen so far).
    pub compression: u8,
    /// Length of the decoded body, bytes.
    pub body_len: u32,
    /// Version of the program that wrote the file, e.g. `40100` for 4.1.0, `30602` for
    /// V-REP 3.6.2.
    pub program_version: u16,
    /// Revision of that program version.
    pub revision: u8,
    /// Scene or model.
    pub file_type: FileType,
}

impl Header {
    /// Parses and checks the header at the start of `bytes`.
    ///
    /// # Errors
    /// [`ReadError::Header`] if the file is shorter than the header or lacks the `VREP`
    /// magic, [`ReadError::UnsupportedVersion`] for serialization versions before 18,
    /// [`ReadError::UnsupportedCompression`] for anything but Huffman and
    /// [`ReadError::BodyLength`] for a negative body length.
    pub fn parse(bytes: &[u8]) -> Result<Header, ReadError> {
        if bytes.len() < 4 || &bytes[..4] != MAGIC {
            return Err(ReadError::Header("the file does not start with VREP".into()));
        }
        if bytes.len() < HEADER_LEN {
            return Err(ReadError::Header(format!(
                "the header needs {HEADER_LEN} bytes, the file has {}",
                bytes.len()
            )));
        }
        let i32_at = |at: usize| i32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
        let serialization_version = i32_at(4);
        if serialization_version < MIN_SERIALIZATION_VERSION {
            return Err(ReadError::UnsupportedVersion {
                version: serialization_version,
                min: MIN_SERIALIZATION_VERSION,
            });
        }
        let compression = bytes[12];
        if compression != COMPRESSION_HUFFMAN {
            return Err(ReadError::UnsupportedCompression(compression));
        }
        let body_len = i32_at(13);
        let body_len = u32::try_from(body_len).map_err(|_| ReadError::BodyLength {
            len: i64::from(body_len),
            why: "negative",
        })?;
        let file_type = match bytes[28] {
            1 => FileType::Scene,
            2 => FileType::Model,
            other => FileType::Unspecified(other),
        };
        Ok(Header {
            serialization_version,
            oldest_reader_version: i32_at(8),
            compression,
            body_len,
            program_version: u16::from_le_bytes([bytes[21], bytes[22]]),
            revision: bytes[27],
            file_type,
        })
    }

    /// The program version as text, `4.1.0` for `40100`.
    pub fn program_version_text(&self) -> String {
        let v = self.program_version;
        format!("{}.{}.{}", v / 10000, v / 100 % 100, v % 100)
    }
}
