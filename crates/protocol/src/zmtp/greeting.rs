//! The ZMTP 3 greeting: 64 bytes each side sends first, before any frame.
//!
//! `signature (0xFF, 8 bytes of padding, 0x7F) | major 3 | minor | mechanism (20 bytes,
//! NUL-padded) | as-server | filler (31 zero bytes)`. The padding, the minor version and
//! the filler carry nothing gantry uses; the as-server flag only matters for mechanisms
//! with roles, which NULL is not.

use super::rules::Violation;

/// Length of the ZMTP 3 greeting.
pub const GREETING_LEN: usize = 64;

/// The mechanism field (bytes 12..32) of a NULL-mechanism greeting.
const NULL_MECHANISM: [u8; 20] = *b"NULL\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0";
const MECHANISM_AT: usize = 12;

/// Appends gantry's greeting: ZMTP 3.1, the NULL mechanism. `as_server` is written as
/// given; with NULL it means nothing, and libzmq sends 0.
pub fn encode_greeting(out: &mut Vec<u8>, as_server: bool) {
    let start = out.len();
    out.resize(start + GREETING_LEN, 0);
    let g = &mut out[start..];
    g[0] = 0xff;
    g[9] = 0x7f;
    g[10] = 3;
    g[11] = 1;
    g[MECHANISM_AT..MECHANISM_AT + NULL_MECHANISM.len()].copy_from_slice(&NULL_MECHANISM);
    g[32] = u8::from(as_server);
}

/// Checks the part of a peer's greeting received so far (`seen`, up to 64 bytes), so
/// that a peer speaking something else is refused at its first wrong signature or
/// version byte, or once its mechanism field is in, rather than after 64 bytes.
/// `Ok(true)` once all 64 bytes are in and valid.
///
/// # Errors
/// [`Violation::Greeting`] for a wrong signature or major version,
/// [`Violation::Mechanism`] for a mechanism other than NULL.
pub(super) fn check_greeting(seen: &[u8]) -> Result<bool, Violation> {
    let seen = &seen[..seen.len().min(GREETING_LEN)];
    for (offset, expected) in [(0usize, 0xffu8), (9, 0x7f), (10, 3)] {
        if let Some(&byte) = seen.get(offset)
            && byte != expected
        {
            // `offset` is at most 10, so it fits in a u8.
            return Err(Violation::Greeting {
                offset: offset as u8,
                byte,
            });
        }
    }
    // Judged once the whole field is in, so that the name reported does not depend on
    // how the bytes were split.
    if let Some(mechanism) = seen.get(MECHANISM_AT..MECHANISM_AT + NULL_MECHANISM.len())
        && mechanism != NULL_MECHANISM
    {
        let name: Vec<u8> = mechanism.iter().copied().take_while(|&b| b != 0).collect();
        return Err(Violation::Mechanism(String::from_utf8_lossy(&name).into_owned()));
    }
    Ok(seen.len() == GREETING_LEN)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn greeting() -> Vec<u8> {
        let mut g = Vec::new();
        encode_greeting(&mut g, false);
        g
    }

    #[test]
    fn our_greeting_is_what_libzmq_expects() {
        let g = greeting();
        assert_eq!(g.len(), GREETING_LEN);
        assert_eq!((g[0], g[9], g[10], g[11]), (0xff, 0x7f, 3, 1));
        assert_eq!(&g[12..16], b"NULL");
        assert!(g[16..].iter().all(|&b| b == 0));
        let mut server = Vec::new();
        encode_greeting(&mut server, true);
        assert_eq!(server[32], 1);
        // Appends, leaving what was there.
        let mut out = vec![7];
        encode_greeting(&mut out, false);
        assert_eq!(out[0], 7);
        assert_eq!(&out[1..], &g[..]);
    }

    #[test]
    fn a_valid_greeting_passes_at_every_length() {
        let mut g = greeting();
        // What a peer is free to put in the padding, minor version, as-server and filler.
        g[1..9].fill(0xaa);
        g[11] = 0;
        g[32] = 1;
        g[40] = 0x55;
        for n in 0..GREETING_LEN {
            assert_eq!(check_greeting(&g[..n]), Ok(false), "{n} bytes");
        }
        assert_eq!(check_greeting(&g), Ok(true));
    }

    #[test]
    fn a_wrong_signature_or_version_is_refused_at_its_byte() {
        for (offset, byte) in [(0u8, 0x13u8), (9, 0x00), (10, 2), (10, 4)] {
            let mut g = greeting();
            g[usize::from(offset)] = byte;
            for n in usize::from(offset) + 1..=GREETING_LEN {
                assert_eq!(
                    check_greeting(&g[..n]),
                    Err(Violation::Greeting { offset, byte }),
                    "{n} bytes"
                );
            }
        }
    }

    #[test]
    fn mechanisms_other_than_null_are_refused() {
        let mut g = greeting();
        g[12..17].copy_from_slice(b"CURVE");
        assert_eq!(check_greeting(&g), Err(Violation::Mechanism("CURVE".into())));
        // Judged when the whole field is in, whatever came before.
        assert_eq!(check_greeting(&g[..31]), Ok(false));
        assert_eq!(check_greeting(&g[..32]), Err(Violation::Mechanism("CURVE".into())));
        let mut g = greeting();
        g[16] = b'X';
        assert_eq!(check_greeting(&g), Err(Violation::Mechanism("NULLX".into())));
    }
}
