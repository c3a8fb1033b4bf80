//! The last pass of a render: the rasteriser's buffers (packed colour, planar depth in
//! metres) become the sensor image (RGB bytes, normalised depth), and CoppeliaSim's
//! packet 1 (image statistics) is gathered on the way: with the depth normalisation in
//! one pass, and over the colours in three simple passes (see `colour`).
//!
//! Each statistic is kept in a few independent lanes (per byte for the channel
//! extremes) that the compiler holds in vector registers; the lanes are folded once at
//! the end.

use super::simd::multiversion;

/// Packet 1 as CoppeliaSim reports it: minimum, maximum and average of intensity, red,
/// green, blue and normalised depth, in that order within each group, all 0..1.
pub(crate) type Packet1 = [f64; 15];

/// Writes `rgb` (3 bytes per pixel) from `color` (`0x00BBGGRR` per pixel) and `depth`
/// (planar depth normalised between `near` and `far`, 1 where `zbuf` is infinite,
/// that is, nothing was drawn) from `zbuf` (metres), and returns packet 1 of the
/// result. All the buffers hold the same number of pixels. Without `color` (a sensor
/// ignoring RGB) `rgb` is left as it is, without `depth` nothing is written there, and
/// packet 1's values for what was skipped are 0.
pub(crate) fn resolve(
    color: Option<&[u32]>,
    zbuf: &[f32],
    near: f32,
    far: f32,
    rgb: &mut [u8],
    depth: Option<&mut [f32]>,
) -> Packet1 {
    let n = zbuf.len();
    if n == 0 {
        return [0.0; 15];
    }
    let [cmin, cmax, csum] = color.map_or([[0.0; 4]; 3], |c| colour(c, rgb));
    let [dmin, dmax, dsum] = depth.map_or([0.0; 3], |d| depths(zbuf, near, far, d));
    let scale = [765.0, 255.0, 255.0, 255.0];
    let mut out = [0.0; 15];
    for k in 0..4 {
        out[k] = cmin[k] / scale[k];
        out[5 + k] = cmax[k] / scale[k];
        out[10 + k] = csum[k] / n as f64 / scale[k];
    }
    out[4] = dmin;
    out[9] = dmax;
    out[14] = dsum / n as f64;
    out
}

/// RGB bytes from packed colours; returns min, max and sum of intensity (r + g + b),
/// r, g and b, in byte units.
///
/// Three passes, each simple enough to stay in vector registers (one fused loop
/// spills and is twice as slow): channel extremes on the bytes, intensity extremes
/// and channel sums on the words, then the RGB bytes.
fn colour(color: &[u32], rgb: &mut [u8]) -> [[f64; 4]; 3] {
    let (blocks, rest) = color.as_chunks::<4>();
    // The last pixels padded with copies of the first one, which changes no extreme;
    // the copies' contribution to the sums is taken out below.
    let mut last = [color[0]; 4];
    last[..rest.len()].copy_from_slice(rest);
    let padding = (4 - rest.len()) % 4;
    let tail: &[[u32; 4]] = if rest.is_empty() {
        &[]
    } else {
        std::slice::from_ref(&last)
    };
    let (mut bmin, mut bmax) = ([u8::MAX; 16], [0u8; 16]);
    let (mut imin, mut imax) = ([i32::MAX; 4], [0i32; 4]);
    let mut sum = [[0u32; 4]; 3];
    for part in [blocks, tail] {
        byte_extremes(part, &mut bmin, &mut bmax);
        pixel_stats(part, &mut imin, &mut imax, &mut sum);
    }
    super::bytes::write_packed_rgb(color, rgb);

    let first = color[0].to_le_bytes().map(u64::from);
    let channel_sum = |k: usize| sum[k].iter().map(|&s| u64::from(s)).sum::<u64>() - padding as u64 * first[k];
    let sums = [0, 1, 2].map(channel_sum);
    // Byte `k` of each of the four pixels.
    let fold = |b: &[u8; 16], k: usize, f: fn(u8, u8) -> u8| (1..4).fold(b[k], |acc, i| f(acc, b[4 * i + k]));
    let mut out = [[0.0; 4]; 3];
    out[0][0] = f64::from(imin.iter().copied().min().unwrap_or(0));
    out[1][0] = f64::from(imax.iter().copied().max().unwrap_or(0));
    out[2][0] = (sums[0] + sums[1] + sums[2]) as f64;
    for k in 0..3 {
        out[0][k + 1] = f64::from(fold(&bmin, k, u8::min));
        out[1][k + 1] = f64::from(fold(&bmax, k, u8::max));
        out[2][k + 1] = sums[k] as f64;
    }
    out
}

/// Extremes per byte of four packed pixels (R G B 0, four times).
// Not inlined: inside a larger function the compiler has been seen to make this loop
// scalar (15x slower). Not compiled for AVX2 either (`super::simd`): that copy measured
// eight times slower.
#[inline(never)]
fn byte_extremes(blocks: &[[u32; 4]], bmin: &mut [u8; 16], bmax: &mut [u8; 16]) {
    for px in blocks {
        let mut bytes = [0u8; 16];
        for (b, p) in bytes.as_chunks_mut::<4>().0.iter_mut().zip(px) {
            *b = p.to_le_bytes();
        }
        for j in 0..16 {
            bmin[j] = bmin[j].min(bytes[j]);
            bmax[j] = bmax[j].max(bytes[j]);
        }
    }
}

multiversion! {
    /// Intensity extremes and channel sums per pixel of four. At most 255 per channel and
    /// 512 * 512 / 4 pixels per lane, so no sum overflows.
    ///
    /// Not inlined: inside a larger function the compiler has been seen to make this loop
    /// scalar (15x slower). Twice as fast with AVX2 (see [`super::simd`]).
    #[inline(never)]
    fn pixel_stats(blocks: &[[u32; 4]], imin: &mut [i32; 4], imax: &mut [i32; 4], sum: &mut [[u32; 4]; 3]) {
        for px in blocks {
            for i in 0..4 {
                let (r, g, b) = (px[i] & 0xff, px[i] >> 8 & 0xff, px[i] >> 16 & 0xff);
                let v = (r + g + b) as i32;
                imin[i] = imin[i].min(v);
                imax[i] = imax[i].max(v);
                sum[0][i] += r;
                sum[1][i] += g;
                sum[2][i] += b;
            }
        }
    }
}

multiversion! {
    /// Normalised depth from planar depth in metres (background at the far plane, as
    /// CoppeliaSim's depth buffer); returns its min, max and sum.
    // Not inlined: inside a larger function the compiler has been seen to make this loop
    // scalar (15x slower).
    #[inline(never)]
    fn depths(zbuf: &[f32], near: f32, far: f32, depth: &mut [f32]) -> [f64; 3] {
        // Eight lanes: one AVX2 vector, two baseline ones. (With four, the AVX2 copy was
        // twice as slow as the baseline.) The lanes fix the order of the f32 sums, so
        // both copies give the same bits.
        const LANES: usize = 8;
        let inv_span = 1.0 / (far - near);
        // Nothing drawn is z = +inf, which the clamp takes to 1; z is never NaN. (Written
        // as compares rather than `clamp`, whose NaN rules cost vector instructions.)
        let normalise = |z: f32| {
            let v = (z - near) * inv_span;
            let v = if v > 0.0 { v } else { 0.0 };
            if v < 1.0 { v } else { 1.0 }
        };
        let (mut lo, mut hi) = ([f32::INFINITY; LANES], [f32::NEG_INFINITY; LANES]);
        let mut total = 0.0f64;
        let (blocks, rest) = zbuf.as_chunks::<LANES>();
        let (out_blocks, out_rest) = depth.as_chunks_mut::<LANES>();
        // Sums in f32 lanes over 64 blocks at most (error below 1e-5 relative), then f64.
        for (zs, ds) in blocks.chunks(64).zip(out_blocks.chunks_mut(64)) {
            let mut acc = [0.0f32; LANES];
            for (z, d) in zs.iter().zip(ds) {
                for i in 0..LANES {
                    let v = normalise(z[i]);
                    d[i] = v;
                    lo[i] = if v < lo[i] { v } else { lo[i] };
                    hi[i] = if v > hi[i] { v } else { hi[i] };
                    acc[i] += v;
                }
            }
            total += acc.iter().map(|&a| f64::from(a)).sum::<f64>();
        }
        for (&z, d) in rest.iter().zip(out_rest) {
            *d = normalise(z);
            lo[0] = lo[0].min(*d);
            hi[0] = hi[0].max(*d);
            total += f64::from(*d);
        }
        [
            f64::from(lo.iter().copied().fold(f32::INFINITY, f32::min)),
            f64::from(hi.iter().copied().fold(f32::NEG_INFINITY, f32::max)),
            total,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Packet 1 the obvious way: per pixel, in f64, from the resolved image.
    fn reference(rgb: &[u8], depth: &[f32]) -> Vec<f64> {
        let mut min = [f64::INFINITY; 5];
        let mut max = [f64::NEG_INFINITY; 5];
        let mut sum = [0.0f64; 5];
        for (px, &d) in rgb.chunks_exact(3).zip(depth) {
            let [r, g, b] = [px[0], px[1], px[2]].map(|c| f64::from(c) / 255.0);
            let v = [(r + g + b) / 3.0, r, g, b, f64::from(d)];
            for k in 0..5 {
                min[k] = min[k].min(v[k]);
                max[k] = max[k].max(v[k]);
                sum[k] += v[k];
            }
        }
        let n = depth.len() as f64;
        min.iter()
            .chain(&max)
            .copied()
            .chain(sum.iter().map(|s| s / n))
            .collect()
    }

    #[test]
    fn image_and_packet1_match_the_per_pixel_definition() {
        // Sizes with and without a partial block, and pseudo-random content.
        for (w, h) in [(16, 1), (37, 5), (256, 256), (1, 1), (512, 512)] {
            let n = w * h;
            let mut x = 0x2545_f491_4f6c_dd1du64;
            let mut next = || {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                x
            };
            let color: Vec<u32> = (0..n).map(|_| (next() >> 20) as u32 & 0x00ff_ffff).collect();
            // Metres between near 0.01 and far 1, some pixels with nothing drawn.
            let zbuf: Vec<f32> = (0..n)
                .map(|i| {
                    if i % 7 == 3 {
                        f32::INFINITY
                    } else {
                        0.01 + (i % 97) as f32 / 96.0 * 1.2
                    }
                })
                .collect();
            let (mut rgb, mut depth) = (vec![0u8; 3 * n], vec![0f32; n]);
            let got = resolve(Some(&color), &zbuf, 0.01, 1.0, &mut rgb, Some(&mut depth));
            for i in 0..n {
                assert_eq!(rgb[3 * i..3 * i + 3], color[i].to_le_bytes()[..3], "{w}x{h} pixel {i}");
                let want = if zbuf[i].is_finite() {
                    ((zbuf[i] - 0.01) / 0.99).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                assert!(
                    (depth[i] - want).abs() < 1e-6,
                    "{w}x{h} depth {i}: {} vs {want}",
                    depth[i]
                );
            }
            let want = reference(&rgb, &depth);
            for (k, (g, r)) in got.iter().zip(&want).enumerate() {
                // Depth sums run in f32 lanes (CoppeliaSim's packets are f32 too).
                assert!((g - r).abs() < 1e-6, "{w}x{h}, value {k}: {g} vs {r}");
            }
        }
    }
}
