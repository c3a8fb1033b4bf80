//! Line framing for the text command channel.
//!
//! The text protocol is one packet per line. Clients are typically LuaSocket or a terminal,
//! so lines may end in LF or CRLF, and LuaSocket's `*l` pattern drops *every* CR in a line,
//! not only the one before LF. We do the same so a line means the same thing on both ends.
//!
//! The decoder works on a caller-owned `Vec<u8>` receive buffer: the connection task
//! appends whatever it read, then calls [`LineDecoder::decode`] until it returns `Ok(None)`.
//! Complete lines are drained from the front of the buffer, so the buffer never holds more
//! than one partial line plus what the last read brought in.

use thiserror::Error;

/// The default longest line accepted, in bytes, excluding the line terminator.
///
/// The longest well-formed packet (64 fields of 32-char keys and 24-char numbers) is well
/// under this, so anything longer is a broken or hostile peer.
pub const DEFAULT_MAX_LINE_LEN: usize = 4096;

/// Why a line could not be produced.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum LineError {
    /// The line (or the unterminated tail of the buffer) exceeds the limit.
    ///
    /// The decoder discards the rest of that line, so decoding can resume with the next
    /// one, but the expected reaction is to send an error reply and close the connection.
    #[error("line too long: more than {max} bytes without a newline; send one packet per line, ending in '\\n'")]
    TooLong {
        /// The limit that was exceeded.
        max: usize,
    },
    /// The line is complete but is not valid UTF-8.
    ///
    /// The line has been consumed, so the connection can reply with an error and keep
    /// going: one garbled line (e.g. a Latin-1 degree sign) should not cost the session.
    #[error("line is not valid UTF-8 (invalid byte at offset {offset}); send ASCII or UTF-8 text")]
    InvalidUtf8 {
        /// Byte offset of the first invalid sequence within the line.
        offset: usize,
    },
}

/// Splits a byte stream into text lines ending in LF, with a length limit.
#[derive(Debug, Clone)]
pub struct LineDecoder {
    max_len: usize,
    /// How far the buffer has already been searched for LF, so feeding a long line one
    /// byte at a time stays linear instead of rescanning from the start each call.
    scanned: usize,
    /// Set after [`LineError::TooLong`]: bytes are dropped until the next LF, so a peer
    /// cannot make us buffer an unbounded line.
    discarding: bool,
}

impl Default for LineDecoder {
    fn default() -> Self {
        Self::new()
    }
}

impl LineDecoder {
    /// A decoder with the default limit of [`DEFAULT_MAX_LINE_LEN`] bytes.
    pub fn new() -> Self {
        Self::with_max_len(DEFAULT_MAX_LINE_LEN)
    }

    /// A decoder that refuses lines longer than `max_len` bytes (terminator excluded).
    pub fn with_max_len(max_len: usize) -> Self {
        Self {
            max_len,
            scanned: 0,
            discarding: false,
        }
    }

    /// The longest line accepted, in bytes.
    pub fn max_len(&self) -> usize {
        self.max_len
    }

    /// Takes the next complete line off the front of `buf`.
    ///
    /// Returns `Ok(Some(line))` without the LF and with every CR removed, `Ok(None)` when
    /// `buf` holds no complete line yet (read more and call again), or an error. The
    /// caller must only append to `buf` between calls; after removing bytes from it any
    /// other way, call [`LineDecoder::reset`].
    ///
    /// The length limit counts the bytes before LF, minus one CR directly before it, so
    /// it is the same whether the peer sends LF or CRLF. It is checked before the LF
    /// arrives, so an endless line is refused once it passes the limit.
    pub fn decode(&mut self, buf: &mut Vec<u8>) -> Result<Option<String>, LineError> {
        loop {
            // `min` keeps this total if the caller shrank the buffer behind our back.
            let start = self.scanned.min(buf.len());
            let Some(rel) = buf.get(start..).and_then(|t| t.iter().position(|&b| b == b'\n')) else {
                if self.discarding {
                    buf.clear();
                    self.scanned = 0;
                    return Ok(None);
                }
                self.scanned = buf.len();
                // A trailing CR may be the first half of CRLF, so it does not count yet.
                let pending = buf.len() - usize::from(buf.last() == Some(&b'\r'));
                if pending > self.max_len {
                    self.start_discarding(buf);
                    return Err(LineError::TooLong { max: self.max_len });
                }
                return Ok(None);
            };
            let lf = start + rel;
            let mut line: Vec<u8> = buf.drain(..=lf).collect();
            self.scanned = 0;
            line.pop(); // the LF
            if self.discarding {
                // This was the tail of an over-long line; resume with the next one.
                self.discarding = false;
                continue;
            }
            let len = line.len() - usize::from(line.last() == Some(&b'\r'));
            if len > self.max_len {
                return Err(LineError::TooLong { max: self.max_len });
            }
            line.retain(|&b| b != b'\r');
            return match String::from_utf8(line) {
                Ok(s) => Ok(Some(s)),
                Err(e) => Err(LineError::InvalidUtf8 {
                    offset: e.utf8_error().valid_up_to(),
                }),
            };
        }
    }

    /// Forgets all progress, for when the caller cleared or replaced the buffer.
    pub fn reset(&mut self) {
        self.scanned = 0;
        self.discarding = false;
    }

    fn start_discarding(&mut self, buf: &mut Vec<u8>) {
        buf.clear();
        self.scanned = 0;
        self.discarding = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all_lines(dec: &mut LineDecoder, buf: &mut Vec<u8>) -> Vec<Result<String, LineError>> {
        let mut out = Vec::new();
        loop {
            match dec.decode(buf) {
                Ok(Some(l)) => out.push(Ok(l)),
                Ok(None) => return out,
                Err(e) => out.push(Err(e)),
            }
        }
    }

    #[test]
    fn byte_by_byte() {
        let mut dec = LineDecoder::new();
        let mut buf = Vec::new();
        let mut lines = Vec::new();
        for &b in b"<PING#>\r\n<FK#J1=0>\n" {
            buf.push(b);
            if let Some(l) = dec.decode(&mut buf).unwrap() {
                lines.push(l);
            }
        }
        assert_eq!(lines, ["<PING#>", "<FK#J1=0>"]);
        assert!(buf.is_empty());
    }

    #[test]
    fn crlf_and_stray_cr_are_stripped() {
        let mut dec = LineDecoder::new();
        let mut buf = b"a\r\nb\rc\r\n\r\n".to_vec();
        let got = all_lines(&mut dec, &mut buf);
        assert_eq!(got, [Ok("a".into()), Ok("bc".into()), Ok(String::new())]);
    }

    #[test]
    fn several_lines_and_partial_tail() {
        let mut dec = LineDecoder::new();
        let mut buf = b"one\ntwo\nthr".to_vec();
        let got = all_lines(&mut dec, &mut buf);
        assert_eq!(got, [Ok("one".into()), Ok("two".into())]);
        assert_eq!(buf, b"thr");
        buf.extend_from_slice(b"ee\n");
        assert_eq!(dec.decode(&mut buf), Ok(Some("three".into())));
        assert_eq!(dec.decode(&mut buf), Ok(None));
    }

    #[test]
    fn exactly_max_len_is_accepted_with_lf_or_crlf() {
        let mut dec = LineDecoder::with_max_len(4);
        let mut buf = b"abcd\nabcd\r\n".to_vec();
        let got = all_lines(&mut dec, &mut buf);
        assert_eq!(got, [Ok("abcd".into()), Ok("abcd".into())]);
        // A trailing CR awaiting its LF does not count against the limit either.
        buf.extend_from_slice(b"abcd\r");
        assert_eq!(dec.decode(&mut buf), Ok(None));
        buf.push(b'\n');
        assert_eq!(dec.decode(&mut buf), Ok(Some("abcd".into())));
    }

    #[test]
    fn oversize_before_lf_is_refused_then_skipped() {
        let mut dec = LineDecoder::with_max_len(4);
        let mut buf = Vec::new();
        let mut errors = 0;
        for &b in b"abcdefghij" {
            buf.push(b);
            if let Err(e) = dec.decode(&mut buf) {
                assert_eq!(e, LineError::TooLong { max: 4 });
                errors += 1;
            }
            assert!(buf.len() <= 5, "buffer must stay bounded");
        }
        assert_eq!(errors, 1, "one error per over-long line");
        buf.extend_from_slice(b"xyz\nok\n");
        assert_eq!(dec.decode(&mut buf), Ok(Some("ok".into())));
    }

    #[test]
    fn oversize_complete_line_in_one_buffer() {
        let mut dec = LineDecoder::with_max_len(4);
        let mut buf = b"abcde\nok\n".to_vec();
        let got = all_lines(&mut dec, &mut buf);
        assert_eq!(got, [Err(LineError::TooLong { max: 4 }), Ok("ok".into())]);
    }

    #[test]
    fn invalid_utf8_consumes_the_line_only() {
        let mut dec = LineDecoder::new();
        let mut buf = b"ab\xb0c\nnext\n".to_vec();
        let got = all_lines(&mut dec, &mut buf);
        assert_eq!(got, [Err(LineError::InvalidUtf8 { offset: 2 }), Ok("next".into())]);
    }

    #[test]
    fn caller_clearing_the_buffer_is_safe() {
        let mut dec = LineDecoder::new();
        let mut buf = b"partial".to_vec();
        assert_eq!(dec.decode(&mut buf), Ok(None));
        buf.clear();
        // Without reset this must not panic (it may miss a line, which is the documented
        // price of breaking the append-only contract).
        buf.extend_from_slice(b"x\n");
        let _ = dec.decode(&mut buf);
        buf.clear();
        dec.reset();
        buf.extend_from_slice(b"x\n");
        assert_eq!(dec.decode(&mut buf), Ok(Some("x".into())));
    }
}
