//! `sim.transformImage`: flips of an image buffer, as V-REP-era scripts do to a vision
//! sensor's image before publishing it (a vision sensor's rows start at the bottom, ROS
//! images' at the top).

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::world::World;

/// The image functions.
pub const FUNCTIONS: &[ApiFunction] = &[ApiFunction {
    name: "transformImage",
    call: ApiFn::World(transform_image),
    cost: Cost::Quick,
}];

/// `options` bits of `sim.transformImage`, CoppeliaSim's values.
const RGBA: i64 = 1;
const SHIFT: i64 = 2;
const FLIP_ROWS: i64 = 4;
const FLIP_COLUMNS: i64 = 8;

/// `sim.transformImage(image, {width, height}, options)`: the image with its rows
/// reversed (bit 4: "flip on x", the vertical flip scripts use) and/or each row's pixels
/// reversed (bit 8), returned. CoppeliaSim rewrites the Lua string in place and returns
/// nothing, which a host cannot do safely to a Lua string (docs/api-notes.md).
///
/// A pixel is 3 bytes (4 with bit 1), unless the buffer holds `width * height * k`
/// bytes for another `k` up to 16: then `k` bytes, so a depth buffer (4-byte floats)
/// flips too, as the scripts that pass one intend.
fn transform_image(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let image = transformed(a.bytes(0)?, resolution(a)?, a.opt_int(2, 0)?)?;
    Ok(vec![Value::Bytes(image)])
}

/// [`transform_image`] on its parsed arguments.
fn transformed(mut image: Vec<u8>, [w, h]: [usize; 2], options: i64) -> Result<Vec<u8>, SimError> {
    if options & SHIFT != 0 {
        return Err(SimError::bad_argument(
            "argument 3: the shift option (2) is not supported; flips are 4 (rows) and 8 (columns)",
        ));
    }
    let pixels = w
        .checked_mul(h)
        .filter(|&n| n > 0)
        .ok_or_else(|| SimError::bad_argument(format!("argument 2: a resolution of {w} x {h} has no pixels")))?;
    let declared = if options & RGBA != 0 { 4 } else { 3 };
    let bpp = if image.len() == pixels * declared {
        declared
    } else if image.len().is_multiple_of(pixels) && (1..=16).contains(&(image.len() / pixels)) {
        image.len() / pixels
    } else {
        return Err(SimError::bad_argument(format!(
            "argument 1: a {w} x {h} image has {} bytes ({declared} a pixel), got {}",
            pixels * declared,
            image.len()
        )));
    };
    let row = w * bpp;
    if options & FLIP_ROWS != 0 {
        for y in 0..h / 2 {
            let (top, bottom) = image.split_at_mut((h - 1 - y) * row);
            top[y * row..(y + 1) * row].swap_with_slice(&mut bottom[..row]);
        }
    }
    if options & FLIP_COLUMNS != 0 {
        for r in image.chunks_exact_mut(row) {
            for x in 0..w / 2 {
                let (left, right) = r.split_at_mut((w - 1 - x) * bpp);
                left[x * bpp..(x + 1) * bpp].swap_with_slice(&mut right[..bpp]);
            }
        }
    }
    Ok(image)
}

/// `{width, height}`, positive integers.
fn resolution(a: &Args<'_>) -> Result<[usize; 2], SimError> {
    let bad = || SimError::bad_argument("argument 2: expected {width, height}, two positive integers");
    let Value::Array(items) = a.get(1) else {
        return Err(bad());
    };
    let dim = |v: Option<&Value>| {
        v.and_then(Value::as_i64)
            .and_then(|n| usize::try_from(n).ok())
            .filter(|&n| n > 0)
            .ok_or_else(bad)
    };
    Ok([dim(items.first())?, dim(items.get(1))?])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(image: &[u8], w: usize, h: usize, options: i64) -> Result<Vec<u8>, SimError> {
        transformed(image.to_vec(), [w, h], options)
    }

    #[test]
    fn rows_and_columns_flip() {
        // 2 x 3 RGB: pixel (x, y) is [10y + x; 3].
        let img: Vec<u8> = (0..3).flat_map(|y| (0..2).flat_map(move |x| [10 * y + x; 3])).collect();
        let rows = run(&img, 2, 3, 4).unwrap();
        assert_eq!(&rows[..6], &[20, 20, 20, 21, 21, 21]);
        assert_eq!(&rows[12..], &[0, 0, 0, 1, 1, 1]);
        let cols = run(&img, 2, 3, 8).unwrap();
        assert_eq!(&cols[..6], &[1, 1, 1, 0, 0, 0]);
        let both = run(&img, 2, 3, 12).unwrap();
        assert_eq!(&both[..6], &[21, 21, 21, 20, 20, 20]);
        assert_eq!(run(&rows, 2, 3, 4).unwrap(), img, "a flip undoes itself");
        assert_eq!(run(&img, 2, 3, 0).unwrap(), img);
    }

    #[test]
    fn pixel_size_follows_the_buffer_and_bad_input_is_refused() {
        // A 1 x 2 depth buffer of 4-byte floats flips as 4-byte pixels.
        let depth = [1, 2, 3, 4, 5, 6, 7, 8];
        assert_eq!(run(&depth, 1, 2, 4).unwrap(), [5, 6, 7, 8, 1, 2, 3, 4]);
        let e = run(&[0; 7], 2, 1, 4).unwrap_err().to_string();
        assert!(e.contains("has 6 bytes") && e.contains("got 7"), "{e}");
        assert!(run(&[0; 6], 0, 1, 4).is_err());
        assert!(run(&[0; 6], 2, 1, 2).unwrap_err().to_string().contains("shift"));
    }
}
