//! The tagged chunk stream inside the decoded body.
//!
//! A chunk is a 3-character tag, an i32 payload length and the payload. Three bare
//! markers carry no length: `EOO` (end of object, also the end of every nested stream and
//! the separator between the two parts of a mesh), `NXT` (end of an object's common
//! part) and `EOF`. The walker needs no table of tags: which payloads are nested streams
//! is decided by the readers that know the tag, and anything unknown is skipped whole.
//!
//! [`Chunks`] walks one stream level and checks every length against the bytes that
//! remain before handing out a payload slice. [`At`] remembers the tag path and the
//! absolute body offset of a payload, so errors can say where they happened.

use crate::error::ReadError;

/// Deepest nesting of streams the readers follow (compound shapes nest wrappers).
pub const MAX_DEPTH: usize = 48;

/// Where a payload sits: its tag path and the body offset of its first byte.
#[derive(Debug, Clone, Copy)]
pub struct At<'p> {
    /// Tag of this chunk (`b"   "` for the top level).
    pub tag: [u8; 3],
    /// Offset of the payload's first byte in the decoded body.
    pub offset: usize,
    /// The enclosing chunk.
    pub parent: Option<&'p At<'p>>,
    /// Number of enclosing chunks.
    pub depth: usize,
}

impl<'p> At<'p> {
    /// The top level of the body.
    pub const fn top() -> At<'static> {
        At {
            tag: *b"   ",
            offset: 0,
            parent: None,
            depth: 0,
        }
    }

    /// The place of a child chunk found at `offset` (absolute) inside this one.
    pub fn child(&'p self, tag: [u8; 3], offset: usize) -> At<'p> {
        At {
            tag,
            offset,
            parent: Some(self),
            depth: self.depth + 1,
        }
    }

    /// `SHP/Ge2/Gst`-style path.
    pub fn path(&self) -> String {
        let mut tags = Vec::new();
        let mut at = Some(self);
        while let Some(a) = at {
            if a.parent.is_some() {
                tags.push(String::from_utf8_lossy(&a.tag).into_owned());
            }
            at = a.parent;
        }
        if tags.is_empty() {
            return "top level".into();
        }
        tags.reverse();
        tags.join("/")
    }

    /// A [`ReadError::Chunk`] at this place.
    pub fn chunk_error(&self, offset: usize, why: impl Into<String>) -> ReadError {
        ReadError::Chunk {
            path: self.path(),
            offset,
            why: why.into(),
        }
    }

    /// A [`ReadError::Value`] about this chunk's payload.
    pub fn value_error(&self, why: impl Into<String>) -> ReadError {
        ReadError::Value {
            path: self.path(),
            offset: self.offset,
            why: why.into(),
        }
    }

    /// Refuses to go deeper than [`MAX_DEPTH`].
    pub fn check_depth(&self) -> Result<(), ReadError> {
        if self.depth > MAX_DEPTH {
            return Err(self.chunk_error(self.offset, format!("nesting deeper than {MAX_DEPTH}")));
        }
        Ok(())
    }
}

/// One item of a stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Item<'a> {
    /// A tagged chunk.
    Chunk {
        /// Its tag.
        tag: [u8; 3],
        /// Its payload.
        payload: &'a [u8],
        /// Absolute body offset of the payload.
        offset: usize,
    },
    /// `EOO`: end of an object or nested stream, or the end of a part.
    EndOfObject,
    /// `NXT`: end of an object's common part.
    Next,
    /// `EOF`: end of the file's top-level stream.
    EndOfFile,
}

/// Walks one level of a chunk stream.
pub struct Chunks<'a, 'p> {
    bytes: &'a [u8],
    pos: usize,
    at: &'p At<'p>,
}

impl<'a, 'p> Chunks<'a, 'p> {
    /// Walks `payload`, the payload of the chunk at `at`.
    pub fn new(payload: &'a [u8], at: &'p At<'p>) -> Self {
        Chunks {
            bytes: payload,
            pos: 0,
            at,
        }
    }

    /// Absolute offset of the next item.
    pub fn offset(&self) -> usize {
        self.at.offset + self.pos
    }

    /// Whether every byte has been consumed.
    pub fn is_empty(&self) -> bool {
        self.pos >= self.bytes.len()
    }

    /// The next item, or `None` at the end of the bytes.
    ///
    /// # Errors
    /// [`ReadError::Chunk`] for a tag or length cut off by the end of the payload, a
    /// negative length, or a payload that runs past its container.
    pub fn next_item(&mut self) -> Result<Option<Item<'a>>, ReadError> {
        let rest = &self.bytes[self.pos.min(self.bytes.len())..];
        if rest.is_empty() {
            return Ok(None);
        }
        let start = self.offset();
        let Some(tag) = rest.get(..3) else {
            return Err(self.at.chunk_error(start, "stream ends inside a tag"));
        };
        let tag = [tag[0], tag[1], tag[2]];
        let marker = match &tag {
            b"EOO" => Some(Item::EndOfObject),
            b"NXT" => Some(Item::Next),
            b"EOF" => Some(Item::EndOfFile),
            _ => None,
        };
        if let Some(marker) = marker {
            self.pos += 3;
            return Ok(Some(marker));
        }
        let Some(len) = rest.get(3..7) else {
            return Err(self
                .at
                .chunk_error(start, format!("stream ends inside the length of {}", show(tag))));
        };
        let len = i32::from_le_bytes([len[0], len[1], len[2], len[3]]);
        let Ok(len) = usize::try_from(len) else {
            return Err(self
                .at
                .chunk_error(start, format!("{} has a negative length {len}", show(tag))));
        };
        if len > rest.len() - 7 {
            return Err(self.at.chunk_error(
                start,
                format!("{} claims {len} bytes but only {} remain", show(tag), rest.len() - 7),
            ));
        }
        self.pos += 7 + len;
        Ok(Some(Item::Chunk {
            tag,
            payload: &rest[7..7 + len],
            offset: start + 7,
        }))
    }

    /// The chunks of one part: everything up to the next `EOO` or `EOF` (or `NXT` when
    /// `stop_at_next`). Returns the chunks and the marker that ended the part, `None` when
    /// the bytes ran out first.
    ///
    /// # Errors
    /// As [`Chunks::next_item`].
    pub fn part(&mut self, stop_at_next: bool) -> Result<(Vec<Chunk<'a>>, Option<Item<'a>>), ReadError> {
        let mut chunks = Vec::new();
        while let Some(item) = self.next_item()? {
            match item {
                Item::Chunk { tag, payload, offset } => chunks.push(Chunk { tag, payload, offset }),
                Item::Next if !stop_at_next => {}
                marker => return Ok((chunks, Some(marker))),
            }
        }
        Ok((chunks, None))
    }
}

/// A chunk with its place.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Chunk<'a> {
    /// Its tag.
    pub tag: [u8; 3],
    /// Its payload.
    pub payload: &'a [u8],
    /// Absolute body offset of the payload.
    pub offset: usize,
}

/// A tag for messages: printable as text, otherwise in hex.
pub fn show(tag: [u8; 3]) -> String {
    if tag.iter().all(|b| b.is_ascii_graphic()) {
        String::from_utf8_lossy(&tag).into_owned()
    } else {
        format!("0x{:02x}{:02x}{:02x}", tag[0], tag[1], tag[2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::Stream;

    #[test]
    fn walks_chunks_markers_and_nested_payloads() {
        let inner = Stream::new().chunk("Abc", &[1, 2]).marker("EOO").bytes();
        let bytes = Stream::new()
            .chunk("Out", &inner)
            .marker("NXT")
            .chunk("Xyz", &[])
            .marker("EOF")
            .bytes();
        let top = At::top();
        let mut c = Chunks::new(&bytes, &top);
        let Some(Item::Chunk { tag, payload, offset }) = c.next_item().unwrap() else {
            panic!("expected a chunk");
        };
        assert_eq!((&tag, offset), (b"Out", 7));
        assert_eq!(c.next_item().unwrap(), Some(Item::Next));
        assert!(matches!(
            c.next_item().unwrap(),
            Some(Item::Chunk {
                tag: [b'X', b'y', b'z'],
                ..
            })
        ));
        assert_eq!(c.next_item().unwrap(), Some(Item::EndOfFile));
        assert_eq!(c.next_item().unwrap(), None);

        // The nested stream walks with absolute offsets and a path.
        let at = top.child(tag, offset);
        let mut n = Chunks::new(payload, &at);
        assert_eq!(
            n.next_item().unwrap(),
            Some(Item::Chunk {
                tag: *b"Abc",
                payload: &[1, 2],
                offset: 14
            })
        );
        assert_eq!(n.next_item().unwrap(), Some(Item::EndOfObject));
        assert_eq!(at.path(), "Out");
    }

    #[test]
    fn bad_lengths_are_errors_with_their_place() {
        let top = At::top();
        // Length past the end.
        let mut bytes = b"Abc".to_vec();
        bytes.extend_from_slice(&100i32.to_le_bytes());
        bytes.extend_from_slice(&[0; 10]);
        let err = Chunks::new(&bytes, &top).next_item().unwrap_err();
        assert!(err.to_string().contains("claims 100 bytes but only 10 remain"), "{err}");
        // Negative length.
        let mut bytes = b"Abc".to_vec();
        bytes.extend_from_slice(&(-5i32).to_le_bytes());
        assert!(Chunks::new(&bytes, &top).next_item().is_err());
        // Cut inside a tag and inside a length.
        assert!(Chunks::new(b"Ab", &top).next_item().is_err());
        assert!(Chunks::new(b"Abc\x01\x00", &top).next_item().is_err());
        // Errors name the path.
        let shp = top.child(*b"SHP", 100);
        let ge2 = shp.child(*b"Ge2", 120);
        let err = Chunks::new(b"Ab", &ge2).next_item().unwrap_err();
        assert!(err.to_string().contains("SHP/Ge2 (body byte 120)"), "{err}");
    }
}
