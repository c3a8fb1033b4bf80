//! The optional access token (`--token`) that protects the text channel and the viewer
//! when gantry listens beyond loopback.
//!
//! A token is a shared secret, not encryption: it travels in clear over TCP and HTTP,
//! so it keeps out other people on a lab network, not someone who can read the traffic
//! (use an SSH tunnel for that). Its value never appears in logs or `Debug` output;
//! candidates are compared in constant time so response timing does not reveal how
//! much of a guess was right. The ZMQ remote API has no authentication in CoppeliaSim's
//! protocol; see `runner.rs` for how it is kept on loopback when a token is set.

use std::fmt;
use std::sync::Arc;

/// Shortest accepted token: 8 characters from 66 give about 48 bits, already far out
/// of reach of guessing over a socket that answers a few thousand times a second.
pub const MIN_TOKEN_LEN: usize = 8;
/// Longest accepted token, so it fits in a text-channel line and a URL with room left.
pub const MAX_TOKEN_LEN: usize = 256;

/// A validated access token. Cloning is cheap; `Debug` prints no secret.
#[derive(Clone)]
pub struct AccessToken(Arc<str>);

/// Why a string is not a usable token.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TokenError {
    /// Too short or too long.
    #[error(
        "the access token must be {MIN_TOKEN_LEN} to {MAX_TOKEN_LEN} characters long, not {0} (for example: openssl rand -hex 16)"
    )]
    Length(usize),
    /// A character that would need escaping in a URL, a cookie or a packet.
    #[error(
        "the access token may only contain letters, digits, '-', '_', '.' and '~' (found {0:?}; for example: openssl rand -hex 16)"
    )]
    Character(char),
}

impl AccessToken {
    /// Checks `token`: [`MIN_TOKEN_LEN`] to [`MAX_TOKEN_LEN`] characters, all from URL's
    /// unreserved set (`A-Z a-z 0-9 - _ . ~`), so it goes unescaped into a URL query, a
    /// cookie and a `<AUTH#TOKEN>` packet.
    ///
    /// # Errors
    /// The length or a character is out of range.
    pub fn new(token: &str) -> Result<Self, TokenError> {
        if let Some(c) = token
            .chars()
            .find(|c| !(c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.' | '~')))
        {
            return Err(TokenError::Character(c));
        }
        // All ASCII now, so bytes are characters.
        if !(MIN_TOKEN_LEN..=MAX_TOKEN_LEN).contains(&token.len()) {
            return Err(TokenError::Length(token.len()));
        }
        Ok(Self(token.into()))
    }

    /// Whether `candidate` is this token. The time taken depends on the token's length
    /// only, never on where the first difference is.
    pub fn matches(&self, candidate: &[u8]) -> bool {
        let secret = self.0.as_bytes();
        // A length mismatch is folded into the same accumulator instead of returning
        // early; the loop always runs over the whole secret.
        let mut diff = u8::from(candidate.len() != secret.len());
        for (i, s) in secret.iter().enumerate() {
            diff |= s ^ candidate.get(i).copied().unwrap_or(0);
        }
        // Keeps the optimiser from turning the loop into an early-exit comparison.
        std::hint::black_box(diff) == 0
    }

    /// The token itself, for the one place that must show it: the viewer URL that
    /// `gantry run` prints for its user to open. Never log it.
    pub fn reveal(&self) -> &str {
        &self.0
    }
}

impl fmt::Debug for AccessToken {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("AccessToken(<redacted>)")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_the_problem() {
        assert!(AccessToken::new("abcDEF09-_.~").is_ok());
        assert_eq!(AccessToken::new("short").err(), Some(TokenError::Length(5)));
        assert_eq!(AccessToken::new(&"a".repeat(257)).err(), Some(TokenError::Length(257)));
        assert_eq!(AccessToken::new("with space").err(), Some(TokenError::Character(' ')));
        assert_eq!(AccessToken::new("abcdefgh>").err(), Some(TokenError::Character('>')));
        assert_eq!(AccessToken::new("abcdefgh;x").err(), Some(TokenError::Character(';')));
        assert_eq!(AccessToken::new("abcdéfgh").err(), Some(TokenError::Character('é')));
        assert!(TokenError::Length(3).to_string().contains("openssl rand"));
    }

    #[test]
    fn matches_exactly_and_debug_hides_it() {
        let t = AccessToken::new("s3cret-token").expect("valid");
        assert!(t.matches(b"s3cret-token"));
        for wrong in [
            &b""[..],
            b"s3cret-toke",
            b"s3cret-token2",
            b"S3cret-token",
            b"s3cret-token\0",
        ] {
            assert!(!t.matches(wrong), "{wrong:?}");
        }
        assert_eq!(format!("{t:?}"), "AccessToken(<redacted>)");
    }
}
