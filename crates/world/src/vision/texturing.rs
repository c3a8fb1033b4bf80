//! Textures as the rasteriser draws them: the texture coordinates of each triangle
//! corner of a visual's tessellation, worked out once when the visual is cached, and
//! the sampling of a texture image at u, v.
//!
//! Coordinates are the shape's explicit ones (`sim.applyTexture`, a file's fixed
//! coordinates: u, v per corner of each triangle of `sim.getShapeMesh`), or projected
//! from each corner's position in the texture frame ([`ShapeTexture::position`],
//! `orientation`, in the shape frame), with the texture `uv_scaling` metres wide and
//! centred on the frame's origin where a coordinate is a length:
//! - plane: u = x / su + 1/2, v = y / sv + 1/2;
//! - cylinder: u = the angle about z, one turn across the texture, v = z / sv + 1/2;
//! - sphere: u as the cylinder's, v = the latitude, pole to pole across the texture;
//! - cube: each triangle as the plane mapping onto the texture frame's plane most
//!   facing it (x, y on z; y, z on x; x, z on y).
//!
//! Around a cylinder or sphere, a triangle straddling the seam (u jumping from near 1 to
//! near 0) has its low corners moved up by one turn, so it shows the texture's edge
//! rather than the whole texture squeezed backwards.
//!
//! v runs up the picture: v = 0 is its bottom row (CoppeliaSim's convention, which the
//! file reader's notes confirm: the first stored row is where v = 0), so a plane
//! mapping seen from +z shows the picture upright with u along x.

use std::sync::Arc;

use super::tessellate::TriMesh;
use crate::math::{Pose, pose_from_euler};
use crate::world::{ShapeTexture, Texture, TextureMapping};

/// `sim.setShapeTexture` option bits the renderer reads.
const NO_INTERPOLATION: i64 = 1;
const DECAL: i64 = 2;
const REPEAT_U: i64 = 4;
const REPEAT_V: i64 = 8;

/// A visual's texture, ready to draw.
#[derive(Debug, Clone)]
pub(crate) struct VisualTexture {
    /// The image: RGBA, rows from the top.
    rgba: Arc<Vec<u8>>,
    width: usize,
    height: usize,
    /// u, v of each corner of each triangle, parallel to the tessellation's triangles.
    pub uvs: Vec<[[f32; 2]; 3]>,
    /// The texel's colour replaces the visual's (decal), rather than multiplying it.
    pub decal: bool,
    /// Repeat (else clamp to the edge) along u, along v.
    repeat: [bool; 2],
    /// Bilinear (else nearest-texel) sampling.
    interpolate: bool,
}

impl VisualTexture {
    /// The texture `texture` worn as `worn` by a visual tessellated as `mesh`, placed at
    /// `local` in the shape frame. `explicit`: the visual's share of the shape's explicit
    /// coordinates (6 numbers per triangle of its mesh data) when the texture has them.
    pub fn new(
        texture: &Texture,
        worn: &ShapeTexture,
        mesh: &TriMesh,
        local: &Pose,
        explicit: Option<&[f32]>,
    ) -> VisualTexture {
        let uvs = match explicit {
            Some(coordinates) => explicit_uvs(mesh, coordinates),
            None => projected_uvs(mesh, local, worn),
        };
        VisualTexture {
            rgba: Arc::clone(&texture.rgba),
            width: texture.resolution[0] as usize,
            height: texture.resolution[1] as usize,
            uvs,
            decal: worn.options & DECAL != 0,
            repeat: [worn.options & REPEAT_U != 0, worn.options & REPEAT_V != 0],
            interpolate: worn.options & NO_INTERPOLATION == 0,
        }
    }

    /// The texture's colours at `N` points (`u[k]`, `v[k]`) at once, each channel 0..1,
    /// for the lanes `live` selects (the others are 0).
    ///
    /// The coordinates' wrapping and the texel indices and weights are worked out for
    /// all lanes in array code, which the rasteriser's AVX2 copy turns into vector
    /// instructions (and `floor` into one instruction rather than a library call); only
    /// the texel reads are per lane, and each lane's result does not depend on the
    /// others or on `N`.
    #[inline(always)]
    pub fn sample_lanes<const N: usize>(&self, u: [f32; N], v: [f32; N], live: [bool; N]) -> [[f32; 3]; N] {
        let (w, h) = (self.width, self.height);
        let mut out = [[0.0; 3]; N];
        if self.interpolate {
            // Texel centres at half-integers: the four around the point, weighted.
            let (x0, x1, fx) = bilinear(u, w, self.repeat[0]);
            let (y0, y1, fy) = bilinear(v, h, self.repeat[1]);
            for k in 0..N {
                if !live[k] {
                    continue;
                }
                let [a, b, c, d] = [(x0[k], y0[k]), (x1[k], y0[k]), (x0[k], y1[k]), (x1[k], y1[k])]
                    .map(|(x, y)| self.texel(x as usize, y as usize));
                for j in 0..3 {
                    let lo = a[j] + (b[j] - a[j]) * fx[k];
                    let hi = c[j] + (d[j] - c[j]) * fx[k];
                    out[k][j] = lo + (hi - lo) * fy[k];
                }
            }
        } else {
            let (x, y) = (nearest(u, w, self.repeat[0]), nearest(v, h, self.repeat[1]));
            for k in 0..N {
                if live[k] {
                    out[k] = self.texel(x[k] as usize, y[k] as usize);
                }
            }
        }
        out
    }

    /// Texel `x` (from the left), `y` (from the bottom), 0..1 per channel.
    #[inline(always)]
    fn texel(&self, x: usize, y: usize) -> [f32; 3] {
        let row = self.height - 1 - y.min(self.height - 1);
        let at = (row * self.width + x.min(self.width - 1)) * 4;
        match self.rgba.get(at..at + 3) {
            Some(p) => [
                UNIT[usize::from(p[0])],
                UNIT[usize::from(p[1])],
                UNIT[usize::from(p[2])],
            ],
            None => [0.0; 3],
        }
    }
}

/// `b / 255` for each byte `b`: a texel channel as 0..1, looked up rather than divided
/// (a bilinear sample reads twelve channels), with the division's exact result.
static UNIT: [f32; 256] = {
    let mut table = [0.0; 256];
    let mut b = 0;
    while b < 256 {
        table[b] = b as f32 / 255.0;
        b += 1;
    }
    table
};

/// `t` within 0..1: its fraction when repeating, else clamped to the edges. A
/// non-finite coordinate (a degenerate triangle's) reads as 0.
#[inline(always)]
fn wrap(t: f32, repeat: bool) -> f32 {
    if !t.is_finite() {
        0.0
    } else if repeat {
        t - t.floor()
    } else {
        t.clamp(0.0, 1.0)
    }
}

/// The texel of `n` along one axis that each coordinate `t[k]` falls in.
#[inline(always)]
fn nearest<const N: usize>(t: [f32; N], n: usize, repeat: bool) -> [u32; N] {
    // A side is at most MAX_TEXTURE_SIDE texels: n and the indices fit in u32.
    let (nf, last) = (n as f32, n.saturating_sub(1) as u32);
    // 0 <= t <= 1, so the product is 0..=n; t = 1 (clamped) is the last texel.
    t.map(|t| ((wrap(t, repeat) * nf) as u32).min(last))
}

/// For each coordinate `t[k]`, the two texels of `n` along one axis whose centres are
/// on either side of it, and the weight of the second: neighbours across the edge when
/// repeating, else the edge texel twice.
#[inline(always)]
fn bilinear<const N: usize>(t: [f32; N], n: usize, repeat: bool) -> ([u32; N], [u32; N], [f32; N]) {
    let (nf, ni) = (n as f32, n as i32);
    let (mut first, mut second, mut weight) = ([0; N], [0; N], [0.0; N]);
    // Within 0..n: one wrap either way when repeating (k is -1..=n), else the edge.
    let pick = |k: i32| {
        if repeat {
            let k = if k < 0 { k + ni } else { k };
            (if k >= ni { k - ni } else { k }) as u32
        } else {
            k.clamp(0, ni - 1) as u32
        }
    };
    for k in 0..N {
        let x = wrap(t[k], repeat) * nf - 0.5;
        let x0 = x.floor();
        weight[k] = x - x0;
        // -1 <= x0 <= n - 1.
        let i = x0 as i32;
        first[k] = pick(i);
        second[k] = pick(i + 1);
    }
    (first, second, weight)
}

/// Corner coordinates from explicit ones: triangle `k` of the mesh data has
/// `coordinates[6k..6k + 6]`; a tessellation triangle finds its data triangle through
/// [`TriMesh::source`] (itself, for a mesh that left none out). Missing ones are 0.
fn explicit_uvs(mesh: &TriMesh, coordinates: &[f32]) -> Vec<[[f32; 2]; 3]> {
    (0..mesh.triangles.len())
        .map(|i| {
            let k = mesh.source.get(i).map_or(i, |&s| s as usize);
            match coordinates.get(6 * k..6 * k + 6) {
                Some(c) => [[c[0], c[1]], [c[2], c[3]], [c[4], c[5]]],
                None => [[0.0; 2]; 3],
            }
        })
        .collect()
}

/// Corner coordinates projected by the texture's mapping (see the module docs).
fn projected_uvs(mesh: &TriMesh, local: &Pose, worn: &ShapeTexture) -> Vec<[[f32; 2]; 3]> {
    let texture_from_visual = pose_from_euler(worn.position, worn.orientation).inverse() * local;
    let [su, sv] = worn.uv_scaling.map(|s| if s.is_finite() && s > 0.0 { s } else { 1.0 });
    let turn = std::f64::consts::TAU;
    let mut out = Vec::with_capacity(mesh.triangles.len());
    for chunk in &mesh.chunks {
        let positions = mesh.chunk_positions(chunk);
        for tri in mesh.chunk_triangles(chunk) {
            let p = tri.map(|i| {
                let v = positions.get(i as usize).copied().unwrap_or_default();
                let q = texture_from_visual * nalgebra::Point3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]));
                [q.x, q.y, q.z]
            });
            let plane = |a: usize, b: usize| p.map(|q| [q[a] / su + 0.5, q[b] / sv + 0.5]);
            let around = |q: [f64; 3]| q[1].atan2(q[0]) / turn + 0.5;
            let mut uv = match worn.mapping {
                TextureMapping::Plane | TextureMapping::Coordinates => plane(0, 1),
                TextureMapping::Cylinder => p.map(|q| [around(q), q[2] / sv + 0.5]),
                TextureMapping::Sphere => {
                    p.map(|q| [around(q), q[2].atan2(q[0].hypot(q[1])) / std::f64::consts::PI + 0.5])
                }
                TextureMapping::Cube => {
                    let e = |a: usize, b: usize| [0, 1, 2].map(|k| p[a][k] - p[b][k]);
                    let (d1, d2) = (e(1, 0), e(2, 0));
                    let n = [
                        (d1[1] * d2[2] - d1[2] * d2[1]).abs(),
                        (d1[2] * d2[0] - d1[0] * d2[2]).abs(),
                        (d1[0] * d2[1] - d1[1] * d2[0]).abs(),
                    ];
                    if n[2] >= n[0] && n[2] >= n[1] {
                        plane(0, 1)
                    } else if n[0] >= n[1] {
                        plane(1, 2)
                    } else {
                        plane(0, 2)
                    }
                }
            };
            if matches!(worn.mapping, TextureMapping::Cylinder | TextureMapping::Sphere) {
                let (lo, hi) = uv.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| {
                    (lo.min(c[0]), hi.max(c[0]))
                });
                if hi - lo > 0.5 {
                    for c in &mut uv {
                        if c[0] < 0.5 {
                            c[0] += 1.0;
                        }
                    }
                }
            }
            out.push(uv.map(|c| c.map(|x| if x.is_finite() { x as f32 } else { 0.0 })));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Geometry;

    /// A 2 x 2 texture: red, green on the top row; blue, white on the bottom.
    fn checker(options: i64) -> VisualTexture {
        let texture = Texture {
            name: "checker".into(),
            resolution: [2, 2],
            rgba: Arc::new(vec![
                255, 0, 0, 255, 0, 255, 0, 255, //
                0, 0, 255, 255, 255, 255, 255, 255,
            ]),
        };
        let mesh = TriMesh::from_geometry(&Geometry::Box {
            half_extents: [0.5, 0.5, 0.01],
        });
        let worn = ShapeTexture {
            id: 0,
            mapping: TextureMapping::Plane,
            options,
            uv_scaling: [1.0, 1.0],
            position: [0.0; 3],
            orientation: [0.0; 3],
            coordinates: None,
        };
        VisualTexture::new(&texture, &worn, &mesh, &Pose::identity(), None)
    }

    impl VisualTexture {
        /// One point's colour: a one-lane [`VisualTexture::sample_lanes`].
        fn sample(&self, u: f32, v: f32) -> [f32; 3] {
            self.sample_lanes([u], [v], [true])[0]
        }
    }

    #[test]
    fn eight_lanes_sample_as_one_lane_does() {
        // Coordinates inside, on and beyond the edges, and not finite.
        let ts = [
            -2.3,
            -1.0,
            -0.26,
            0.0,
            0.01,
            0.25,
            0.49,
            0.5,
            0.75,
            0.99,
            1.0,
            1.7,
            f32::NAN,
            f32::INFINITY,
        ];
        for options in [
            0,
            NO_INTERPOLATION,
            REPEAT_U | REPEAT_V,
            NO_INTERPOLATION | REPEAT_U | REPEAT_V,
        ] {
            let t = checker(options);
            for (k, &v) in ts.iter().enumerate() {
                let u: [f32; 8] = std::array::from_fn(|j| ts[(k + j) % ts.len()]);
                // Every other lane dead: it reads as 0 and leaves the others alone.
                let live: [bool; 8] = std::array::from_fn(|j| j % 2 == 0);
                let lanes = t.sample_lanes(u, [v; 8], live);
                for j in 0..8 {
                    let one = if live[j] { t.sample(u[j], v) } else { [0.0; 3] };
                    assert_eq!(
                        lanes[j].map(f32::to_bits),
                        one.map(f32::to_bits),
                        "options {options}, u {}, v {v}",
                        u[j]
                    );
                }
            }
        }
    }

    #[test]
    fn nearest_sampling_repeats_or_clamps() {
        let (red, green, blue, white) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0; 3]);
        let t = checker(NO_INTERPOLATION | REPEAT_U | REPEAT_V);
        // v = 0 is the bottom row.
        assert_eq!(t.sample(0.25, 0.25), blue);
        assert_eq!(t.sample(0.75, 0.25), white);
        assert_eq!(t.sample(0.25, 0.75), red);
        assert_eq!(t.sample(0.75, 0.75), green);
        // Repeating: u = 1.25 is u = 0.25, v = -0.25 is 0.75.
        assert_eq!(t.sample(1.25, -0.25), red);
        // Clamped: beyond the edges, the edge texels.
        let t = checker(NO_INTERPOLATION);
        assert_eq!(t.sample(1.25, -0.25), white);
        assert_eq!(t.sample(-3.0, 7.0), red);
        assert_eq!(t.sample(f32::NAN, 0.25), blue);
    }

    #[test]
    fn bilinear_sampling_blends_neighbours() {
        let t = checker(0);
        // At a texel centre, the texel; halfway between blue and white, their mean.
        assert_eq!(t.sample(0.25, 0.25), [0.0, 0.0, 1.0]);
        let mid = t.sample(0.5, 0.25);
        assert!((mid[0] - 0.5).abs() < 1e-6 && (mid[2] - 1.0).abs() < 1e-6, "{mid:?}");
        // Clamped at the edge: the edge texel; repeating: blended with the other side.
        assert_eq!(t.sample(0.0, 0.25), [0.0, 0.0, 1.0]);
        let t = checker(REPEAT_U | REPEAT_V);
        let wrapped = t.sample(0.0, 0.25);
        assert!((wrapped[0] - 0.5).abs() < 1e-6, "{wrapped:?}");
    }

    #[test]
    fn a_plane_mapping_centres_the_texture_on_the_frame() {
        let t = checker(0);
        // The box's top face: corners at +-0.5 m map to 0 and 1.
        let mut seen = Vec::new();
        for uv in &t.uvs {
            for c in uv {
                assert!([0.0, 1.0].contains(&c[0]) && [0.0, 1.0].contains(&c[1]), "{c:?}");
                seen.push(*c);
            }
        }
        assert!(seen.contains(&[0.0, 0.0]) && seen.contains(&[1.0, 1.0]));
    }

    #[test]
    fn explicit_coordinates_follow_the_data_triangles() {
        let data = crate::scene::MeshData {
            source: "test".into(),
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            // The second triangle is degenerate and left out of the tessellation.
            indices: vec![[0, 0, 1], [0, 1, 2]],
            parts: Vec::new(),
        };
        let mesh = TriMesh::from_geometry(&Geometry::Mesh(Arc::new(data)));
        let coordinates: Vec<f32> = (0..12).map(|k| k as f32).collect();
        let uvs = explicit_uvs(&mesh, &coordinates);
        assert_eq!(uvs, [[[6.0, 7.0], [8.0, 9.0], [10.0, 11.0]]]);
    }

    #[test]
    fn round_mappings_do_not_wrap_backwards_across_the_seam() {
        let mesh = TriMesh::from_geometry(&Geometry::Cylinder {
            radius: 0.1,
            length: 0.2,
        });
        let worn = ShapeTexture {
            id: 0,
            mapping: TextureMapping::Cylinder,
            options: 0,
            uv_scaling: [1.0, 1.0],
            position: [0.0; 3],
            orientation: [0.0; 3],
            coordinates: None,
        };
        for uv in projected_uvs(&mesh, &Pose::identity(), &worn) {
            let us = uv.map(|c| c[0]);
            let spread = us.iter().copied().fold(f32::MIN, f32::max) - us.iter().copied().fold(f32::MAX, f32::min);
            // Side triangles span one of 32 segments; caps reach the axis (u of the
            // centre is its own angle, 0), so only the side is checked tightly.
            assert!(spread < 0.55, "{uv:?}");
        }
    }
}
