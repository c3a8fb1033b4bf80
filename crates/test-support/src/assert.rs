//! Assertions with messages that show both sides.

/// Asserts that `actual` and `expected` have the same length and that each pair of
/// items differs by at most `tol` (0 asks for equality; a NaN on either side fails).
///
/// # Panics
/// If they differ in length or in any item by more than `tol`.
#[track_caller]
pub fn assert_close(actual: &[f64], expected: &[f64], tol: f64) {
    assert_eq!(actual.len(), expected.len(), "{actual:?} vs expected {expected:?}");
    for (a, e) in actual.iter().zip(expected) {
        assert!(
            (a - e).abs() <= tol,
            "{actual:?} vs expected {expected:?} (tolerance {tol})"
        );
    }
}

/// Asserts that `message` (as printed: an error's text) contains every one of `parts`.
///
/// # Panics
/// If a part is missing; the message names it and quotes the whole text.
#[track_caller]
pub fn assert_contains(message: impl std::fmt::Display, parts: &[&str]) {
    let message = message.to_string();
    for p in parts {
        assert!(message.contains(p), "{message:?} does not contain {p:?}");
    }
}

#[cfg(test)]
mod tests {
    use super::{assert_close, assert_contains};

    #[test]
    fn close_within_the_tolerance_and_exact_at_zero() {
        assert_close(&[1.0, 2.0], &[1.0 + 1e-10, 2.0], 1e-9);
        assert_close(&[1.0, 2.0], &[1.0, 2.0], 0.0);
        assert_contains("file.toml:3:7: unknown key", &["file.toml", ":3:7"]);
    }

    #[test]
    #[should_panic(expected = "tolerance")]
    fn far_apart_fails() {
        assert_close(&[1.0], &[1.1], 1e-3);
    }

    #[test]
    #[should_panic(expected = "vs expected")]
    fn lengths_must_agree() {
        assert_close(&[1.0, 2.0], &[1.0], 1.0);
    }

    #[test]
    #[should_panic(expected = "NaN")]
    fn nan_fails() {
        assert_close(&[f64::NAN], &[0.0], 1.0);
    }
}
