//! ZMTP 3 frames: a flags byte, a 1- or 8-byte big-endian length, a body.
//!
//! [`Header::parse`] reads and checks one header from the front of a byte slice;
//! [`encode_frame`] and [`encode_message`] write frames.

use super::rules::{FLAG_COMMAND, FLAG_LONG, FLAG_MORE, FLAGS_RESERVED, MAX_FRAME_LEN, SHORT_MAX, Violation};

/// One frame header, checked against the flag rules and [`MAX_FRAME_LEN`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Header {
    /// More frames of the same message follow.
    pub more: bool,
    /// A command frame rather than a message frame.
    pub command: bool,
    /// Bytes in the header itself (2 or 9).
    pub header_len: usize,
    /// Bytes in the body; at most [`MAX_FRAME_LEN`], so it fits a usize.
    pub body_len: usize,
}

impl Header {
    /// The header at the front of `bytes`; `Ok(None)` while it is incomplete.
    ///
    /// # Errors
    /// Reserved flag bits, MORE on a command, or a length over [`MAX_FRAME_LEN`]: each
    /// as soon as the bytes that show it are in.
    pub(super) fn parse(bytes: &[u8]) -> Result<Option<Self>, Violation> {
        let Some(&flags) = bytes.first() else {
            return Ok(None);
        };
        if flags & FLAGS_RESERVED != 0 {
            return Err(Violation::Flags(flags));
        }
        let command = flags & FLAG_COMMAND != 0;
        let more = flags & FLAG_MORE != 0;
        if command && more {
            return Err(Violation::MoreOnCommand);
        }
        let (len, header_len) = if flags & FLAG_LONG != 0 {
            let Some(len) = bytes.get(1..9) else {
                return Ok(None);
            };
            let mut be = [0; 8];
            be.copy_from_slice(len);
            (u64::from_be_bytes(be), 9)
        } else {
            let Some(&len) = bytes.get(1) else {
                return Ok(None);
            };
            (u64::from(len), 2)
        };
        if len > MAX_FRAME_LEN {
            return Err(Violation::FrameTooLong(len));
        }
        Ok(Some(Self {
            more,
            command,
            header_len,
            // At most MAX_FRAME_LEN (16 MiB), so the conversion cannot fail.
            body_len: usize::try_from(len).map_err(|_| Violation::FrameTooLong(len))?,
        }))
    }
}

/// Appends one frame: a message frame with MORE set when `more`, or a command frame
/// when `command` (commands never have MORE). Bodies up to 255 bytes get the short
/// header.
pub(super) fn encode_raw(out: &mut Vec<u8>, body: &[u8], more: bool, command: bool) {
    let mut flags = 0;
    if more && !command {
        flags |= FLAG_MORE;
    }
    if command {
        flags |= FLAG_COMMAND;
    }
    if body.len() > SHORT_MAX {
        out.push(flags | FLAG_LONG);
        // usize is at most 64 bits on every target Rust supports.
        out.extend_from_slice(&(body.len() as u64).to_be_bytes());
    } else {
        out.push(flags);
        // Checked just above: at most 255.
        out.push(body.len() as u8);
    }
    out.extend_from_slice(body);
}

/// Appends one message frame; `more` says whether more frames of the same message
/// follow.
pub fn encode_frame(out: &mut Vec<u8>, body: &[u8], more: bool) {
    encode_raw(out, body, more, false);
}

/// Appends a whole message: every frame but the last with MORE. An empty list writes
/// nothing (ZMTP has no empty messages).
pub fn encode_message(out: &mut Vec<u8>, frames: &[&[u8]]) {
    if let Some((last, init)) = frames.split_last() {
        for f in init {
            encode_frame(out, f, true);
        }
        encode_frame(out, last, false);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_short_and_long() {
        assert_eq!(Header::parse(&[]), Ok(None));
        assert_eq!(Header::parse(&[0x01]), Ok(None));
        assert_eq!(
            Header::parse(&[0x01, 0]),
            Ok(Some(Header {
                more: true,
                command: false,
                header_len: 2,
                body_len: 0
            }))
        );
        assert_eq!(
            Header::parse(&[0x04, 7, 1, 2]),
            Ok(Some(Header {
                more: false,
                command: true,
                header_len: 2,
                body_len: 7
            }))
        );
        let long = [&[0x02][..], &300u64.to_be_bytes()].concat();
        for n in 1..long.len() {
            assert_eq!(Header::parse(&long[..n]), Ok(None), "{n} bytes");
        }
        assert_eq!(
            Header::parse(&long),
            Ok(Some(Header {
                more: false,
                command: false,
                header_len: 9,
                body_len: 300
            }))
        );
        // A long header for a short length is allowed (RFC 23 does not forbid it).
        let small = [&[0x03][..], &5u64.to_be_bytes()].concat();
        assert_eq!(Header::parse(&small).map(|h| h.map(|h| h.body_len)), Ok(Some(5)));
    }

    #[test]
    fn headers_breaking_the_rules_are_refused_as_soon_as_visible() {
        for bit in 3..8 {
            let flags = 1u8 << bit;
            assert_eq!(Header::parse(&[flags]), Err(Violation::Flags(flags)));
        }
        assert_eq!(Header::parse(&[0x05]), Err(Violation::MoreOnCommand));
        let at_limit = [&[0x02][..], &MAX_FRAME_LEN.to_be_bytes()].concat();
        assert!(Header::parse(&at_limit).is_ok_and(|h| h.is_some()));
        for len in [MAX_FRAME_LEN + 1, 1 << 50, u64::MAX] {
            let h = [&[0x06][..], &len.to_be_bytes()].concat();
            assert_eq!(Header::parse(&h), Err(Violation::FrameTooLong(len)));
        }
    }

    #[test]
    fn encoders_write_what_the_parser_reads() {
        for (len, more) in [(0usize, false), (1, true), (255, false), (256, true), (70_000, false)] {
            let body = vec![0xab; len];
            let mut out = Vec::new();
            encode_frame(&mut out, &body, more);
            let h = Header::parse(&out).unwrap().unwrap();
            assert_eq!((h.more, h.command, h.body_len), (more, false, len));
            assert_eq!(&out[h.header_len..], &body[..]);
            assert_eq!(h.header_len, if len > 255 { 9 } else { 2 });
        }
        let mut out = Vec::new();
        encode_message(&mut out, &[b"", b"abc"]);
        assert_eq!(out, b"\x01\x00\x00\x03abc");
        let mut out = Vec::new();
        encode_message(&mut out, &[]);
        assert!(out.is_empty());
        encode_raw(&mut out, b"\x04PING\x00\x00", true, true);
        assert_eq!(out, b"\x04\x07\x04PING\x00\x00", "commands never get MORE");
    }
}
