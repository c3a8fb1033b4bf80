//! Byte conversions for pixel loops: floats to bytes, and packed pixels to RGB bytes.
//!
//! Rust's `as` cast from `f32` to an integer saturates and maps NaN to 0, which is the
//! behaviour images need, but on x86 it compiles to a compare and branch per value,
//! which keeps loops over pixels scalar. [`round_byte`] computes the same result with
//! plain float arithmetic and a bit cast, so such loops vectorise.

use super::simd::multiversion;

/// 2^23: adding it to a float in 0..2^23 leaves that float's value rounded to an
/// integer in the low bits of the mantissa.
const MAGIC: f32 = 8_388_608.0;

/// `(x + 0.5) as u8`: `x` (in byte units) rounded half up, below 0 and NaN giving 0,
/// above 255 giving 255. Identical for every input (tested), without the branches.
#[inline]
pub(crate) fn round_byte(x: f32) -> u8 {
    // `max` returns the other operand when one is NaN, so NaN becomes 0 here (`clamp`
    // would keep the NaN).
    #[allow(clippy::manual_clamp, reason = "clamp keeps NaN; max maps it to 0")]
    let t = x.max(0.0).min(255.0) + 0.5;
    // Round to nearest even, then step down where that rounded up: floor(t).
    let r = (t + MAGIC) - MAGIC;
    let floor = if r > t { r - 1.0 } else { r };
    // `floor` is an integer in 0..=255, so the low byte of the mantissa holds it.
    ((floor + MAGIC).to_bits() & 0xff) as u8
}

/// Writes interleaved RGB bytes (3 per pixel) from `pixels`, each turned by `word` into
/// a packed `0x00BBGGRR` word. Four pixels at a time are exactly three little-endian
/// words of output, so the loop stores words instead of single bytes.
#[inline(always)]
fn write_rgb<T: Copy>(pixels: &[T], rgb: &mut [u8], word: impl Fn(T) -> u32) {
    let (blocks, rest) = pixels.as_chunks::<4>();
    let (out_blocks, out_rest) = rgb.as_chunks_mut::<12>();
    for (px, out) in blocks.iter().zip(out_blocks) {
        let [p0, p1, p2, p3] = px.map(&word);
        let words = [p0 | p1 << 24, p1 >> 8 | p2 << 16, p2 >> 16 | p3 << 8];
        for (o, w) in out.as_chunks_mut::<4>().0.iter_mut().zip(words) {
            *o = w.to_le_bytes();
        }
    }
    for (&p, o) in rest.iter().zip(out_rest.chunks_exact_mut(3)) {
        o.copy_from_slice(&word(p).to_le_bytes()[..3]);
    }
}

multiversion! {
    /// [`write_rgb`] of packed `0x00BBGGRR` colours (the rasteriser's buffer).
    pub(crate) fn write_packed_rgb(color: &[u32], rgb: &mut [u8]) {
        write_rgb(color, rgb, |p| p);
    }
}

multiversion! {
    /// [`write_rgb`] of a black-and-white mask: 0 is black, anything else white.
    pub(crate) fn write_mask_rgb(mask: &[u8], rgb: &mut [u8]) {
        write_rgb(mask, rgb, |v| u32::from(v != 0) * 0x00ff_ffff);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_byte_equals_the_saturating_cast_everywhere() {
        let specials = [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MAX,
            f32::MIN,
            -0.0,
            0.0,
            1e-30,
            -1e-30,
            0.001,
            -0.001,
            0.49999997,
            0.5,
            254.5,
            254.49998,
            255.0,
            255.49998,
            255.5,
            256.0,
            -0.5,
            -0.50000006,
            1e30,
        ];
        for x in specials {
            assert_eq!(round_byte(x), (x + 0.5) as u8, "{x}");
        }
        // Every float within 0.002 of each integer and half-integer from -2 to 300,
        // where the result changes, and a pseudo-random spread in between.
        // (Zero is left to the specials: it has a billion floats within 0.002.)
        for k in (-4..=600).filter(|&k| k != 0) {
            let centre = k as f32 / 2.0;
            let mut x = centre - 0.002;
            while x <= centre + 0.002 {
                assert_eq!(round_byte(x), (x + 0.5) as u8, "{x}");
                x = x.next_up();
            }
        }
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..1_000_000 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let x = (seed >> 40) as f32 / (1u64 << 24) as f32 * 302.0 - 2.0;
            assert_eq!(round_byte(x), (x + 0.5) as u8, "{x}");
        }
    }
}
