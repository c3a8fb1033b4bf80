//! Textured triangles: the same coverage, depth and light as the plain path
//! ([`super::fill`]), with u and v interpolated perspective-correctly (u/z and v/z are
//! affine on screen, as 1/z is) and the texture sampled per pixel. Only images with
//! colours take this path (a depth-only, colour-coded or mask render draws textured
//! shapes as plain ones), so it is scalar and kept apart from the vector code of
//! untextured spans: textured shapes are a few tables and walls in a scene.

use super::{
    CamVertex, Camera, ChunkVertex, ClipVertex, MAX_POLY, ScreenVertex, Target, VisualTexture, clip, covered_spans,
    edge, project,
};
use crate::vision::bytes::round_byte;

/// A camera-frame corner with its texture coordinates.
#[derive(Debug, Clone, Copy, Default)]
struct TexVertex {
    cam: CamVertex,
    uv: [f32; 2],
}

impl ClipVertex for TexVertex {
    #[inline]
    fn position(&self) -> [f32; 3] {
        self.cam.p
    }

    #[inline]
    fn lerp(a: TexVertex, b: TexVertex, t: f32) -> TexVertex {
        TexVertex {
            cam: CamVertex::lerp(a.cam, b.cam, t),
            uv: [a.uv[0] + (b.uv[0] - a.uv[0]) * t, a.uv[1] + (b.uv[1] - a.uv[1]) * t],
        }
    }
}

/// A projected corner: [`ScreenVertex`] with u/z and v/z (u and v, orthographic).
#[derive(Clone, Copy)]
struct TexScreen {
    s: ScreenVertex,
    uv_z: [f32; 2],
}

fn tex_project(cam: &Camera, v: TexVertex) -> TexScreen {
    let s = project(cam, v.cam);
    let scale = if cam.ortho { 1.0 } else { s.inv_z };
    TexScreen {
        s,
        uv_z: v.uv.map(|t| t * scale),
    }
}

/// Draws triangle `corners` (not wholly outside the view) with corner coordinates `uv`
/// and `texture`: the texel's colour lit as the plain path lights `color` (RGB scaled to
/// 0..255), replacing it (decal) or multiplying it.
pub(super) fn triangle(
    cam: &Camera,
    target: &mut Target<'_>,
    corners: [ChunkVertex; 3],
    uv: [[f32; 2]; 3],
    texture: &VisualTexture,
    color: [f32; 3],
    id: u32,
) {
    let base = if texture.decal { [255.0; 3] } else { color };
    let codes = corners.iter().fold(0, |acc, v| acc | v.code);
    let mut poly = [TexVertex::default(); MAX_POLY];
    for k in 0..3 {
        poly[k] = TexVertex {
            cam: corners[k].cam,
            uv: uv[k],
        };
    }
    let n = if codes == 0 { 3 } else { clip(cam, &mut poly, 3, codes) };
    for k in 1..n.saturating_sub(1) {
        let tri = [poly[0], poly[k], poly[k + 1]].map(|v| tex_project(cam, v));
        fill(cam, target, tri, texture, base, id);
    }
}

/// Fills one textured triangle inside the frustum, as [`super::fill`] fills a plain one.
fn fill(cam: &Camera, target: &mut Target<'_>, tri: [TexScreen; 3], texture: &VisualTexture, base: [f32; 3], id: u32) {
    let [mut a, mut b, c] = tri;
    let mut area = edge(a.s, b.s, c.s.x, c.s.y);
    if !area.is_finite() || area.abs() < 1e-12 {
        return;
    }
    if area < 0.0 {
        std::mem::swap(&mut a, &mut b);
        area = -area;
    }
    let inv_area = 1.0 / area;
    let w = target.width;
    let steps = [(b, c), (c, a), (a, b)].map(|(p, q)| -(q.s.y - p.s.y));
    // Each value as a plane over the screen: at column 0 of a row from the edge
    // functions there, plus a step per column.
    let plane = |k: [f32; 3]| {
        let step = (steps[0] * k[0] + steps[1] * k[1] + steps[2] * k[2]) * inv_area;
        move |e: [f32; 3]| ((e[0] * k[0] + e[1] * k[1] + e[2] * k[2]) * inv_area, step)
    };
    let iz = plane([a, b, c].map(|v| v.s.inv_z));
    let lz = plane([a, b, c].map(|v| v.s.light_z));
    let uz = plane([a, b, c].map(|v| v.uv_z[0]));
    let vz = plane([a, b, c].map(|v| v.uv_z[1]));
    let (height, rows) = (target.height, target.rows.clone());
    let (with_ids, ortho) = (target.with_ids, cam.ortho);
    covered_spans(w, height, rows, [a.s, b.s, c.s], |row, first, end, e| {
        let start = (row - target.rows.start) * w;
        let ((iz0, diz), (lz0, dlz)) = (iz(e), lz(e));
        let ((uz0, duz), (vz0, dvz)) = (uz(e), vz(e));
        for col in first..end {
            let x = col as f32;
            // The depth exactly as the plain path computes it, so the z-buffer orders
            // textured and plain triangles alike.
            let (z, light, u, v) = if ortho {
                (iz0 + diz * x, lz0 + dlz * x, uz0 + duz * x, vz0 + dvz * x)
            } else {
                let z = 1.0 / (iz0 + diz * x);
                (z, (lz0 + dlz * x) * z, (uz0 + duz * x) * z, (vz0 + dvz * x) * z)
            };
            let i = start + col;
            // Closer than what is drawn (a NaN depth never is), as the plain path tests.
            let Some(zp) = target.zbuf.get_mut(i).filter(|zp| z < **zp) else {
                continue;
            };
            *zp = z;
            let texel = texture.sample(u, v);
            let byte = |k: usize| u32::from(round_byte(base[k] * texel[k] * light));
            if let Some(cp) = target.color.get_mut(i) {
                *cp = byte(0) | byte(1) << 8 | byte(2) << 16;
            }
            if with_ids && let Some(ip) = target.ids.get_mut(i) {
                *ip = id;
            }
        }
    });
}
