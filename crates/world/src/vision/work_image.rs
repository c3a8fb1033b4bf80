//! `simVision`'s work-image filters, ported from CoppeliaSim's simVision plugin
//! (`simVision.cpp`, `imageProcess.cpp`) so that scripts see the same pixels.
//!
//! A work image is `width * height` RGB triples of `f32` (nominally 0..1), bottom row
//! first like the sensor image. The filters are pure functions over slices; the
//! caller owns the buffers, including the scratch image of the 3x3 filters.

/// CoppeliaSim's edge kernel: a Laplacian, row after row.
const EDGE_KERNEL: [f32; 9] = [-3.0, -3.0, -3.0, -3.0, 24.0, -3.0, -3.0, -3.0, -3.0];
/// CoppeliaSim's sharpening kernel (identity plus a scaled Laplacian; the plugin's
/// rounded constants are kept).
const SHARPEN_KERNEL: [f32; 9] = [
    -0.1111, -0.1111, -0.1111, -0.1111, 1.8888, -0.1111, -0.1111, -0.1111, -0.1111,
];

/// 3x3 convolution of an image of `C` interleaved channels, `input` → `output`, as
/// CoppeliaSim's `filter3x3RgbImage`: taps outside the image are left out and the sum
/// is divided by (number of taps inside) / 9, so border pixels are scaled up rather
/// than padded. With a zero-sum kernel this makes the border of any non-black image
/// bright, which CoppeliaSim's edge images show too.
fn filter3x3<const C: usize>(width: usize, height: usize, input: &[f32], output: &mut [f32], m: &[f32; 9]) {
    let stride = C * width;
    let interior = width >= 3 && height >= 3 && input.len() >= stride * height && output.len() >= stride * height;
    if interior {
        // All nine taps exist away from the border: straight-line code over three rows,
        // which the compiler vectorises (about 5x the general path below).
        for y in 1..height - 1 {
            let r0 = &input[(y - 1) * stride..y * stride];
            let r1 = &input[y * stride..(y + 1) * stride];
            let r2 = &input[(y + 1) * stride..(y + 2) * stride];
            let out = &mut output[y * stride..(y + 1) * stride];
            for i in C..stride - C {
                out[i] = m[0] * r0[i - C]
                    + m[1] * r0[i]
                    + m[2] * r0[i + C]
                    + m[3] * r1[i - C]
                    + m[4] * r1[i]
                    + m[5] * r1[i + C]
                    + m[6] * r2[i - C]
                    + m[7] * r2[i]
                    + m[8] * r2[i + C];
            }
        }
    }
    filter_border::<C>(width, height, input, output, m, interior);
}

/// The pixels [`filter3x3`]'s interior pass leaves out: the border (every pixel if
/// `interior` is false, that is, if the interior pass did not run).
fn filter_border<const C: usize>(
    width: usize,
    height: usize,
    input: &[f32],
    output: &mut [f32],
    m: &[f32; 9],
    interior: bool,
) {
    for y in 0..height {
        let whole_row = !interior || y == 0 || y + 1 == height;
        if whole_row && interior {
            // First or last row of an image with an interior: away from the corners,
            // straight-line code that vectorises, as in the interior.
            filter_end_row::<C>(width, input, output, m, y);
            filter_pixel::<C>(width, height, input, output, m, 0, y);
            filter_pixel::<C>(width, height, input, output, m, width - 1, y);
        } else if whole_row {
            for x in 0..width {
                filter_pixel::<C>(width, height, input, output, m, x, y);
            }
        } else {
            // Only the first and last pixel of an interior row are on the border.
            filter_row_ends::<C>(width, input, output, m, y);
        }
    }
}

/// Row `y` (the first or the last) of [`filter3x3`] but for its two corner pixels, in
/// an image of at least 3 x 3 (so the row has one neighbour row). The same arithmetic
/// in the same order as [`filter_pixel`], so the same bits.
#[inline(always)]
fn filter_end_row<const C: usize>(width: usize, input: &[f32], output: &mut [f32], m: &[f32; 9], y: usize) {
    let stride = C * width;
    // The two image rows in the kernel, top first, and the kernel rows they meet.
    let (first, k) = if y == 0 { (0, 3) } else { (y - 1, 0) };
    let (Some(ra), Some(rb)) = (
        input.get(first * stride..(first + 1) * stride),
        input.get((first + 1) * stride..(first + 2) * stride),
    ) else {
        return;
    };
    let Some(out) = output.get_mut(y * stride..(y + 1) * stride) else {
        return;
    };
    // Six taps of nine, as `filter_pixel` counts them.
    let norm = 6.0f32 / 9.0;
    for i in C..stride - C {
        // Starting from 0.0 as `filter_pixel` does, which turns a -0.0 product into 0.0.
        let mut sum = 0.0 + ra[i - C] * m[k];
        sum += ra[i] * m[k + 1];
        sum += ra[i + C] * m[k + 2];
        sum += rb[i - C] * m[k + 3];
        sum += rb[i] * m[k + 4];
        sum += rb[i + C] * m[k + 5];
        out[i] = sum / norm;
    }
}

/// The first and the last pixel of interior row `y` of [`filter3x3`], when the
/// interior pass ran: six taps each, in [`filter_pixel`]'s order, so the same bits.
#[inline(always)]
fn filter_row_ends<const C: usize>(width: usize, input: &[f32], output: &mut [f32], m: &[f32; 9], y: usize) {
    let stride = C * width;
    let norm = 6.0f32 / 9.0;
    // Offsets of the two columns each end pixel reads, and the kernel column of the
    // first of them: columns 0, 1 (kernel 1, 2) and w-2, w-1 (kernel 0, 1).
    for (x, first_col, kc) in [(0, 0, 1), (width - 1, width - 2, 0)] {
        for c in 0..C {
            let tap = |row: usize, col: usize| input.get(row * stride + C * col + c).copied().unwrap_or(0.0);
            let mut sum = 0.0;
            for (kr, row) in [(0, y - 1), (3, y), (6, y + 1)] {
                sum += tap(row, first_col) * m[kr + kc];
                sum += tap(row, first_col + 1) * m[kr + kc + 1];
            }
            if let Some(o) = output.get_mut(y * stride + C * x + c) {
                *o = sum / norm;
            }
        }
    }
}

/// One output pixel of [`filter3x3`], with the border rule.
fn filter_pixel<const C: usize>(
    width: usize,
    height: usize,
    input: &[f32],
    output: &mut [f32],
    m: &[f32; 9],
    x: usize,
    y: usize,
) {
    let mut sum = [0.0f32; C];
    let mut taps = 0.0f32;
    for dy in -1isize..=1 {
        let Some(yy) = y.checked_add_signed(dy).filter(|&v| v < height) else {
            continue;
        };
        for dx in -1isize..=1 {
            let Some(xx) = x.checked_add_signed(dx).filter(|&v| v < width) else {
                continue;
            };
            // Offsets are in -1..=1, so the kernel index is 0..9.
            let w = m[((dx + 1) + (dy + 1) * 3) as usize];
            let i = C * (xx + yy * width);
            if let Some(px) = input.get(i..i + C) {
                for k in 0..C {
                    sum[k] += px[k] * w;
                }
            }
            taps += 1.0;
        }
    }
    let i = C * (x + y * width);
    if let Some(out) = output.get_mut(i..i + C) {
        let norm = taps / 9.0;
        for k in 0..C {
            out[k] = sum[k] / norm;
        }
    }
}

/// `simVision.edgeDetectionOnWorkImg`: the edge kernel over each channel, then every
/// pixel becomes white where the mean of its filtered R, G, B exceeds `threshold`, and
/// black elsewhere. Takes `grey`, each pixel's R + G + B, and writes `mask`, 1 for
/// white and 0 for black per pixel; `scratch` holds [`edge_scratch_len`] values.
///
/// The filter is linear, so the mean of the three filtered channels is the filtered
/// mean: one channel (R + G + B) is filtered instead of three, and compared with
/// 3 * `threshold`. (Only a sum within rounding of the threshold can differ.)
// Always inlined: into both copies of `vision::edge_detection` (see `vision::simd`).
#[inline(always)]
pub(crate) fn edge_mask(
    width: usize,
    height: usize,
    grey: &[f32],
    scratch: &mut [f32],
    threshold: f32,
    mask: &mut Vec<u8>,
) {
    let (filtered, rows) = scratch.split_at_mut((width * height).min(scratch.len()));
    edge_filter(width, height, grey, filtered, rows);
    let limit = 3.0 * threshold;
    mask.clear();
    mask.extend(filtered.iter().map(|&f| u8::from(f > limit)));
}

/// Scratch values [`edge_mask`] needs for a `width` x `height` image: the filtered
/// image and three rows of horizontal sums.
pub(crate) fn edge_scratch_len(width: usize, height: usize) -> usize {
    width * height + 3 * width
}

/// [`filter3x3`] with [`EDGE_KERNEL`] on one channel. The kernel is 27 times the
/// centre minus 3 times the 3x3 box sum, and box sums are separable: a row of
/// horizontal sums, then three rows of those added. Four additions per pixel instead
/// of nine multiply-adds. Border pixels follow the border rule ([`filter_border`]).
/// `rows` holds three rows of horizontal sums (at least `3 * width` values).
#[inline(always)]
fn edge_filter(width: usize, height: usize, input: &[f32], output: &mut [f32], rows: &mut [f32]) {
    let n = width * height;
    if width < 3 || height < 3 || input.len() < n || output.len() < n || rows.len() < 3 * width {
        filter3x3::<1>(width, height, input, output, &EDGE_KERNEL);
        return;
    }
    // Row y's horizontal 3-sums go to slot y % 3, so the three around y are at hand.
    let hsum = |rows: &mut [f32], y: usize| {
        let slot = &mut rows[(y % 3) * width..(y % 3) * width + width - 2];
        for (o, w) in slot.iter_mut().zip(input[y * width..(y + 1) * width].windows(3)) {
            *o = w[0] + w[1] + w[2];
        }
    };
    hsum(rows, 0);
    hsum(rows, 1);
    for y in 1..height - 1 {
        hsum(rows, y + 1);
        let slot = |k: usize| &rows[(k % 3) * width..(k % 3) * width + width - 2];
        let (above, here, below) = (slot(y - 1), slot(y), slot(y + 1));
        let centre = &input[y * width + 1..(y + 1) * width - 1];
        let out = &mut output[y * width + 1..(y + 1) * width - 1];
        for ((((o, &c), &a), &h), &b) in out.iter_mut().zip(centre).zip(above).zip(here).zip(below) {
            *o = 27.0 * c - 3.0 * (a + h + b);
        }
    }
    filter_border::<1>(width, height, input, output, &EDGE_KERNEL, true);
}

/// `simVision.sharpenWorkImg`: the sharpening kernel, then a clamp to 0..1.
pub(crate) fn sharpen(width: usize, height: usize, work: &mut [f32], scratch: &mut Vec<f32>) {
    scratch.clear();
    scratch.resize(work.len(), 0.0);
    filter3x3::<3>(width, height, work, scratch, &SHARPEN_KERNEL);
    for (w, s) in work.iter_mut().zip(scratch.iter()) {
        *w = s.clamp(0.0, 1.0);
    }
}

/// `simVision.horizontalFlipWorkImg`: mirrors left and right.
pub(crate) fn flip_horizontal(width: usize, work: &mut [f32]) {
    if width == 0 {
        return;
    }
    for row in work.chunks_exact_mut(3 * width) {
        for x in 0..width / 2 {
            for k in 0..3 {
                row.swap(3 * x + k, 3 * (width - 1 - x) + k);
            }
        }
    }
}

/// `simVision.verticalFlipWorkImg`: mirrors top and bottom.
pub(crate) fn flip_vertical(width: usize, height: usize, work: &mut [f32]) {
    let stride = 3 * width;
    for y in 0..height / 2 {
        let (low, high) = work.split_at_mut(stride * (height - 1 - y));
        if let (Some(a), Some(b)) = (low.get_mut(stride * y..stride * (y + 1)), high.get_mut(..stride)) {
            a.swap_with_slice(b);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Edge detection on a float RGB image, in place, through [`edge_mask`].
    fn edge_detection(width: usize, height: usize, img: &mut [f32], _: &mut Vec<f32>, threshold: f32) {
        let grey: Vec<f32> = img.chunks_exact(3).map(|p| p[0] + p[1] + p[2]).collect();
        let (mut scratch, mut mask) = (vec![0.0; edge_scratch_len(width, height)], Vec::new());
        edge_mask(width, height, &grey, &mut scratch, threshold, &mut mask);
        for (px, &m) in img.chunks_exact_mut(3).zip(&mask) {
            px.fill(f32::from(m));
        }
    }

    fn grey(width: usize, height: usize, f: impl Fn(usize, usize) -> f32) -> Vec<f32> {
        let mut out = Vec::with_capacity(3 * width * height);
        for y in 0..height {
            for x in 0..width {
                out.extend([f(x, y); 3]);
            }
        }
        out
    }

    fn at(img: &[f32], width: usize, x: usize, y: usize) -> f32 {
        img[3 * (x + y * width)]
    }

    #[test]
    fn edges_of_a_step_are_on_its_bright_side() {
        let (w, h) = (8, 6);
        // Dark left half (0.1), bright right half (0.6): a vertical step at x = 4.
        let mut img = grey(w, h, |x, _| if x < 4 { 0.1 } else { 0.6 });
        edge_detection(w, h, &mut img, &mut Vec::new(), 0.2);
        for y in 1..h - 1 {
            // Bright side of the step: 3 * 3 * 0.5 = 4.5 > 0.2.
            assert_eq!(at(&img, w, 4, y), 1.0);
            // Dark side: negative response.
            assert_eq!(at(&img, w, 3, y), 0.0);
            // Uniform interiors: zero response.
            assert_eq!(at(&img, w, 1, y), 0.0);
            assert_eq!(at(&img, w, 6, y), 0.0);
        }
        // CoppeliaSim's border normalisation brightens the frame of a non-black image.
        assert_eq!(at(&img, w, 6, 0), 1.0);
        assert_eq!(at(&img, w, 7, 3), 1.0);
    }

    #[test]
    fn a_black_image_has_no_edges_and_smooth_ramps_none_either() {
        let (w, h) = (5, 5);
        let mut img = grey(w, h, |_, _| 0.0);
        edge_detection(w, h, &mut img, &mut Vec::new(), 0.2);
        assert!(img.iter().all(|&v| v == 0.0));
        // A linear ramp has zero Laplacian inside.
        let mut img = grey(w, h, |x, _| 0.1 * x as f32);
        edge_detection(w, h, &mut img, &mut Vec::new(), 0.2);
        assert_eq!(at(&img, w, 2, 2), 0.0);
    }

    #[test]
    fn edge_detection_equals_filtering_each_channel() {
        // The definition: the kernel over R, G and B separately, then the mean.
        for (w, h) in [(1, 1), (2, 5), (3, 3), (17, 9), (64, 48)] {
            let mut x = 0x853c_49e6_748f_ea9bu64;
            let img: Vec<f32> = (0..3 * w * h)
                .map(|_| {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    // Bytes as the sensor gives them, in 0..1.
                    ((x >> 32) % 256) as f32 / 255.0
                })
                .collect();
            let mut per_channel = vec![0.0; img.len()];
            filter3x3::<3>(w, h, &img, &mut per_channel, &EDGE_KERNEL);
            let mut fast = img.clone();
            edge_detection(w, h, &mut fast, &mut Vec::new(), 0.2);
            for i in 0..w * h {
                let mean = (per_channel[3 * i] + per_channel[3 * i + 1] + per_channel[3 * i + 2]) / 3.0;
                if (mean - 0.2).abs() < 1e-4 {
                    continue; // a tie within rounding may go either way
                }
                let want = if mean > 0.2 { 1.0 } else { 0.0 };
                assert_eq!(fast[3 * i..3 * i + 3], [want; 3], "{w}x{h} pixel {i}: mean {mean}");
            }
        }
    }

    #[test]
    fn the_separable_edge_filter_equals_the_general_one() {
        for (w, h) in [(1, 1), (2, 7), (3, 3), (31, 12)] {
            let img: Vec<f32> = (0..w * h).map(|i| ((i * 37 + 11) % 101) as f32 / 33.0).collect();
            let (mut general, mut fast) = (vec![0.0; w * h], vec![0.0; w * h]);
            filter3x3::<1>(w, h, &img, &mut general, &EDGE_KERNEL);
            edge_filter(w, h, &img, &mut fast, &mut vec![0.0; 3 * w]);
            for (i, (g, f)) in general.iter().zip(&fast).enumerate() {
                assert!((g - f).abs() < 1e-4, "{w}x{h} pixel {i}: {g} vs {f}");
            }
        }
    }

    /// [`filter3x3`] with every pixel through [`filter_pixel`], the definition.
    fn filter_by_pixel<const C: usize>(w: usize, h: usize, img: &[f32], m: &[f32; 9]) -> Vec<f32> {
        let mut out = vec![0.0; img.len()];
        for y in 0..h {
            for x in 0..w {
                filter_pixel::<C>(w, h, img, &mut out, m, x, y);
            }
        }
        out
    }

    #[test]
    fn the_border_is_the_per_pixel_definition_bit_for_bit() {
        for (w, h) in [(3, 3), (4, 3), (3, 7), (31, 12), (256, 5)] {
            let noise = |n: usize| -> Vec<f32> {
                // Of both signs, and every seventh value zero.
                (0..n)
                    .map(|i| {
                        if i % 7 == 0 {
                            0.0
                        } else {
                            ((i * 37 + 11) % 101) as f32 / 33.0 - 1.5
                        }
                    })
                    .collect()
            };
            let grey = noise(w * h);
            let mut fast = vec![0.0; w * h];
            filter3x3::<1>(w, h, &grey, &mut fast, &EDGE_KERNEL);
            let want = filter_by_pixel::<1>(w, h, &grey, &EDGE_KERNEL);
            let rgb = noise(3 * w * h);
            let mut fast3 = vec![0.0; 3 * w * h];
            filter3x3::<3>(w, h, &rgb, &mut fast3, &SHARPEN_KERNEL);
            let want3 = filter_by_pixel::<3>(w, h, &rgb, &SHARPEN_KERNEL);
            for y in 0..h {
                for x in [0, w - 1]
                    .into_iter()
                    .chain(if y == 0 || y == h - 1 { 1..w - 1 } else { 0..0 })
                {
                    let i = x + y * w;
                    assert_eq!(fast[i].to_bits(), want[i].to_bits(), "{w}x{h}, pixel ({x}, {y})");
                    for c in 0..3 {
                        let j = 3 * i + c;
                        assert_eq!(fast3[j].to_bits(), want3[j].to_bits(), "{w}x{h} RGB, pixel ({x}, {y})");
                    }
                }
            }
        }
    }

    #[test]
    fn flips_mirror_the_image() {
        let (w, h) = (3, 2);
        let mut img = grey(w, h, |x, y| (x + 10 * y) as f32);
        flip_horizontal(w, &mut img);
        assert_eq!(at(&img, w, 0, 0), 2.0);
        assert_eq!(at(&img, w, 2, 1), 10.0);
        flip_vertical(w, h, &mut img);
        assert_eq!(at(&img, w, 0, 0), 12.0);
        assert_eq!(at(&img, w, 0, 1), 2.0);
    }

    #[test]
    fn sharpen_keeps_uniform_images_and_clamps() {
        let (w, h) = (4, 4);
        let mut img = grey(w, h, |_, _| 0.5);
        sharpen(w, h, &mut img, &mut Vec::new());
        assert!((at(&img, w, 1, 1) - 0.5).abs() < 1e-3);
        assert!(img.iter().all(|v| (0.0..=1.0).contains(v)));
    }
}
