//! The CPU rasteriser: shapes' visuals → RGB and planar depth of one perspective or
//! orthographic sensor.
//!
//! Per visual, then per chunk of a few hundred triangles (see [`super::tessellate`]), a
//! bounding-sphere test against the *sampled* frustum (below) skips what no pixel can
//! show before any vertex is transformed. The vertices of a chunk that stays go to the
//! camera frame once each, with their outcode and screen position; per triangle:
//! back-face culling for closed primitives, a trivial reject/accept on the six frustum
//! planes (a box for an orthographic sensor), Sutherland–Hodgman clipping only for
//! triangles that cross one, then a half-space scan of the bounding box with depth and
//! intensity interpolated (perspective-correct, or affine in an orthographic image,
//! where they are affine) and a z-buffer. Nothing is allocated per frame once the
//! buffers have grown to the scene's size.
//!
//! # Culling never changes an image
//! A pixel is written only when its centre lies inside a triangle's projected bounding
//! box, so what lies outside the pyramid through the outermost pixel *centres* (the
//! sampled frustum, narrower than the view by half a pixel on each side; at 1 x 1
//! pixel, one ray) writes nothing. A chunk whose bounding sphere is beyond one plane of
//! that pyramid, or beyond the near or far plane, by a margin (0.05 px sideways, and a
//! relative 1e-4 for rounding) draws nothing, and skipping it leaves every byte as
//! drawing it would. The chunks that stay are drawn in the mesh's order, which the
//! z-buffer's "first of two equal depths wins" needs. A test renders random views with
//! and without culling and compares the bits.
//!
//! # Bands of rows
//! An image may be drawn in bands of whole rows, on several threads ([`draw_band`]).
//! A band culls against the pyramid through its own rows' centres and fills only its
//! rows, but clips against the whole view, so each of its pixels gets the same
//! triangles in the same order, with the same arithmetic, as when the image is drawn
//! at once: the bits do not depend on the bands.

use std::collections::BTreeMap;
use std::ops::Range;

use nalgebra::Point3;

use super::bytes::round_byte;
use super::detail;
use super::resolve::{self, Packet1};
use super::simd::multiversion;
use super::tessellate::{Normals, TriMesh, cross, dot, sub};
use super::texturing::VisualTexture;
use crate::math::Pose;
use crate::scene::{Geometry, Projection, RenderMode, VisionModel};
use crate::world::{Handle, ObjectKind, ShapeTexture, Texture, World, geometry_mesh, mesh_data};

/// Textured triangles: the same coverage, depth and light as the plain path
/// ([`super::fill`]), with u and v interpolated perspective-correctly (u/z and v/z are
/// affine on screen, as 1/z is) and the texture sampled per pixel. Only images with
/// colours take this path (a depth-only, colour-coded or mask render draws textured
/// shapes as plain ones).
///
/// Rows are drawn in chunks of [`CHUNK`] pixels as the plain path draws them: depth,
/// light and texture coordinates for the whole chunk in array code (vector code in the
/// AVX2 copy), then the depth test, and the texture read and the writes only for the
/// pixels that pass. A textured table can fill most of a camera's view (RLBench's
/// shoulder cameras), so this loop's speed is a large share of a frame's.
///
/// Kept in this file rather than its own: it draws with this file's clipping,
/// projection and span helpers, and a file of its own would import from this one while
/// this one calls it (a circle `tools/layers.py` refuses).
mod textured {
    use crate::vision::raster::{
        CHUNK, CamVertex, Camera, ChunkVertex, ClipVertex, MAX_POLY, ScreenVertex, Target, VisualTexture, clip,
        covered_spans, edge, project, round_byte,
    };
    use crate::vision::simd::multiversion;

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

    multiversion! {
        /// Fills one textured triangle inside the frustum, as [`super::fill`] fills a
        /// plain one.
        fn fill(
            cam: &Camera,
            target: &mut Target<'_>,
            tri: [TexScreen; 3],
            texture: &VisualTexture,
            base: [f32; 3],
            id: u32,
        ) {
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
            for (row, first, end, e) in covered_spans(w, height, rows, [a.s, b.s, c.s]) {
                let start = (row - target.rows.start) * w;
                let ((iz0, diz), (lz0, dlz)) = (iz(e), lz(e));
                let ((uz0, duz), (vz0, dvz)) = (uz(e), vz(e));
                let mut col0 = first - first % CHUNK;
                while col0 < end {
                    // Depth, light and texture coordinates of the chunk's pixels: the
                    // depth exactly as the plain path computes it, so the z-buffer
                    // orders textured and plain triangles alike.
                    let mut x = [0.0; CHUNK];
                    for (k, x) in x.iter_mut().enumerate() {
                        *x = (col0 + k) as f32;
                    }
                    let (mut z, mut light, mut u, mut v) = ([0.0; CHUNK], [0.0; CHUNK], [0.0; CHUNK], [0.0; CHUNK]);
                    if ortho {
                        for k in 0..CHUNK {
                            (z[k], light[k]) = (iz0 + diz * x[k], lz0 + dlz * x[k]);
                            (u[k], v[k]) = (uz0 + duz * x[k], vz0 + dvz * x[k]);
                        }
                    } else {
                        for k in 0..CHUNK {
                            z[k] = 1.0 / (iz0 + diz * x[k]);
                            light[k] = (lz0 + dlz * x[k]) * z[k];
                            (u[k], v[k]) = ((uz0 + duz * x[k]) * z[k], (vz0 + dvz * x[k]) * z[k]);
                        }
                    }
                    // Covered and closer than what is drawn (a NaN depth never is), as
                    // the plain path tests; the chunk never reaches past the span.
                    let mut live = [false; CHUNK];
                    let mut any = false;
                    for k in 0..CHUNK {
                        let col = col0 + k;
                        let closer = target.zbuf.get(start + col).is_some_and(|&zp| z[k] < zp);
                        live[k] = first <= col && col < end && closer;
                        any |= live[k];
                    }
                    if any {
                        let texels = texture.sample_lanes(u, v, live);
                        for k in 0..CHUNK {
                            let i = start + col0 + k;
                            if !live[k] {
                                continue;
                            }
                            if let Some(zp) = target.zbuf.get_mut(i) {
                                *zp = z[k];
                            }
                            let byte = |j: usize| u32::from(round_byte(base[j] * texels[k][j] * light[k]));
                            if let Some(cp) = target.color.get_mut(i) {
                                *cp = byte(0) | byte(1) << 8 | byte(2) << 16;
                            }
                            if with_ids && let Some(ip) = target.ids.get_mut(i) {
                                *ip = id;
                            }
                        }
                    }
                    col0 += CHUNK;
                }
            }
        }
    }
}

/// Share of an object's colour it shows with no light on it.
pub(crate) const AMBIENT: f32 = 0.3;
/// Weight of the headlight: a directional light along the sensor's viewing axis (+Z),
/// lighting surfaces by `|cos|` of the angle between their normal and that axis.
pub(crate) const HEADLIGHT: f32 = 0.45;
/// Weight of a directional light straight down the world's -Z axis, so that floors,
/// which the headlight grazes, are still lit.
pub(crate) const TOPLIGHT: f32 = 0.35;
/// Colour of pixels that see nothing between the clipping planes (RGB, 0..1) when
/// neither the sensor nor the scene sets one ([`Camera::background`]).
pub(crate) const BACKGROUND: [f32; 3] = [0.0, 0.0, 0.0];
/// Colour of pixels that see nothing in a colour-coded image: white, as CoppeliaSim
/// clears it, which no handle below 2^24 - 1 can be mistaken for.
const CODED_BACKGROUND: u32 = 0x00ff_ffff;
/// The id buffer's value where no shape is seen: -1 as an `i32` handle.
const NO_SHAPE: u32 = u32::MAX;

/// A camera derived from a [`VisionModel`], in the sensor frame: looking along +Z,
/// image up = +Y, image right = -X (CoppeliaSim's convention).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Camera {
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// Orthographic (parallel rays along +Z) rather than perspective.
    pub ortho: bool,
    /// Horizontal half extent of the view: perspective, the tangent of the half angle
    /// (the half width at 1 m); orthographic, the half width in metres.
    pub tan_x: f32,
    /// Vertical half extent of the view, as `tan_x`.
    pub tan_y: f32,
    /// Where the bottom and top frustum planes are, as `tan_x` but signed: `-tan_y`
    /// and `tan_y` for the whole image; a band of rows culls against its own
    /// ([`Camera::sampled`]).
    y_lo: f32,
    y_hi: f32,
    /// Near clipping distance along +Z, metres.
    pub near: f32,
    /// Far clipping distance along +Z, metres.
    pub far: f32,
    /// What the colour buffer holds: the lit colours, handles, or nothing.
    pub colour: ColourWork,
    /// Whether the normalised depth image is written.
    pub depth: bool,
    /// What a shaded image shows where nothing is seen, packed as [`pack`] does: the
    /// sensor's colour, else the scene's ([`Camera::with_scene_background`]), else
    /// [`BACKGROUND`].
    pub background: u32,
}

/// What a render does with colour (from the model's render mode and `ignore_rgb`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ColourWork {
    /// Lit shape colours.
    Shaded,
    /// Each pixel the handle of the shape seen, white where none
    /// ([`RenderMode::ColorCoded`]).
    Coded,
    /// None: the RGB image is left as it was (`ignore_rgb`).
    Skipped,
}

impl Camera {
    /// The camera of a sensor model, or `None` when the model is out of range
    /// (resolution 1..=`max_side`, 0 < fov < pi for a perspective sensor, ortho size
    /// > 0 for an orthographic one, 0 < near < far, all finite).
    pub fn new(m: &VisionModel, max_side: u32) -> Option<Camera> {
        let [w, h] = m.resolution;
        let ortho = m.projection == Projection::Orthographic;
        let extent_ok = if ortho {
            m.ortho_size.is_finite() && m.ortho_size > 0.0
        } else {
            m.fov.is_finite() && m.fov > 0.0 && m.fov < std::f64::consts::PI
        };
        let valid = (1..=max_side).contains(&w)
            && (1..=max_side).contains(&h)
            && extent_ok
            && m.near.is_finite()
            && m.far.is_finite()
            && m.near > 0.0
            && m.far > m.near;
        if !valid {
            return None;
        }
        // The field of view (or ortho size) spans the larger side; the other follows
        // from the aspect.
        let t = if ortho { m.ortho_size / 2.0 } else { (m.fov / 2.0).tan() };
        let (tx, ty) = if w >= h {
            (t, t * f64::from(h) / f64::from(w))
        } else {
            (t * f64::from(w) / f64::from(h), t)
        };
        let colour = match m.render_mode {
            // Handles need no light, and CoppeliaSim's "ignore RGB" does not apply to
            // them (a mask sensor is read through its RGB image).
            RenderMode::ColorCoded => ColourWork::Coded,
            RenderMode::Visible if m.ignore_rgb => ColourWork::Skipped,
            RenderMode::Visible => ColourWork::Shaded,
        };
        Some(Camera {
            width: w as usize,
            height: h as usize,
            ortho,
            tan_x: tx as f32,
            tan_y: ty as f32,
            y_lo: -ty as f32,
            y_hi: ty as f32,
            near: m.near as f32,
            far: m.far as f32,
            colour,
            depth: !m.ignore_depth,
            background: pack_colour(m.background.map_or(BACKGROUND, |c| c.map(|v| v as f32))),
        })
    }

    /// The camera with the scene's background where its sensor sets none (`None`:
    /// black).
    pub fn with_scene_background(self, m: &VisionModel, scene: Option<[f64; 3]>) -> Camera {
        match (m.background, scene) {
            (None, Some(c)) => Camera {
                background: pack_colour(c.map(|v| v as f32)),
                ..self
            },
            _ => self,
        }
    }

    /// Signed distance-like value of `p` to frustum plane `k` (>= 0 inside):
    /// near, far, right (-X), left (+X), top (+Y), bottom (-Y). An orthographic
    /// view's side planes are parallel to +Z, at the half extents.
    fn plane(&self, k: usize, p: [f32; 3]) -> f32 {
        let [x, y, z] = p;
        // Where the side planes are at this depth.
        let depth = if self.ortho { 1.0 } else { z };
        match k {
            0 => z - self.near,
            1 => self.far - z,
            2 => self.tan_x * depth + x,
            3 => self.tan_x * depth - x,
            // For the whole image, `y_hi = tan_y` and `y_lo = -tan_y`: the same bits as
            // `tan_y * depth + y` (negation and the subtraction of a negated value are exact).
            4 => self.y_hi * depth - y,
            _ => y - self.y_lo * depth,
        }
    }

    fn outcode(&self, p: [f32; 3]) -> u8 {
        (0..6).fold(0, |acc, k| acc | (u8::from(self.plane(k, p) < 0.0) << k))
    }

    /// The pyramid (a box, orthographic) through the outermost pixel centres of the
    /// image's `rows`, widened by [`CULL_MARGIN_PX`]: nothing outside it can be drawn in
    /// those rows (see the module docs). Only for culling: triangles are clipped
    /// against the whole view, so a band of rows draws the bits the whole image would.
    fn sampled(&self, rows: &Range<usize>) -> Camera {
        // A pixel centre at screen x (pixels from the left) sees x/z = tan_x (1 - 2x/W)
        // in the sensor frame, and one at screen y (from the bottom) y/z = tan_y (2y/H
        // - 1); the outermost centres of the image are at 0.5 and W - 0.5.
        let shrink = |n: usize| 1.0 - (1.0 - 2.0 * CULL_MARGIN_PX) / n as f32;
        let y_at = |screen_y: f32| self.tan_y * (2.0 * screen_y / self.height as f32 - 1.0);
        Camera {
            tan_x: self.tan_x * shrink(self.width),
            y_lo: y_at(rows.start as f32 + 0.5 - CULL_MARGIN_PX),
            y_hi: y_at(rows.end as f32 - 0.5 + CULL_MARGIN_PX),
            ..*self
        }
    }

    /// Whether a sphere (centre in the sensor frame, radius, metres) lies wholly
    /// outside one of this camera's planes, with a margin for the rounding of the
    /// centre's transform and of the vertices' own.
    fn sphere_outside(&self, c: [f32; 3], radius: f32) -> bool {
        let slack = radius * (1.0 + 1e-4) + 1e-4 * (c[0].abs() + c[1].abs() + c[2].abs()) + 1e-6;
        (0..6).any(|k| self.plane(k, c) < -slack * plane_scale(self, k))
    }
}

/// How far beyond the outermost pixel centres culling keeps geometry, in pixels:
/// covers the fill's 1e-4 px edge tolerance and the rounding of projection.
const CULL_MARGIN_PX: f32 = 0.05;

/// One visual of one shape, tessellated, with its placement in the shape frame and its
/// colour (RGB, 0..1).
#[derive(Debug, Clone)]
pub(crate) struct CachedVisual {
    mesh: TriMesh,
    /// Coarser copies of a dense imported mesh, for views whose pixels are larger than
    /// its triangles (see [`super::detail`]).
    levels: Vec<detail::Level>,
    local: Pose,
    color: [f32; 3],
    /// The texture the visual wears, if any (drawn at full detail: its coordinates are
    /// per triangle of `mesh`).
    texture: Option<VisualTexture>,
}

/// Tessellations of every shape's visuals by shape handle. Each shape is tessellated the
/// first time a sensor renders it, and again after its geometry changes (rarely: a shape
/// scaled at run time), which [`World::geometry_revision`] tells, or the texture it
/// wears does ([`crate::world::Textures::revision`]).
#[derive(Debug, Clone, Default)]
pub(crate) struct ShapeCache {
    shapes: BTreeMap<Handle, Vec<CachedVisual>>,
    /// The world's geometry revision the tessellations were made at.
    revision: u64,
    /// The textures the cached shapes wore when tessellated, and the world's texture
    /// revision then.
    worn: BTreeMap<Handle, ShapeTexture>,
    texture_revision: u64,
}

impl ShapeCache {
    /// Tessellates the shapes not seen before, all of them after a geometry change, and
    /// those whose texture changed.
    pub fn refresh(&mut self, world: &World) {
        if world.geometry_revision() != self.revision {
            self.shapes.clear();
            self.revision = world.geometry_revision();
        }
        if world.textures().revision() != self.texture_revision {
            self.texture_revision = world.textures().revision();
            let worn = &self.worn;
            self.shapes
                .retain(|&h, _| world.shape_texture(h).ok().flatten() == worn.get(&h));
        }
        for &h in world.handles() {
            if self.shapes.contains_key(&h) {
                continue;
            }
            if let Ok(o) = world.object(h)
                && let ObjectKind::Shape(s) = &o.kind
            {
                let worn = world.shape_texture(h).ok().flatten();
                let visuals = match worn.and_then(|t| Some((t, world.textures().get(t.id).ok()?))) {
                    Some((worn, texture)) => textured_visuals(s, worn, texture),
                    None => s
                        .visuals
                        .iter()
                        .map(|v| {
                            let mesh = TriMesh::from_geometry(&v.geometry);
                            CachedVisual {
                                levels: detail::levels(&v.geometry, &mesh),
                                mesh,
                                local: v.local,
                                color: clamp_colour(v.color),
                                texture: None,
                            }
                        })
                        .collect(),
                };
                self.shapes.insert(h, visuals);
                match worn {
                    Some(t) => self.worn.insert(h, t.clone()),
                    None => self.worn.remove(&h),
                };
            }
        }
    }
}

/// A visual's colour with each channel in 0..1 (0 for a non-finite one).
fn clamp_colour(c: [f32; 3]) -> [f32; 3] {
    c.map(|c| if c.is_finite() { c.clamp(0.0, 1.0) } else { 0.0 })
}

/// The visuals of shape `s`, which wears `texture` as `worn`. Explicit coordinates
/// count per triangle of `sim.getShapeMesh` (the visuals' meshes one after the other,
/// primitives as [`geometry_mesh`] tessellates them), so a primitive wearing them is
/// drawn as that mesh; coordinates that do not cover a visual's triangles leave the
/// rest at 0.
pub(crate) fn textured_visuals(
    s: &crate::scene::ShapeModel,
    worn: &ShapeTexture,
    texture: &Texture,
) -> Vec<CachedVisual> {
    let mut first = 0usize;
    s.visuals
        .iter()
        .map(|v| {
            let explicit = worn.coordinates.as_deref().map(|c| c.get(6 * first..).unwrap_or(&[]));
            let (mesh, count) = match &v.geometry {
                Geometry::Mesh(data) => (TriMesh::from_geometry(&v.geometry), data.indices.len()),
                primitive if explicit.is_some() => {
                    let m = geometry_mesh(primitive);
                    let count = m.indices.len();
                    (
                        TriMesh::from_geometry(&Geometry::Mesh(mesh_data(&m, "textured primitive"))),
                        count,
                    )
                }
                primitive => (TriMesh::from_geometry(primitive), 0),
            };
            first += count;
            let texture = VisualTexture::new(texture, worn, &mesh, &v.local, explicit);
            CachedVisual {
                levels: Vec::new(),
                mesh,
                local: v.local,
                color: clamp_colour(v.color),
                texture: Some(texture),
            }
        })
        .collect()
}

impl CachedVisual {
    /// The tessellation and, when the visual wears one, its texture.
    pub(crate) fn parts(&self) -> (&TriMesh, Option<&VisualTexture>) {
        (&self.mesh, self.texture.as_ref())
    }
}

/// A vertex in the camera frame with its light intensity.
#[derive(Debug, Clone, Copy, Default)]
struct CamVertex {
    p: [f32; 3],
    light: f32,
}

/// A polygon corner [`clip`] can cut: a position in the camera frame, and values
/// interpolated along its edges with it.
trait ClipVertex: Copy + Default {
    fn position(&self) -> [f32; 3];
    /// The point at `t` along `a`..`b`, its values interpolated likewise.
    fn lerp(a: Self, b: Self, t: f32) -> Self;
}

impl ClipVertex for CamVertex {
    #[inline]
    fn position(&self) -> [f32; 3] {
        self.p
    }

    #[inline]
    fn lerp(a: CamVertex, b: CamVertex, t: f32) -> CamVertex {
        CamVertex {
            p: [
                a.p[0] + (b.p[0] - a.p[0]) * t,
                a.p[1] + (b.p[1] - a.p[1]) * t,
                a.p[2] + (b.p[2] - a.p[2]) * t,
            ],
            light: a.light + (b.light - a.light) * t,
        }
    }
}

/// A chunk's vertex, ready for its triangles: in the camera frame (with its light for
/// Gouraud-shaded meshes), its outcode, and its screen position when it is in front
/// of the near plane.
#[derive(Debug, Clone, Copy, Default)]
struct ChunkVertex {
    cam: CamVertex,
    code: u8,
    /// Screen x, y (pixels) and 1/z (z, orthographic), as [`project`] gives them.
    screen: [f32; 3],
}

/// One drawing thread's buffers, reused from frame to frame.
#[derive(Debug, Clone, Default)]
pub(crate) struct Scratch {
    vertices: Vec<ChunkVertex>,
    /// What the last band this thread drew culled and drew.
    pub stats: RenderStats,
}

/// The buffers one frame is drawn into, reused from frame to frame. One set per sensor
/// being drawn, so that bands of rows of one image can be drawn on several threads.
#[derive(Debug, Clone, Default)]
pub(crate) struct FrameBuffers {
    /// Planar depth in metres per pixel, `INFINITY` where nothing was drawn.
    zbuf: Vec<f32>,
    /// Colour per pixel as `0x00BBGGRR`: one word per pixel lets the fill loop blend
    /// whole words, which the compiler vectorises; packed to RGB bytes at the end.
    /// Both buffers carry `CHUNK - 1` pixels of padding after the image.
    color: Vec<u32>,
    /// Handle of the shape seen per pixel ([`NO_SHAPE`] where none), when a mask or a
    /// colour-coded image is drawn; padded as the others.
    ids: Vec<u32>,
}

/// Rows `rows` of a frame's buffers (each slice starts at the band's first row): what
/// one thread draws. Only the image's last band holds the buffers' padding.
pub(crate) struct Band<'a> {
    rows: Range<usize>,
    zbuf: &'a mut [f32],
    color: &'a mut [u32],
    ids: &'a mut [u32],
}

impl FrameBuffers {
    /// Copies of the depth buffer and, when it was drawn, the id buffer of the frame
    /// just drawn (`pixels` of each, without padding).
    pub fn copy_depth_ids(&self, pixels: usize, zbuf: &mut Vec<f32>, ids: &mut Vec<u32>) {
        zbuf.extend_from_slice(&self.zbuf[..pixels.min(self.zbuf.len())]);
        if self.ids.len() >= pixels {
            ids.extend_from_slice(&self.ids[..pixels]);
        }
    }

    /// The buffers a colour-coded frame of `cam` leaves, from another frame's depth and
    /// ids ([`FrameBuffers::copy_depth_ids`]) of the same size.
    pub fn load_depth_ids(&mut self, cam: &Camera, zbuf: &[f32], ids: &[u32]) {
        let n = cam.width * cam.height;
        self.zbuf.clear();
        self.zbuf.extend_from_slice(&zbuf[..n.min(zbuf.len())]);
        self.zbuf.resize(n + CHUNK - 1, f32::INFINITY);
        self.color.clear();
        self.ids.clear();
        self.ids.extend_from_slice(&ids[..n.min(ids.len())]);
        self.ids.resize(n + CHUNK - 1, NO_SHAPE);
    }

    /// Clears the buffers for a frame of `cam` (with the id buffer when `mask` is
    /// drawn) and cuts them into `bands` bands of whole rows (at least one, at most
    /// one per row; rows shared out evenly, bottom first).
    pub fn bands(&mut self, cam: &Camera, mask: bool, bands: usize) -> Vec<Band<'_>> {
        let n = cam.width * cam.height;
        // CHUNK - 1 pixels of padding, which the last chunk of the last row may cover.
        self.zbuf.clear();
        self.zbuf.resize(n + CHUNK - 1, f32::INFINITY);
        self.color.clear();
        if cam.colour == ColourWork::Shaded {
            self.color.resize(n + CHUNK - 1, cam.background);
        }
        self.ids.clear();
        if with_ids(cam, mask) {
            self.ids.resize(n + CHUNK - 1, NO_SHAPE);
        }
        let count = bands.clamp(1, cam.height);
        let rows: Vec<Range<usize>> = (0..count)
            .map(|k| k * cam.height / count..(k + 1) * cam.height / count)
            .collect();
        let (mut zbuf, mut color, mut ids) = (&mut self.zbuf[..], &mut self.color[..], &mut self.ids[..]);
        let mut out = Vec::with_capacity(count);
        for (k, r) in rows.into_iter().enumerate() {
            // The band's pixels; the last band takes the rest, padding included.
            let len = if k + 1 == count {
                usize::MAX
            } else {
                r.len() * cam.width
            };
            let z;
            (z, zbuf) = zbuf.split_at_mut(len.min(zbuf.len()));
            let c;
            (c, color) = color.split_at_mut(len.min(color.len()));
            let i;
            (i, ids) = ids.split_at_mut(len.min(ids.len()));
            out.push(Band {
                rows: r,
                zbuf: z,
                color: c,
                ids: i,
            });
        }
        out
    }
}

/// Whether a frame of `cam` draws the id buffer: for a mask, or as the colour-coded
/// image.
fn with_ids(cam: &Camera, mask: bool) -> bool {
    cam.colour == ColourWork::Coded || mask
}

/// Counts of one frame, for tests (that culling is exercised) and profiling.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct RenderStats {
    /// Chunks skipped by the sphere test, with those of whole visuals skipped.
    pub culled_chunks: usize,
    /// Chunks whose vertices were transformed.
    pub drawn_chunks: usize,
    /// Visuals drawn at a coarser level.
    pub coarse_visuals: usize,
    /// Triangles skipped as back faces.
    pub back_faces: usize,
}

/// Where a frame goes: `rgb` (3 bytes per pixel), `depth` (normalised) and, when
/// asked for, `mask` (the handle of the shape seen, -1 where none), all bottom row
/// first, sized `width * height` pixels. What the camera skips (its `colour` and
/// `depth`) is left as it was.
pub(crate) struct Frame<'a> {
    pub rgb: &'a mut [u8],
    pub depth: &'a mut [f32],
    pub mask: Option<&'a mut [i32]>,
}

/// A polygon after clipping a triangle against up to six planes has at most 9 corners.
const MAX_POLY: usize = 12;

/// One visual to draw: where it is in the world, and its tessellation.
#[derive(Debug, Clone, Copy)]
pub(crate) struct DrawItem<'a> {
    /// The shape the visual belongs to: what a mask shows.
    pub handle: Handle,
    /// The visual's world pose.
    pub pose: Pose,
    pub visual: &'a CachedVisual,
}

/// What every sensor of a step sees: the visuals of every shape with their world
/// poses, in the world's handle order (the drawing order). Borrowing neither the world
/// nor anything but the shape cache, it can be shared by threads rendering sensors.
pub(crate) fn draw_list<'a>(world: &World, shapes: &'a ShapeCache) -> Vec<DrawItem<'a>> {
    let mut items = Vec::new();
    for &h in world.handles() {
        let (Some(visuals), Ok(object)) = (shapes.shapes.get(&h), world.object(h)) else {
            continue;
        };
        // Objects on hidden layers (a model's respondable shapes under its visual
        // meshes) are not drawn, as in CoppeliaSim.
        if !world.is_shown(h) {
            continue;
        }
        for v in visuals {
            if !v.mesh.triangles.is_empty() {
                items.push(DrawItem {
                    handle: h,
                    pose: object.world * v.local,
                    visual: v,
                });
            }
        }
    }
    items
}

/// How much [`draw_band`] may skip: `cull` false draws every chunk (for the test that
/// culling changes nothing), `coarse` false always draws the full meshes (for the test
/// that coarser levels stay within their error).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Shortcuts {
    pub cull: bool,
    pub coarse: bool,
    /// Skip the back faces of imported meshes' closed parts (false: for the test that
    /// this changes no pixel away from silhouettes).
    pub mesh_back_faces: bool,
}

/// Draws the rows of `band` of the frame `items` make as seen from `sensor` (the
/// sensor's world pose). Each pixel gets the bits it gets when the whole image is drawn
/// at once: triangles are clipped against the whole view, and the band only culls and
/// limits the rows filled.
pub(crate) fn draw_band(
    items: &[DrawItem<'_>],
    cam: &Camera,
    sensor: &Pose,
    scratch: &mut Scratch,
    band: Band<'_>,
    shortcuts: Shortcuts,
) {
    let cam_from_world = sensor.inverse();
    let sampled = shortcuts.cull.then(|| cam.sampled(&band.rows));
    let mut target = Target {
        width: cam.width,
        height: cam.height,
        shaded: !band.color.is_empty(),
        with_ids: !band.ids.is_empty(),
        rows: band.rows,
        zbuf: band.zbuf,
        color: band.color,
        ids: band.ids,
    };
    scratch.stats = RenderStats::default();
    // Front to back: each visual ordered by the depth of the far side of its bounding
    // sphere, so that what is near (and small) is drawn first and the pixels of what
    // lies behind it fail the depth test before any shading or texture read; large
    // backgrounds (floors, walls, tables) come last. The z-buffer makes the image the
    // same in any order, except where two surfaces have exactly the same depth, and a
    // stable sort on the same poses gives the same order every time.
    let mut order: Vec<(f32, usize)> = items
        .iter()
        .enumerate()
        .map(|(k, item)| {
            let c = item.visual.mesh.center;
            let at = (cam_from_world * item.pose).transform_point(&Point3::new(c[0].into(), c[1].into(), c[2].into()));
            (at.z as f32 + item.visual.mesh.radius, k)
        })
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0));
    for item in order.iter().map(|&(_, k)| &items[k]) {
        draw_visual(
            cam,
            sampled.as_ref(),
            shortcuts,
            &cam_from_world,
            item,
            &mut scratch.vertices,
            &mut target,
            &mut scratch.stats,
        );
    }
}

/// The last pass of a frame whose bands are all drawn: the mask, the colour-coded
/// colours and the sensor image with its packet 1 ([`resolve::resolve`]).
pub(crate) fn finish(cam: &Camera, buffers: &mut FrameBuffers, frame: Frame<'_>) -> Packet1 {
    let n = cam.width * cam.height;
    let ids = &buffers.ids[..if with_ids(cam, frame.mask.is_some()) { n } else { 0 }];
    if let Some(mask) = frame.mask {
        for (m, &id) in mask.iter_mut().zip(ids) {
            // NO_SHAPE is -1; handles are below 2^31.
            *m = id as i32;
        }
    }
    let colour = match cam.colour {
        ColourWork::Shaded => Some(&buffers.color[..n]),
        ColourWork::Coded => {
            buffers.color.clear();
            buffers.color.extend(ids.iter().map(|&id| {
                if id == NO_SHAPE {
                    CODED_BACKGROUND
                } else {
                    id & CODED_BACKGROUND
                }
            }));
            Some(&buffers.color[..n])
        }
        ColourWork::Skipped => None,
    };
    resolve::resolve(
        colour,
        &buffers.zbuf[..n],
        cam.near,
        cam.far,
        frame.rgb,
        cam.depth.then_some(frame.depth),
    )
}

/// An RGB colour (0..1, clamped) as one `0x00BBGGRR` word.
fn pack_colour(c: [f32; 3]) -> u32 {
    pack(c.map(|v| to_byte(v.clamp(0.0, 1.0))))
}

/// `[r, g, b]` bytes as one `0x00BBGGRR` word.
fn pack([r, g, b]: [u8; 3]) -> u32 {
    u32::from(r) | u32::from(g) << 8 | u32::from(b) << 16
}

/// The buffers triangles are drawn into, and which of them are (`zbuf` always): rows
/// `rows` of an image `width` x `height`, each buffer starting at the first of them.
struct Target<'a> {
    width: usize,
    height: usize,
    rows: Range<usize>,
    zbuf: &'a mut [f32],
    color: &'a mut [u32],
    ids: &'a mut [u32],
    shaded: bool,
    with_ids: bool,
}

fn rows(p: &Pose) -> ([[f32; 3]; 3], [f32; 3]) {
    let r = p.rotation.to_rotation_matrix();
    let m = r.matrix();
    let t = p.translation.vector;
    let row = |i: usize| [m[(i, 0)] as f32, m[(i, 1)] as f32, m[(i, 2)] as f32];
    ([row(0), row(1), row(2)], [t.x as f32, t.y as f32, t.z as f32])
}

multiversion! {
    /// Draws one visual. `sampled`: the frustum to cull chunks against (`None`: cull
    /// nothing, beyond what the per-triangle outcodes reject). `shortcuts`: whether a dense
    /// mesh may be drawn at a coarser level where this view's pixels allow
    /// ([`detail::pick`]), and whether the back faces of an imported mesh's closed parts
    /// may be skipped.
    #[expect(
        clippy::too_many_arguments,
        reason = "the frame's shared state, passed rather than bundled per call"
    )]
    fn draw_visual(
        cam: &Camera,
        sampled: Option<&Camera>,
        shortcuts: Shortcuts,
        cam_from_world: &Pose,
        item: &DrawItem<'_>,
        vertices: &mut Vec<ChunkVertex>,
        target: &mut Target<'_>,
        stats: &mut RenderStats,
    ) {
        let (world_pose, v) = (&item.pose, item.visual);
        let (r, t) = rows(&(cam_from_world * world_pose));
        let xf = |p: [f32; 3]| [dot(r[0], p) + t[0], dot(r[1], p) + t[1], dot(r[2], p) + t[2]];
        let mut mesh = &v.mesh;
        let center = xf(mesh.center);
        if let Some(s) = sampled
            && s.sphere_outside(center, mesh.radius)
        {
            stats.culled_chunks += mesh.chunks.len();
            return;
        }
        if shortcuts.coarse && !v.levels.is_empty() {
            // A pixel's side (metres) at the visual's nearest point in view.
            let per_pixel = (2.0 * cam.tan_x / cam.width as f32).min(2.0 * cam.tan_y / cam.height as f32);
            let footprint = if cam.ortho {
                per_pixel
            } else {
                per_pixel * (center[2] - mesh.radius).max(cam.near)
            };
            if let Some(level) = detail::pick(&v.levels, footprint) {
                mesh = &level.mesh;
                stats.coarse_visuals += 1;
            }
        }
        // Light directions in the visual's frame: the camera's Z axis (row 2 of the
        // camera-from-visual rotation) and the world's Z axis.
        let head = r[2];
        let up = rows(world_pose).0[2];
        let light = |n: [f32; 3]| (AMBIENT + HEADLIGHT * dot(head, n).abs() + TOPLIGHT * dot(up, n).max(0.0)).min(1.0);
        let color = v.color.map(|c| c * 255.0);
        // Textures only change colours: images without them take the plain path.
        let texture = v.texture.as_ref().filter(|_| target.shaded);
        // Handles are never negative.
        let id = item.handle as u32;
        let (vertex_normals, face_normals) = match &mesh.normals {
            Normals::Vertex(n) => (Some(n.as_slice()), None),
            Normals::Face(n) => (None, Some(n.as_slice())),
        };
        // The closed parts of an imported mesh hide their back faces only when the eye is
        // outside them and the near plane cuts none of them open: so only when the whole
        // visual lies beyond the near plane (a primitive's back faces are always culled).
        // The full mesh's sphere holds its coarser levels too (their vertices are means of
        // its vertices).
        let beyond_near = center[2] - v.mesh.radius * (1.0 + 1e-4) > cam.near;
        for chunk in &mesh.chunks {
            if let Some(s) = sampled
                && s.sphere_outside(xf(chunk.center), chunk.radius)
            {
                stats.culled_chunks += 1;
                continue;
            }
            stats.drawn_chunks += 1;
            let cull_back = chunk.closed && (mesh.closed || (shortcuts.mesh_back_faces && beyond_near));
            // Each vertex once: camera frame, light (Gouraud), outcode, screen position.
            let first = chunk.first_vertex as usize;
            vertices.clear();
            // A plain loop rather than `extend(map(..))`: the iterator's fold stayed a
            // function of its own, compiled for the baseline only.
            for (k, &p) in mesh.chunk_positions(chunk).iter().enumerate() {
                let cam_v = CamVertex {
                    p: xf(p),
                    // Face-shaded meshes set the light per triangle below.
                    light: vertex_normals.and_then(|n| n.get(first + k)).map_or(0.0, |&n| light(n)),
                };
                let code = cam.outcode(cam_v.p);
                // Only read for triangles wholly inside, whose z >= near > 0.
                let s = project(cam, cam_v);
                vertices.push(ChunkVertex {
                    cam: cam_v,
                    code,
                    screen: [s.x, s.y, s.inv_z],
                });
            }
            let faces = face_normals.and_then(|n| n.get(chunk.first_triangle as usize..chunk.end_triangle as usize));
            for (k, tri) in mesh.chunk_triangles(chunk).iter().enumerate() {
                let Some([mut a, mut b, mut c]) = fetch(vertices, *tri) else {
                    continue;
                };
                let (oa, ob, oc) = (a.code, b.code, c.code);
                // Skipped: wholly outside one plane, or wholly inside and covering no
                // pixel centre (most triangles of a vendor mesh in a small image), where
                // `fill` would draw nothing (the same test as its bounding box, on the same
                // values). One branch for all of it: separate ones were mispredicted often
                // enough to be a third of a frame.
                let [xa, ya, _] = a.screen;
                let [xb, yb, _] = b.screen;
                let [xc, yc, _] = c.screen;
                let covers = may_cover(min3(xa, xb, xc), max3(xa, xb, xc), 0..target.width)
                    & may_cover(min3(ya, yb, yc), max3(ya, yb, yc), target.rows.clone());
                if (oa & ob & oc != 0) | ((oa | ob | oc == 0) & !covers) {
                    continue;
                }
                // Flat shading: the face's light at all three corners.
                if let Some(&n) = faces.and_then(|f| f.get(k)) {
                    let l = light(n);
                    (a.cam.light, b.cam.light, c.cam.light) = (l, l, l);
                }
                if cull_back {
                    // Outward normal pointing away from the camera: a back face. The view
                    // ray runs from the eye at the origin, or along +Z in an orthographic
                    // view.
                    let n = cross(sub(b.cam.p, a.cam.p), sub(c.cam.p, a.cam.p));
                    let ray = if cam.ortho { [0.0, 0.0, 1.0] } else { a.cam.p };
                    if dot(n, ray) >= 0.0 {
                        stats.back_faces += 1;
                        continue;
                    }
                }
                if let Some(t) = texture
                    && let Some(&uv) = t.uvs.get(chunk.first_triangle as usize + k)
                {
                    textured::triangle(cam, target, [a, b, c], uv, t, color, id);
                    continue;
                }
                if oa | ob | oc == 0 {
                    fill(cam, target, [a, b, c].map(|v| screen(cam, v)), color, id);
                    continue;
                }
                let mut poly = [CamVertex::default(); MAX_POLY];
                poly[..3].copy_from_slice(&[a.cam, b.cam, c.cam]);
                let n = clip(cam, &mut poly, 3, oa | ob | oc);
                for k in 1..n.saturating_sub(1) {
                    fill(
                        cam,
                        target,
                        [poly[0], poly[k], poly[k + 1]].map(|v| project(cam, v)),
                        color,
                        id,
                    );
                }
            }
        }
    }
}

/// The least of three numbers, as one `minss` each (`f32::min` also orders NaNs, in
/// several more instructions, on a path where a NaN makes any answer right: see
/// [`may_cover`]).
#[inline(always)]
fn min3(a: f32, b: f32, c: f32) -> f32 {
    let ab = if a < b { a } else { b };
    if ab < c { ab } else { c }
}

/// The greatest of three numbers, as [`min3`].
#[inline(always)]
fn max3(a: f32, b: f32, c: f32) -> f32 {
    let ab = if a > b { a } else { b };
    if ab > c { ab } else { c }
}

/// Whether `fill`'s span of pixel centres `k + 0.5` (`k` in `range`, not empty)
/// between `lo` and `hi` (pixels) is not empty: `ceil(max(lo - 0.5, start)) <=
/// floor(min(hi - 0.5, end - 1))` with `hi - 0.5 >= start`, computed without branches
/// and with casts (`ceil` and `floor` are library calls on baseline x86-64; the
/// truncation of a non-negative number is its floor, and an integer at least `a` is at
/// least `ceil(a)`). Any answer is right for a triangle with a NaN coordinate: its area
/// is NaN, and `fill` draws nothing.
#[inline(always)]
fn may_cover(lo: f32, hi: f32, range: Range<usize>) -> bool {
    let start = range.start as f32;
    let a = (lo - 0.5).max(start);
    let b = (hi - 0.5).min((range.end - 1) as f32);
    (hi - 0.5 >= start) & (b as i32 as f32 >= a)
}

/// A chunk vertex's screen vertex, exactly as [`project`] computes it from the camera
/// vertex (the position part was computed once per vertex; light/z is the light times
/// the stored 1/z).
#[inline]
fn screen(cam: &Camera, v: ChunkVertex) -> ScreenVertex {
    let [x, y, inv_z] = v.screen;
    ScreenVertex {
        x,
        y,
        inv_z,
        light_z: if cam.ortho { v.cam.light } else { v.cam.light * inv_z },
    }
}

/// The norm of plane `k`'s normal, so a bounding sphere's radius compares with
/// [`Camera::plane`]'s unnormalised value.
fn plane_scale(cam: &Camera, k: usize) -> f32 {
    match k {
        _ if cam.ortho => 1.0,
        0 | 1 => 1.0,
        2 | 3 => (1.0 + cam.tan_x * cam.tan_x).sqrt(),
        4 => (1.0 + cam.y_hi * cam.y_hi).sqrt(),
        _ => (1.0 + cam.y_lo * cam.y_lo).sqrt(),
    }
}

fn fetch(v: &[ChunkVertex], [a, b, c]: [u32; 3]) -> Option<[ChunkVertex; 3]> {
    Some([*v.get(a as usize)?, *v.get(b as usize)?, *v.get(c as usize)?])
}

/// Clips the convex polygon `poly[..n]` against the planes in `mask` and returns the
/// new corner count (< 3: nothing left).
fn clip<V: ClipVertex>(cam: &Camera, poly: &mut [V; MAX_POLY], mut n: usize, mask: u8) -> usize {
    let mut out = [V::default(); MAX_POLY];
    for k in (0..6).filter(|k| mask & (1 << k) != 0) {
        let mut m = 0;
        let mut push = |v: V| {
            // Each plane adds at most one corner, so 3 + 6 never exceeds MAX_POLY.
            if m < MAX_POLY {
                out[m] = v;
                m += 1;
            }
        };
        for i in 0..n {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            let (da, db) = (cam.plane(k, a.position()), cam.plane(k, b.position()));
            if da >= 0.0 {
                push(a);
            }
            if (da >= 0.0) != (db >= 0.0) {
                push(V::lerp(a, b, da / (da - db)));
            }
        }
        n = m;
        poly[..n].copy_from_slice(&out[..n]);
        if n < 3 {
            return 0;
        }
    }
    n
}

/// A vertex projected to pixel coordinates (x to the right, y up, pixel centres at
/// half-integers), with the two values interpolated over the triangle: perspective,
/// 1/z and light/z (affine on screen, which z and light are not); orthographic, z and
/// light themselves (affine on screen already).
#[derive(Clone, Copy)]
struct ScreenVertex {
    x: f32,
    y: f32,
    inv_z: f32,
    light_z: f32,
}

#[inline]
fn project(cam: &Camera, v: CamVertex) -> ScreenVertex {
    let [x, y, z] = v.p;
    if cam.ortho {
        return ScreenVertex {
            x: 0.5 * cam.width as f32 * (1.0 - x / cam.tan_x),
            y: 0.5 * cam.height as f32 * (1.0 + y / cam.tan_y),
            inv_z: z,
            light_z: v.light,
        };
    }
    let inv_z = 1.0 / z;
    ScreenVertex {
        // Image right is the sensor's -X.
        x: 0.5 * cam.width as f32 * (1.0 - x * inv_z / cam.tan_x),
        y: 0.5 * cam.height as f32 * (1.0 + y * inv_z / cam.tan_y),
        inv_z,
        light_z: v.light * inv_z,
    }
}

#[inline]
fn edge(a: ScreenVertex, b: ScreenVertex, px: f32, py: f32) -> f32 {
    (b.x - a.x) * (py - a.y) - (b.y - a.y) * (px - a.x)
}

fn to_byte(c: f32) -> u8 {
    round_byte(c * 255.0)
}

multiversion! {
    /// Fills one triangle that lies inside the frustum. `color` is RGB scaled to 0..255,
    /// `id` the handle written to the id buffer (when it is drawn).
    ///
    /// Per row, the pixels whose centres lie inside all three edges form one interval,
    /// found from the edge functions directly ([`covered_spans`]); 1/z and light/z are
    /// affine in screen space, and [`write_span`] draws the interval in vector code (eight lanes with
    /// AVX2, see [`super::simd`]).
    fn fill(cam: &Camera, target: &mut Target<'_>, tri: [ScreenVertex; 3], color: [f32; 3], id: u32) {
        let [mut a, mut b, c] = tri;
        let mut area = edge(a, b, c.x, c.y);
        if !area.is_finite() || area.abs() < 1e-12 {
            return;
        }
        if area < 0.0 {
            // Drawn two-sided: orient every triangle counter-clockwise on screen.
            std::mem::swap(&mut a, &mut b);
            area = -area;
        }
        let inv_area = 1.0 / area;
        let w = target.width;
        // Edge steps per pixel along a row, as `covered_spans` finds them.
        let steps = [(b, c), (c, a), (a, b)].map(|(p, q)| -(q.y - p.y));
        // 1/z and light/z as planes over the screen: value at pixel centre (0.5, y) of a
        // row plus a step per pixel.
        let weights = |f: fn(&ScreenVertex) -> f32| [f(&a), f(&b), f(&c)];
        let (iz, lz) = (weights(|v| v.inv_z), weights(|v| v.light_z));
        let grad = |k: [f32; 3]| (steps[0] * k[0] + steps[1] * k[1] + steps[2] * k[2]) * inv_area;
        let (diz, dlz) = (grad(iz), grad(lz));
        for (row, first, end, e) in covered_spans(w, target.height, target.rows.clone(), [a, b, c]) {
            let span = Span {
                start: (row - target.rows.start) * w,
                first,
                end,
                iz0: (e[0] * iz[0] + e[1] * iz[1] + e[2] * iz[2]) * inv_area,
                diz,
                lz0: (e[0] * lz[0] + e[1] * lz[1] + e[2] * lz[2]) * inv_area,
                dlz,
            };
            // Chosen per row rather than per pixel: each copy keeps its loop branch-free.
            let bufs = Buffers {
                zbuf: &mut *target.zbuf,
                color: &mut *target.color,
                ids: &mut *target.ids,
            };
            match (cam.ortho, target.shaded, target.with_ids) {
                (false, true, false) => write_span::<false, true, false>(bufs, &span, color, id),
                (false, true, true) => write_span::<false, true, true>(bufs, &span, color, id),
                (false, false, false) => write_span::<false, false, false>(bufs, &span, color, id),
                (false, false, true) => write_span::<false, false, true>(bufs, &span, color, id),
                (true, true, false) => write_span::<true, true, false>(bufs, &span, color, id),
                (true, true, true) => write_span::<true, true, true>(bufs, &span, color, id),
                (true, false, false) => write_span::<true, false, false>(bufs, &span, color, id),
                (true, false, true) => write_span::<true, false, true>(bufs, &span, color, id),
            }
        }
    }
}

/// The rows of `rows` (within an image `width` x `height`) where triangle `a, b, c`
/// (counter-clockwise on screen, not degenerate) covers the centres of some pixels:
/// for each, `(row, first, end, e)`, the pixels `first..end` (at least one) and `e`
/// the three edge functions (opposite a, b, c) at the centre of the row's column 0.
///
/// Plain ([`fill`]) and textured triangles both find their pixels here, so they cover
/// alike. An iterator whose `next` is inlined, rather than a function taking the row's
/// work as a closure (or an adapter such as `filter_map` taking this one's): a closure
/// is compiled as a function of its own, outside the AVX2 copy of its caller (see
/// [`super::simd`]), which made frames 20 % slower.
#[inline(always)]
fn covered_spans(width: usize, height: usize, rows: Range<usize>, [a, b, c]: [ScreenVertex; 3]) -> CoveredRows {
    // Pixels whose centre may lie inside; clipping keeps corners within the image
    // (up to rounding), and the clamps make out-of-range indices impossible.
    let span = |lo: f32, hi: f32, n: usize| {
        let first = (lo - 0.5).ceil().max(0.0) as usize;
        let end = ((hi - 0.5).floor() + 1.0).clamp(0.0, n as f32) as usize;
        (first, end)
    };
    let (x0, x1) = span(a.x.min(b.x).min(c.x), a.x.max(b.x).max(c.x), width);
    let (y0, y1) = span(a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y), height);
    // Only the band's rows, and none when the box is empty.
    let (y0, y1) = (y0.max(rows.start), y1.min(rows.end));
    let edges = [(b, c), (c, a), (a, b)];
    CoveredRows {
        rows: y0..if x0 >= x1 { y0 } else { y1 },
        columns: (x0 as f32, x1.saturating_sub(1) as f32),
        edges,
        steps: edges.map(|(p, q)| -(q.y - p.y)),
    }
}

/// The iterator [`covered_spans`] returns.
struct CoveredRows {
    /// The rows still to look at.
    rows: Range<usize>,
    /// The bounding box's first and last column.
    columns: (f32, f32),
    /// Edges (opposite a, b, c) and their steps per pixel along a row.
    edges: [(ScreenVertex, ScreenVertex); 3],
    steps: [f32; 3],
}

impl Iterator for CoveredRows {
    type Item = (usize, usize, usize, [f32; 3]);

    #[inline(always)]
    fn next(&mut self) -> Option<Self::Item> {
        let steps = self.steps;
        for row in self.rows.by_ref() {
            let py = row as f32 + 0.5;
            // Edge values at the centre of column 0, and the columns where each is >= 0.
            let e = self.edges.map(|(p, q)| edge(p, q, 0.5, py));
            // Continuous column bounds, lo <= col <= hi, within the bounding box.
            let (mut lo, mut hi) = self.columns;
            for k in 0..3 {
                // A tolerance of 1e-4 px keeps pixel centres exactly on an edge shared
                // by two triangles from being dropped by both through rounding.
                let at = -e[k] / steps[k];
                if steps[k] > 0.0 {
                    lo = lo.max(at - 1e-4);
                } else if steps[k] < 0.0 {
                    hi = hi.min(at + 1e-4);
                } else if e[k] < 0.0 {
                    hi = -1.0;
                }
            }
            // Rounded with casts (lo >= x0 >= 0 here) rather than `ceil`/`floor`, which
            // are library calls on baseline x86-64.
            // (`max` and `min` skip a NaN bound, so neither is NaN.)
            if lo > hi || hi < 0.0 {
                continue;
            }
            let first = lo as usize + usize::from((lo as usize as f32) < lo);
            let end = hi as usize + 1;
            if first < end {
                return Some((row, first, end, e));
            }
        }
        None
    }
}

/// Depth (metres) and packed colour of column `col` of `span` in colour `rgb`; `ORTHO`:
/// the span interpolates z and light themselves, not 1/z and light/z.
#[inline(always)]
fn shade<const ORTHO: bool>(span: &Span, col: i32, [cr, cg, cb]: [f32; 3]) -> (f32, u32) {
    let x = col as f32;
    let (z, light) = if ORTHO {
        (span.iz0 + span.diz * x, span.lz0 + span.dlz * x)
    } else {
        let z = 1.0 / (span.iz0 + span.diz * x);
        (z, (span.lz0 + span.dlz * x) * z)
    };
    let byte = |c: f32| u32::from(round_byte(c * light));
    (z, byte(cr) | byte(cg) << 8 | byte(cb) << 16)
}

/// Pixels per chunk in [`write_span`]: one AVX2 vector of `f32`.
const CHUNK: usize = 8;

/// The pixels of one row that a triangle covers, with 1/z and light/z along the row
/// (z and light in an orthographic view).
struct Span {
    /// Index of the row's first pixel in the buffers.
    start: usize,
    /// Covered columns: `first..end`.
    first: usize,
    end: usize,
    /// 1/z at column 0 and per column.
    iz0: f32,
    diz: f32,
    /// light/z at column 0 and per column.
    lz0: f32,
    dlz: f32,
}

/// The buffers one span is drawn into; `color` and `ids` are only touched when
/// [`write_span`]'s `COLOUR` and `IDS` say so.
struct Buffers<'a> {
    zbuf: &'a mut [f32],
    color: &'a mut [u32],
    ids: &'a mut [u32],
}

/// Draws `span` in colour `rgb` (scaled to 0..255) and with handle `id` where it is
/// closer than what the z-buffer holds. Each pixel costs a multiply-add, a division
/// (perspective-correct depth and light) and a depth test done as a bit blend: written
/// as `if closer { .. }` (or as a select) the compiler makes each store conditional,
/// lane by lane.
///
/// The row is processed in whole chunks of [`CHUNK`] pixels aligned in the row, with
/// the pixels outside the span masked out: most triangles are a few pixels wide, and a
/// loop over the span alone would spend its time in scalar remainders. So a chunk may
/// reach past the row's end into the next row, whose pixels it writes back unchanged,
/// or into the buffers' padding of `CHUNK - 1` pixels (without it, the last pixels are
/// drawn one by one).
///
/// `ORTHO`: see [`shade`]. `COLOUR`: write the colour buffer (lit colours); `IDS`:
/// write the id buffer. A depth-only sensor draws neither, and the compiler drops the
/// light arithmetic with them.
#[inline(always)]
fn write_span<const ORTHO: bool, const COLOUR: bool, const IDS: bool>(
    bufs: Buffers<'_>,
    span: &Span,
    rgb: [f32; 3],
    id: u32,
) {
    let Buffers { zbuf, color, ids } = bufs;
    // Columns fit in i32 (images are at most MAX_RESOLUTION wide) and convert to f32
    // exactly (below 2^24).
    let (first, end) = (span.first as i32, span.end as i32);
    let mut col0 = span.first - span.first % CHUNK;
    while col0 < span.end {
        let at = span.start + col0;
        let zs = zbuf.get_mut(at..).and_then(|z| z.first_chunk_mut::<CHUNK>());
        let cs = if COLOUR {
            color.get_mut(at..).and_then(|c| c.first_chunk_mut::<CHUNK>())
        } else {
            None
        };
        let is = if IDS {
            ids.get_mut(at..).and_then(|c| c.first_chunk_mut::<CHUNK>())
        } else {
            None
        };
        let Some(zs) = zs.filter(|_| (!COLOUR || cs.is_some()) && (!IDS || is.is_some())) else {
            // Buffers without the padding: the rest pixel by pixel.
            for col in col0.max(span.first)..span.end {
                let i = span.start + col;
                let (z, packed) = shade::<ORTHO>(span, col as i32, rgb);
                if let Some(zp) = zbuf.get_mut(i)
                    && z < *zp
                {
                    *zp = z;
                    if COLOUR && let Some(cp) = color.get_mut(i) {
                        *cp = packed;
                    }
                    if IDS && let Some(ip) = ids.get_mut(i) {
                        *ip = id;
                    }
                }
            }
            return;
        };
        // Computed from copies into fresh arrays, which the compiler keeps in vector
        // registers (working on `zs` and `cs` in place, it did not vectorise).
        let z_old = *zs;
        let c_old = cs.as_deref().copied().unwrap_or([0; CHUNK]);
        let i_old = is.as_deref().copied().unwrap_or([0; CHUNK]);
        let (mut z_new, mut c_new, mut i_new) = ([0.0f32; CHUNK], [0u32; CHUNK], [0u32; CHUNK]);
        for k in 0..CHUNK {
            let col = (col0 + k) as i32;
            let (z, packed) = shade::<ORTHO>(span, col, rgb);
            let inside = (first <= col) & (col < end);
            let keep_new = u32::from(inside & (z < z_old[k])).wrapping_neg();
            z_new[k] = f32::from_bits(z.to_bits() & keep_new | z_old[k].to_bits() & !keep_new);
            c_new[k] = packed & keep_new | c_old[k] & !keep_new;
            i_new[k] = id & keep_new | i_old[k] & !keep_new;
        }
        *zs = z_new;
        if let Some(cs) = cs {
            *cs = c_new;
        }
        if let Some(is) = is {
            *is = i_new;
        }
        col0 += CHUNK;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model(resolution: [u32; 2], fov: f64, near: f64, far: f64) -> VisionModel {
        VisionModel {
            resolution,
            projection: Projection::Perspective,
            fov,
            ortho_size: 1.0,
            near,
            far,
            render_mode: RenderMode::Visible,
            ignore_rgb: false,
            ignore_depth: false,
            ros2_rate: None,
            background: None,
        }
    }

    fn ortho(resolution: [u32; 2], ortho_size: f64, near: f64, far: f64) -> VisionModel {
        VisionModel {
            projection: Projection::Orthographic,
            ortho_size,
            ..model(resolution, 1.0, near, far)
        }
    }

    /// [`write_span`] the obvious way: each covered pixel, one after the other.
    fn write_span_by_pixel<const ORTHO: bool>(
        zbuf: &mut [f32],
        color: &mut [u32],
        ids: &mut [u32],
        span: &Span,
        rgb: [f32; 3],
        id: u32,
    ) {
        for col in span.first..span.end {
            let (z, packed) = shade::<ORTHO>(span, col as i32, rgb);
            let i = span.start + col;
            if z < zbuf[i] {
                zbuf[i] = z;
                color[i] = packed;
                ids[i] = id;
            }
        }
    }

    #[test]
    fn spans_in_chunks_draw_exactly_the_covered_pixels() {
        spans_in_chunks::<false>();
        spans_in_chunks::<true>();
    }

    /// `ORTHO`: the span's values are z and light themselves; 1/z of 0.6..2 read as z
    /// covers the same kind of overlap with what is drawn.
    fn spans_in_chunks<const ORTHO: bool>() {
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move |n: u64| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x % n
        };
        // Widths below, at and above one chunk, and not multiples of it.
        for w in [1usize, 3, 7, 8, 9, 13, 64, 100] {
            let h = 4;
            let n = w * h;
            // A scene drawn earlier: random depths 0.5..1.5 m, some pixels empty.
            let zbuf: Vec<f32> = (0..n + CHUNK - 1)
                .map(|i| {
                    if i % 5 == 0 {
                        f32::INFINITY
                    } else {
                        0.5 + next(1000) as f32 / 1000.0
                    }
                })
                .collect();
            let color: Vec<u32> = (0..n + CHUNK - 1).map(|_| next(1 << 24) as u32).collect();
            let ids: Vec<u32> = (0..n + CHUNK - 1).map(|_| next(50) as u32).collect();
            let mut drawn = 0;
            for _ in 0..200 {
                let row = next(h as u64) as usize;
                let first = next(w as u64) as usize;
                let end = first + 1 + next((w - first) as u64) as usize;
                // 1/z of 0.6..2 per metre across the row: depths 0.5..1.7 m, so some
                // pixels are in front of what is drawn and some behind.
                let iz0 = 0.6 + next(1000) as f32 / 1000.0;
                let span = Span {
                    start: row * w,
                    first,
                    end,
                    iz0,
                    diz: (next(1000) as f32 / 1000.0 - 0.5) / w as f32,
                    lz0: iz0 * next(1000) as f32 / 1000.0,
                    dlz: (next(1000) as f32 / 1000.0 - 0.5) / w as f32 * 0.1,
                };
                let rgb = [200.0, 100.0, 50.0];
                let id = 50 + next(50) as u32;
                let (mut z_want, mut c_want, mut i_want) = (zbuf.clone(), color.clone(), ids.clone());
                write_span_by_pixel::<ORTHO>(&mut z_want, &mut c_want, &mut i_want, &span, rgb, id);
                let bits = |z: &[f32]| z.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                // With the padding, and without (the buffers cut to the image); every
                // combination of buffers, each of which must get what the reference
                // wrote or stay untouched.
                for len in [n + CHUNK - 1, n] {
                    let at = format!("w {w}, row {row}, {first}..{end}, {len} pixels");
                    for (colour, with_ids) in [(true, false), (true, true), (false, true), (false, false)] {
                        let mut z_fast = zbuf[..len].to_vec();
                        let mut c_fast = color[..len].to_vec();
                        let mut i_fast = ids[..len].to_vec();
                        let bufs = Buffers {
                            zbuf: &mut z_fast,
                            color: &mut c_fast,
                            ids: &mut i_fast,
                        };
                        match (colour, with_ids) {
                            (true, false) => write_span::<ORTHO, true, false>(bufs, &span, rgb, id),
                            (true, true) => write_span::<ORTHO, true, true>(bufs, &span, rgb, id),
                            (false, true) => write_span::<ORTHO, false, true>(bufs, &span, rgb, id),
                            (false, false) => write_span::<ORTHO, false, false>(bufs, &span, rgb, id),
                        }
                        assert_eq!(bits(&z_fast), bits(&z_want[..len]), "{at}");
                        let c_ref = if colour { &c_want[..len] } else { &color[..len] };
                        assert_eq!(c_fast, c_ref, "{at}, colour {colour}");
                        let i_ref = if with_ids { &i_want[..len] } else { &ids[..len] };
                        assert_eq!(i_fast, i_ref, "{at}, ids {with_ids}");
                    }
                }
                drawn += usize::from(z_want != zbuf);
            }
            // Most spans draw something, so the comparison above is not empty.
            assert!(drawn > 100, "w {w}: {drawn} of 200 spans drew");
        }
    }

    #[test]
    fn the_view_angle_spans_the_larger_side() {
        let right = std::f64::consts::FRAC_PI_2;
        let wide = Camera::new(&model([128, 64], right, 0.01, 1.0), 512).expect("valid");
        assert!((wide.tan_x - 1.0).abs() < 1e-6 && (wide.tan_y - 0.5).abs() < 1e-6);
        let tall = Camera::new(&model([64, 128], right, 0.01, 1.0), 512).expect("valid");
        assert!((tall.tan_x - 0.5).abs() < 1e-6 && (tall.tan_y - 1.0).abs() < 1e-6);
        // An orthographic sensor's size spans the larger side in the same way.
        let wide = Camera::new(&ortho([128, 64], 0.2, 0.01, 1.0), 512).expect("valid");
        assert!(wide.ortho && (wide.tan_x - 0.1).abs() < 1e-7 && (wide.tan_y - 0.05).abs() < 1e-7);
        let tall = Camera::new(&ortho([64, 128], 0.2, 0.01, 1.0), 512).expect("valid");
        assert!((tall.tan_x - 0.05).abs() < 1e-7 && (tall.tan_y - 0.1).abs() < 1e-7);
    }

    #[test]
    fn models_out_of_range_are_refused() {
        for m in [
            model([0, 10], 1.0, 0.01, 1.0),
            model([513, 10], 1.0, 0.01, 1.0),
            model([10, 10], f64::NAN, 0.01, 1.0),
            model([10, 10], std::f64::consts::PI, 0.01, 1.0),
            model([10, 10], 1.0, 0.0, 1.0),
            model([10, 10], 1.0, 0.5, 0.5),
            model([10, 10], 1.0, 0.01, f64::INFINITY),
            ortho([10, 10], 0.0, 0.01, 1.0),
            ortho([10, 10], f64::INFINITY, 0.01, 1.0),
            ortho([10, 10], -1.0, 0.01, 1.0),
        ] {
            assert!(Camera::new(&m, 512).is_none(), "{m:?}");
        }
        // The view angle does not matter to an orthographic sensor, nor the ortho size
        // to a perspective one.
        assert!(Camera::new(&ortho([10, 10], 0.1, 0.01, 1.0), 512).is_some());
        assert!(
            Camera::new(
                &VisionModel {
                    fov: f64::NAN,
                    ..ortho([10, 10], 0.1, 0.01, 1.0)
                },
                512
            )
            .is_some()
        );
        assert!(
            Camera::new(
                &VisionModel {
                    ortho_size: 0.0,
                    ..model([10, 10], 1.0, 0.01, 1.0)
                },
                512
            )
            .is_some()
        );
    }
}
