//! `simVision.selectiveColorOnWorkImg` and `simVision.blobDetectionOnWorkImg` over a
//! work image (`width * height` RGB `f32` triples, nominally 0..1, bottom row first).
//!
//! The rules follow CoppeliaSim's simVision plugin: a pixel belongs to a blob when the
//! mean of its R, G, B is at least the threshold; blobs are 8-connected; each is
//! described by its relative pixel count and the smallest-area rectangle around it
//! (orientation, centre, width, height, relative to the image). The rectangle is fitted
//! to the pixels as unit squares, so a 10-pixel-wide square blob is 10 pixels wide.

use std::f64::consts::FRAC_PI_4;

/// Values describing one blob in the packet (CoppeliaSim's layout).
pub const BLOB_VALUES: usize = 6;

/// Colours of blobs when the detection recolours the work image: red, green, yellow,
/// blue, magenta, cyan, white, then the same darker, as simVision paints them.
const PALETTE: [[f32; 3]; 7] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
    [1.0, 1.0, 1.0],
];

/// `simVision.selectiveColorOnWorkImg`'s pixel test and removal: a pixel matches when
/// each component is within `tolerance` of `color`, in RGB, or in HSL (hue wrapping
/// around 1) when `rgb` is false. With `keep`, pixels that do not match turn black;
/// without, pixels that match do.
/// With `removed` (buffer 1, the work image's size), each pixel removed is copied there
/// and each kept one is black there, as the plugin's `removedPartToBuffer1` does.
pub(crate) fn selective_color(
    work: &mut [f32],
    color: [f32; 3],
    tolerance: [f32; 3],
    rgb: bool,
    keep: bool,
    mut removed: Option<&mut [f32]>,
) {
    let low: [f32; 3] = std::array::from_fn(|k| color[k] - tolerance[k]);
    let high: [f32; 3] = std::array::from_fn(|k| color[k] + tolerance[k]);
    let within = |k: usize, v: f32| v >= low[k] && v <= high[k];
    for (i, px) in work.as_chunks_mut::<3>().0.iter_mut().enumerate() {
        let matches = if rgb {
            (0..3).all(|k| within(k, px[k]))
        } else {
            let hsl = rgb_to_hsl(*px);
            // Hue is an angle: a window reaching past 0 or 1 continues on the other side.
            let hue_ok =
                high[0] - low[0] >= 1.0 || within(0, hsl[0]) || within(0, hsl[0] + 1.0) || within(0, hsl[0] - 1.0);
            hue_ok && within(1, hsl[1]) && within(2, hsl[2])
        };
        let remove = matches != keep;
        if let Some(to) = removed.as_deref_mut().and_then(|b| b.get_mut(3 * i..3 * i + 3)) {
            to.copy_from_slice(if remove { px.as_slice() } else { &[0.0; 3] });
        }
        if remove {
            *px = [0.0; 3];
        }
    }
}

/// RGB (0..1) to hue, saturation, lightness (each 0..1).
fn rgb_to_hsl([r, g, b]: [f32; 3]) -> [f32; 3] {
    let max = r.max(g).max(b);
    let min = r.min(g).min(b);
    let l = (max + min) / 2.0;
    let d = max - min;
    if d <= 0.0 {
        return [0.0, 0.0, l];
    }
    let s = if l > 0.5 {
        d / (2.0 - max - min)
    } else {
        d / (max + min)
    };
    let h = if max == r {
        (g - b) / d + if g < b { 6.0 } else { 0.0 }
    } else if max == g {
        (b - r) / d + 2.0
    } else {
        (r - g) / d + 4.0
    };
    [h / 6.0, s, l]
}

/// One blob found by [`detect_blobs`], in pixels of the image (x from the left, y from
/// the bottom, a pixel spanning one unit).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Blob {
    /// Number of pixels.
    pub pixels: usize,
    /// Angle of the rectangle's width axis from the image's x axis, counter-clockwise,
    /// radians in [-π/4, π/4).
    pub orientation: f64,
    /// Centre of the rectangle.
    pub center: [f64; 2],
    /// Extent along the width axis, then along the height axis.
    pub size: [f64; 2],
}

/// Options of `simVision.blobDetectionOnWorkImg`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BlobOptions {
    /// Minimum mean of R, G, B of a blob pixel.
    pub threshold: f32,
    /// Minimum blob size as a fraction of the image's pixels; smaller blobs are
    /// dropped, and blacked out in the work image as simVision does.
    pub min_size: f64,
    /// Paint the background black and each blob in a colour of its own.
    pub recolor: bool,
    /// Draw each blob's rectangle in this colour.
    pub overlay: Option<[f32; 3]>,
}

/// Finds the blobs of the work image, in the order of their first pixel (rows from the
/// bottom, each from the left), and applies the options' changes to the image.
pub(crate) fn detect_blobs(width: usize, height: usize, work: &mut [f32], opt: BlobOptions) -> Vec<Blob> {
    let n = width * height;
    if work.len() < 3 * n || n == 0 {
        return Vec::new();
    }
    let labels = label(width, height, work, opt.threshold);
    let count = labels.iter().flatten().map(|&l| l + 1).max().unwrap_or(0);
    let mut pixels = vec![0usize; count];
    for &l in labels.iter().flatten() {
        pixels[l] += 1;
    }
    let big: Vec<bool> = pixels.iter().map(|&p| p as f64 / n as f64 >= opt.min_size).collect();
    // The corners of each blob's outline pixels: an inner pixel cannot be an extreme
    // of any projection, so the rectangle only needs these.
    let mut corners: Vec<Vec<[f64; 2]>> = vec![Vec::new(); count];
    let at = |x: isize, y: isize| -> Option<usize> {
        if x < 0 || y < 0 || x >= width as isize || y >= height as isize {
            None
        } else {
            labels[y as usize * width + x as usize]
        }
    };
    for y in 0..height {
        for x in 0..width {
            let i = y * width + x;
            let Some(l) = labels[i] else {
                if opt.recolor {
                    work[3 * i..3 * i + 3].fill(0.0);
                }
                continue;
            };
            if !big[l] {
                work[3 * i..3 * i + 3].fill(0.0);
                continue;
            }
            if opt.recolor {
                // Seven hues, then each darker by 0.2 (wrapping back up), as simVision.
                let mut v = 0.8 - (l / PALETTE.len()) as f32 * 0.2;
                while v < 0.19 {
                    v += 0.7;
                }
                let c = PALETTE[l % PALETTE.len()];
                work[3 * i..3 * i + 3].copy_from_slice(&[c[0] * v, c[1] * v, c[2] * v]);
            }
            let (xi, yi) = (x as isize, y as isize);
            let outline = (-1..=1).any(|dy| (-1..=1).any(|dx| at(xi + dx, yi + dy).is_none()));
            if outline {
                let (fx, fy) = (x as f64, y as f64);
                corners[l].extend([[fx, fy], [fx + 1.0, fy], [fx, fy + 1.0], [fx + 1.0, fy + 1.0]]);
            }
        }
    }
    let blobs: Vec<Blob> = (0..count)
        .filter(|&l| big[l])
        .map(|l| {
            let (orientation, center, size) = min_area_rectangle(&corners[l]);
            Blob {
                pixels: pixels[l],
                orientation,
                center,
                size,
            }
        })
        .collect();
    if let Some(color) = opt.overlay {
        for b in &blobs {
            draw_rectangle(width, height, work, b, color);
        }
    }
    blobs
}

/// Labels the pixels whose mean of R, G, B is at least `threshold` by 8-connected
/// component, numbered from 0 in the order of their first pixel.
fn label(width: usize, height: usize, work: &[f32], threshold: f32) -> Vec<Option<usize>> {
    let n = width * height;
    let on = |i: usize| (work[3 * i] + work[3 * i + 1] + work[3 * i + 2]) / 3.0 >= threshold;
    // Union-find over provisional labels: one pass sees only the neighbours already
    // visited (left, and the three below), so two arms of a U meet only later.
    let mut parent: Vec<usize> = Vec::new();
    fn root(parent: &mut [usize], mut a: usize) -> usize {
        while parent[a] != a {
            parent[a] = parent[parent[a]];
            a = parent[a];
        }
        a
    }
    let mut provisional: Vec<Option<usize>> = vec![None; n];
    for y in 0..height {
        for x in 0..width {
            let i = y * width + x;
            if !on(i) {
                continue;
            }
            let mut neighbours = [None; 4];
            if x > 0 {
                neighbours[0] = provisional[i - 1];
            }
            if y > 0 {
                let below = i - width;
                if x > 0 {
                    neighbours[1] = provisional[below - 1];
                }
                neighbours[2] = provisional[below];
                if x + 1 < width {
                    neighbours[3] = provisional[below + 1];
                }
            }
            let mut mine: Option<usize> = None;
            for l in neighbours.into_iter().flatten() {
                let r = root(&mut parent, l);
                match mine {
                    None => mine = Some(r),
                    Some(m) if m != r => {
                        // The older label stays the root, keeping first-pixel order.
                        let (keep, join) = if m < r { (m, r) } else { (r, m) };
                        parent[join] = keep;
                        mine = Some(keep);
                    }
                    Some(_) => {}
                }
            }
            provisional[i] = Some(mine.unwrap_or_else(|| {
                parent.push(parent.len());
                parent.len() - 1
            }));
        }
    }
    // Final labels, dense, in the order their roots were created (= first pixel).
    let mut dense = vec![usize::MAX; parent.len()];
    let mut next = 0;
    for l in 0..parent.len() {
        let r = root(&mut parent, l);
        if dense[r] == usize::MAX {
            dense[r] = next;
            next += 1;
        }
        dense[l] = dense[r];
    }
    provisional.into_iter().map(|p| p.map(|l| dense[l])).collect()
}

/// The smallest-area rectangle around `points`: orientation in [-π/4, π/4), centre,
/// and extents along its axes. Rectangles repeat every quarter turn, so the search
/// covers one: four angles 22.5° apart, then three refinements around the best, each
/// a third of the previous step (to about 0.8°). An axis-aligned rectangle is found
/// exactly, angle 0 being one of the first four.
fn min_area_rectangle(points: &[[f64; 2]]) -> (f64, [f64; 2], [f64; 2]) {
    let fit = |angle: f64| {
        let (s, c) = angle.sin_cos();
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in points {
            let uv = [p[0] * c + p[1] * s, -p[0] * s + p[1] * c];
            for k in 0..2 {
                lo[k] = lo[k].min(uv[k]);
                hi[k] = hi[k].max(uv[k]);
            }
        }
        let size = [hi[0] - lo[0], hi[1] - lo[1]];
        let (cu, cv) = ((hi[0] + lo[0]) / 2.0, (hi[1] + lo[1]) / 2.0);
        let center = [cu * c - cv * s, cu * s + cv * c];
        (angle, center, size)
    };
    let area = |r: &(f64, [f64; 2], [f64; 2])| r.2[0] * r.2[1];
    let mut step = FRAC_PI_4 / 2.0;
    let mut best = fit(0.0);
    for k in [-2.0, -1.0, 1.0] {
        let r = fit(k * step);
        if area(&r) < area(&best) {
            best = r;
        }
    }
    for _ in 0..3 {
        step /= 3.0;
        let around = best.0;
        for k in [-2.0, -1.0, 1.0, 2.0] {
            let r = fit(around + k * step);
            if area(&r) < area(&best) {
                best = r;
            }
        }
    }
    // Back into [-π/4, π/4): a quarter turn swaps width and height.
    let (mut angle, center, mut size) = best;
    if angle >= FRAC_PI_4 {
        angle -= 2.0 * FRAC_PI_4;
        size.swap(0, 1);
    } else if angle < -FRAC_PI_4 {
        angle += 2.0 * FRAC_PI_4;
        size.swap(0, 1);
    }
    (angle, center, size)
}

/// Draws a blob's rectangle into the work image (pixels outside the image skipped).
fn draw_rectangle(width: usize, height: usize, work: &mut [f32], b: &Blob, color: [f32; 3]) {
    let (s, c) = b.orientation.sin_cos();
    // Corners lie on pixel edges; half a pixel inwards they are the centres of the
    // blob's corner pixels, where the outline is drawn.
    let (hu, hv) = ((b.size[0] / 2.0 - 0.5).max(0.0), (b.size[1] / 2.0 - 0.5).max(0.0));
    let corner = |su: f64, sv: f64| {
        let x = b.center[0] + su * hu * c - sv * hv * s;
        let y = b.center[1] + su * hu * s + sv * hv * c;
        [x.floor() as i64, y.floor() as i64]
    };
    let pts = [
        corner(-1.0, -1.0),
        corner(1.0, -1.0),
        corner(1.0, 1.0),
        corner(-1.0, 1.0),
    ];
    for k in 0..4 {
        line(width, height, work, pts[k], pts[(k + 1) % 4], color);
    }
}

/// Bresenham's line from `a` to `b`, both ends included.
fn line(width: usize, height: usize, work: &mut [f32], a: [i64; 2], b: [i64; 2], color: [f32; 3]) {
    let (dx, dy) = ((b[0] - a[0]).abs(), -(b[1] - a[1]).abs());
    let (sx, sy) = (if a[0] < b[0] { 1 } else { -1 }, if a[1] < b[1] { 1 } else { -1 });
    let (mut x, mut y, mut err) = (a[0], a[1], dx + dy);
    loop {
        if x >= 0 && y >= 0 && (x as usize) < width && (y as usize) < height {
            let i = 3 * (y as usize * width + x as usize);
            work[i..i + 3].copy_from_slice(&color);
        }
        if x == b[0] && y == b[1] {
            break;
        }
        let e2 = 2 * err;
        if e2 >= dy {
            err += dy;
            x += sx;
        }
        if e2 <= dx {
            err += dx;
            y += sy;
        }
    }
}

/// The packet `simVision.blobDetectionOnWorkImg` returns, as floats: the blob count,
/// [`BLOB_VALUES`], then per blob its size (fraction of the image's pixels),
/// orientation (radians), centre x and y, width and height (fractions of the image's
/// width and height).
pub(crate) fn blob_packet(width: usize, height: usize, blobs: &[Blob]) -> Vec<f32> {
    let (w, h) = (width as f64, height as f64);
    let mut out = Vec::with_capacity(2 + BLOB_VALUES * blobs.len());
    out.extend([blobs.len() as f32, BLOB_VALUES as f32]);
    for b in blobs {
        out.extend(
            [
                b.pixels as f64 / (w * h),
                b.orientation,
                b.center[0] / w,
                b.center[1] / h,
                b.size[0] / w,
                b.size[1] / h,
            ]
            .map(|v| v as f32),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: usize, h: usize, on: impl Fn(usize, usize) -> bool) -> Vec<f32> {
        (0..w * h)
            .flat_map(|i| [if on(i % w, i / w) { 1.0 } else { 0.0 }; 3])
            .collect()
    }

    const PLAIN: BlobOptions = BlobOptions {
        threshold: 0.5,
        min_size: 0.0,
        recolor: false,
        overlay: None,
    };

    #[test]
    fn a_u_shape_is_one_blob_and_diagonal_neighbours_connect() {
        // Two arms joined only at the top row: labelled apart at first, merged later.
        let mut u = image(5, 4, |x, y| x == 0 || x == 4 || y == 3);
        assert_eq!(detect_blobs(5, 4, &mut u, PLAIN).len(), 1);
        let mut diag = image(3, 3, |x, y| x == y);
        assert_eq!(detect_blobs(3, 3, &mut diag, PLAIN).len(), 1);
    }

    #[test]
    fn a_rotated_bar_reports_its_angle_and_sides() {
        // A 40 x 8 bar rotated by 20°, rasterised by pixel centres.
        let (w, h) = (100, 100);
        let a = 20f64.to_radians();
        let (s, c) = a.sin_cos();
        let mut img = image(w, h, |x, y| {
            let (px, py) = (x as f64 + 0.5 - 50.0, y as f64 + 0.5 - 50.0);
            (px * c + py * s).abs() <= 20.0 && (-px * s + py * c).abs() <= 4.0
        });
        let blobs = detect_blobs(w, h, &mut img, PLAIN);
        assert_eq!(blobs.len(), 1);
        let b = &blobs[0];
        assert!(
            (b.orientation - a).abs() < 2f64.to_radians(),
            "{}",
            b.orientation.to_degrees()
        );
        assert!(
            (b.size[0] - 40.0).abs() < 2.5 && (b.size[1] - 8.0).abs() < 2.5,
            "{:?}",
            b.size
        );
        assert!((b.center[0] - 50.0).abs() < 1.0 && (b.center[1] - 50.0).abs() < 1.0);
    }

    #[test]
    fn hue_windows_wrap_around_red() {
        // Pure red has hue 0; a window centred on hue 0.98 still takes it.
        let mut px = vec![1.0, 0.0, 0.0, 0.0, 0.0, 1.0];
        selective_color(&mut px, [0.98, 1.0, 0.5], [0.05, 0.1, 0.1], false, true, None);
        assert_eq!(px, vec![1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    }
}
