//! Triangle meshes for the renderer, built once per visual from [`Geometry`] and laid
//! out for the rasteriser at that time, so a frame does no per-mesh preparation.
//!
//! Curved primitives carry smooth per-vertex normals, so shading varies continuously
//! across a cylinder or sphere (a faceted look would put false edges into
//! `simVision.edgeDetectionOnWorkImg`). Flat faces (box sides, cylinder caps) have their
//! vertices duplicated per face. Imported meshes are shaded flat: one normal per
//! triangle ([`Normals::Face`]), so their vertices can be shared between triangles.
//!
//! # Chunks
//! The triangles are cut into [`Chunk`]s of at most [`CHUNK_TRIANGLES`] consecutive
//! triangles, in the file's order (the z-buffer keeps the first of two equally deep
//! fragments, so the drawing order is part of the image). Each chunk has its own
//! vertices, each position stored once within it (a vendor mesh has about half as many
//! distinct positions as triangles, against three vertices per triangle as read), and
//! a bounding sphere: the renderer skips a chunk outside the view before transforming
//! any of its vertices.

use std::collections::HashMap;

use super::closure;
use crate::scene::{Geometry, MeshData};

/// Segments around the axis of cylinders, spheres and capsules: a chord error of
/// 0.5 % of the radius, below a pixel for objects that fill less than ~100 px.
const AROUND: usize = 32;
/// Latitude bands of spheres and capsule caps (from pole to pole).
const BANDS: usize = 16;
/// Triangles per chunk. Small enough that a chunk of a vendor mesh covers a few
/// centimetres (so most of an arm is culled when the view holds a part of it), large
/// enough that the per-chunk sphere test (about 10 ns) is noise next to drawing it.
pub(crate) const CHUNK_TRIANGLES: usize = 256;

/// How a mesh is shaded.
#[derive(Debug, Clone)]
pub(crate) enum Normals {
    /// Unit normal per vertex, parallel to [`TriMesh::positions`] (Gouraud shading).
    Vertex(Vec<[f32; 3]>),
    /// Unit normal per triangle, parallel to [`TriMesh::triangles`] (flat shading).
    Face(Vec<[f32; 3]>),
}

impl Default for Normals {
    fn default() -> Self {
        Normals::Vertex(Vec::new())
    }
}

/// A run of consecutive triangles of a [`TriMesh`] with its own vertices.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Chunk {
    /// The chunk's vertices: `positions[first_vertex..end_vertex]`.
    pub first_vertex: u32,
    pub end_vertex: u32,
    /// The chunk's triangles: `triangles[first_triangle..end_triangle]`, whose indices
    /// count from `first_vertex`.
    pub first_triangle: u32,
    pub end_triangle: u32,
    /// Bounding sphere of the chunk's vertices, in the visual's frame (metres).
    pub center: [f32; 3],
    pub radius: f32,
    /// Whether every triangle of the chunk lies on a closed surface wound outwards
    /// (every primitive's; an imported mesh's closed components, see
    /// [`super::closure`]), so its back faces may be culled.
    pub closed: bool,
}

/// One visual as triangles, in the visual's own frame (metres), in chunks.
#[derive(Debug, Clone, Default)]
pub(crate) struct TriMesh {
    /// Vertex positions, chunk after chunk.
    pub positions: Vec<[f32; 3]>,
    /// Normals, per vertex or per triangle.
    pub normals: Normals,
    /// Triangles as indices from their chunk's first vertex, counter-clockwise seen
    /// from outside.
    pub triangles: Vec<[u32; 3]>,
    /// The chunks, in drawing order, covering every triangle once.
    pub chunks: Vec<Chunk>,
    /// Whether the surface is a primitive's, closed with outward winding, so back faces
    /// may be culled however it is seen. Imported meshes are not trusted to be: only
    /// their chunks on closed components ([`Chunk::closed`]) may be culled, and only
    /// when the eye is outside them.
    pub closed: bool,
    /// Centre of the bounding sphere, for frustum culling.
    pub center: [f32; 3],
    /// Radius of the bounding sphere (0 for an empty mesh).
    pub radius: f32,
    /// For an imported mesh, parallel to `triangles`: the index of each triangle in the
    /// mesh data (triangles with bad vertices are left out), so that texture
    /// coordinates given per triangle of the data find their triangle. Empty for
    /// primitives.
    pub source: Vec<u32>,
}

/// A mesh as the builders below make it: per-vertex normals, global indices.
#[derive(Debug, Default)]
struct Soup {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
    /// See [`TriMesh::source`].
    source: Vec<u32>,
}

impl TriMesh {
    /// Tessellates a geometry. Invalid sizes (non-finite, or not positive) give an
    /// empty mesh rather than an error: the object is then simply not seen. An
    /// imported mesh's closed parts are found ([`super::closure`]).
    pub fn from_geometry(geometry: &Geometry) -> TriMesh {
        Self::tessellate(geometry, true)
    }

    /// An imported mesh as a coarser copy of another ([`super::detail`]), all of it
    /// drawn two-sided: clustering vertices pinches closed surfaces into edges shared
    /// by more than two triangles, so its copies are (almost) never closed, and judging
    /// them took longer than the full mesh's first frame.
    pub fn coarse_copy(data: std::sync::Arc<MeshData>) -> TriMesh {
        Self::tessellate(&Geometry::Mesh(data), false)
    }

    fn tessellate(geometry: &Geometry, judge_closure: bool) -> TriMesh {
        let mut m = Soup::default();
        match geometry {
            Geometry::Box { half_extents } => {
                if let Some(h) = positive3(*half_extents) {
                    m.add_box(h);
                }
            }
            Geometry::Sphere { radius } => {
                if let Some(r) = positive(*radius) {
                    m.add_round(r, 0.0);
                }
            }
            Geometry::Capsule { radius, length } => {
                if let (Some(r), Some(l)) = (positive(*radius), non_negative(*length)) {
                    m.add_round(r, l / 2.0);
                }
            }
            Geometry::Cylinder { radius, length } => {
                if let (Some(r), Some(l)) = (positive(*radius), positive(*length)) {
                    m.add_cylinder(r, l / 2.0);
                }
            }
            Geometry::Mesh(data) => m.add_mesh(data),
        }
        let flat = matches!(geometry, Geometry::Mesh(_));
        let closed = if !flat {
            vec![true; m.triangles.len()]
        } else if judge_closure {
            closure::closed_triangles(&m.positions, &m.triangles)
        } else {
            vec![false; m.triangles.len()]
        };
        let mut out = m.into_chunks(flat, &closed);
        out.closed = !flat;
        let (center, radius) = bound(&out.positions);
        (out.center, out.radius) = (center, radius);
        out
    }

    /// The triangles of `chunk`, with indices from its first vertex.
    pub fn chunk_triangles(&self, chunk: &Chunk) -> &[[u32; 3]] {
        self.triangles
            .get(chunk.first_triangle as usize..chunk.end_triangle as usize)
            .unwrap_or(&[])
    }

    /// The vertex positions of `chunk`.
    pub fn chunk_positions(&self, chunk: &Chunk) -> &[[f32; 3]] {
        self.positions
            .get(chunk.first_vertex as usize..chunk.end_vertex as usize)
            .unwrap_or(&[])
    }
}

impl Soup {
    /// Cuts the triangles into chunks of consecutive triangles. Within a chunk each
    /// vertex used is stored once: with `flat`, vertices with the same position (bit
    /// for bit) are one, and each triangle keeps its face normal (its first vertex's:
    /// [`Soup::add_mesh`] gives all three the face's); otherwise the builders' vertices
    /// are kept as they are, with their normals.
    /// `closed` tells, per triangle, whether it lies on a closed, outward-wound
    /// surface; a chunk is closed when all its triangles are.
    fn into_chunks(self, flat: bool, closed: &[bool]) -> TriMesh {
        let mut out = TriMesh {
            source: self.source,
            ..TriMesh::default()
        };
        let mut vertex_normals = Vec::new();
        let mut face_normals = Vec::new();
        let mut local: HashMap<[u32; 3], u32> = HashMap::new();
        for (tris, closed) in self
            .triangles
            .chunks(CHUNK_TRIANGLES)
            .zip(closed.chunks(CHUNK_TRIANGLES))
        {
            local.clear();
            let first_vertex = out.positions.len();
            let first_triangle = out.triangles.len();
            for tri in tris {
                let mut t = [0u32; 3];
                for (k, &i) in tri.iter().enumerate() {
                    let p = self.positions[i as usize];
                    // Flat meshes share positions; the builders' smooth vertices are
                    // shared by index already (the key is then the index).
                    let key = if flat { p.map(f32::to_bits) } else { [i, 0, 0] };
                    let next = (out.positions.len() - first_vertex) as u32;
                    t[k] = *local.entry(key).or_insert_with(|| {
                        out.positions.push(p);
                        if !flat {
                            vertex_normals.push(self.normals[i as usize]);
                        }
                        next
                    });
                }
                if flat {
                    face_normals.push(self.normals[tri[0] as usize]);
                }
                out.triangles.push(t);
            }
            let (center, radius) = bound(&out.positions[first_vertex..]);
            // Counts fit in u32: a mesh with more than 4 billion vertices cannot be
            // loaded in the first place.
            out.chunks.push(Chunk {
                first_vertex: first_vertex as u32,
                end_vertex: out.positions.len() as u32,
                first_triangle: first_triangle as u32,
                end_triangle: out.triangles.len() as u32,
                center,
                radius,
                closed: closed.iter().all(|&c| c),
            });
        }
        out.normals = if flat {
            Normals::Face(face_normals)
        } else {
            Normals::Vertex(vertex_normals)
        };
        out
    }

    fn vertex(&mut self, p: [f32; 3], n: [f32; 3]) -> u32 {
        // A visual with more than 4 billion vertices cannot be loaded in the first place.
        let i = u32::try_from(self.positions.len()).unwrap_or(u32::MAX);
        self.positions.push(p);
        self.normals.push(n);
        i
    }

    fn add_box(&mut self, h: [f32; 3]) {
        // Face normal along axis `a`, spanned by axes `b`, `c` with e_b x e_c = e_a, so
        // the corners (-,-), (+,-), (+,+), (-,+) in (b, c) run counter-clockwise.
        for a in 0..3 {
            for sign in [1.0f32, -1.0] {
                let (b, c) = if sign > 0.0 {
                    ((a + 1) % 3, (a + 2) % 3)
                } else {
                    ((a + 2) % 3, (a + 1) % 3)
                };
                let mut n = [0.0; 3];
                n[a] = sign;
                let base = self.positions.len() as u32;
                for (sb, sc) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                    let mut p = [0.0; 3];
                    p[a] = sign * h[a];
                    p[b] = sb * h[b];
                    p[c] = sc * h[c];
                    self.vertex(p, n);
                }
                self.triangles.push([base, base + 1, base + 2]);
                self.triangles.push([base, base + 2, base + 3]);
            }
        }
    }

    /// Appends rings `lo` and `hi` (each `AROUND` vertices, `hi` above `lo`) joined by
    /// quads. `lo_pole`/`hi_pole` mark rings collapsed to a point, whose degenerate
    /// triangles are left out.
    fn join_rings(&mut self, lo: u32, hi: u32, lo_pole: bool, hi_pole: bool) {
        let n = AROUND as u32;
        for j in 0..n {
            let k = (j + 1) % n;
            let (a0, a1, b0, b1) = (lo + j, lo + k, hi + j, hi + k);
            if !lo_pole {
                self.triangles.push([a0, a1, b1]);
            }
            if !hi_pole {
                self.triangles.push([a0, b1, b0]);
            }
        }
    }

    /// A ring of `AROUND` vertices at height `z`, radius `r`, with normals made of the
    /// radial direction scaled by `nr` plus `nz` along Z.
    fn ring(&mut self, r: f32, z: f32, nr: f32, nz: f32) -> u32 {
        let first = self.positions.len() as u32;
        for j in 0..AROUND {
            let th = std::f32::consts::TAU * j as f32 / AROUND as f32;
            let (s, c) = th.sin_cos();
            self.vertex([r * c, r * s, z], [nr * c, nr * s, nz]);
        }
        first
    }

    /// A sphere (`half_length` 0) or a capsule along Z: two hemispheres whose equators
    /// are `2 * half_length` apart, the band between them being the cylindrical part.
    fn add_round(&mut self, r: f32, half_length: f32) {
        let mut prev: Option<(u32, bool)> = None;
        for k in 0..=BANDS {
            let phi = -std::f32::consts::FRAC_PI_2 + std::f32::consts::PI * k as f32 / BANDS as f32;
            let (sp, cp) = phi.sin_cos();
            let pole = k == 0 || k == BANDS;
            // The equator is emitted twice for a capsule (bottom and top hemisphere);
            // for a sphere once.
            let offsets: &[f32] = if 2 * k == BANDS && half_length > 0.0 {
                &[-half_length, half_length]
            } else if 2 * k < BANDS {
                &[-half_length]
            } else {
                &[half_length]
            };
            for &off in offsets {
                let rr = if pole { 0.0 } else { r * cp };
                let ring = self.ring(rr, r * sp + off, if pole { 0.0 } else { cp }, sp);
                if let Some((lo, lo_pole)) = prev {
                    self.join_rings(lo, ring, lo_pole, pole);
                }
                prev = Some((ring, pole));
            }
        }
    }

    fn add_cylinder(&mut self, r: f32, h: f32) {
        let lo = self.ring(r, -h, 1.0, 0.0);
        let hi = self.ring(r, h, 1.0, 0.0);
        self.join_rings(lo, hi, false, false);
        let n = AROUND as u32;
        for (z, nz) in [(h, 1.0f32), (-h, -1.0)] {
            let c = self.vertex([0.0, 0.0, z], [0.0, 0.0, nz]);
            let ring = self.ring(r, z, 0.0, nz);
            for j in 0..n {
                let (a, b) = (ring + j, ring + (j + 1) % n);
                // Counter-clockwise seen from +Z on the top cap, from -Z on the bottom.
                self.triangles.push(if nz > 0.0 { [c, a, b] } else { [c, b, a] });
            }
        }
    }

    fn add_mesh(&mut self, data: &MeshData) {
        for (index, tri) in data.indices.iter().enumerate() {
            let mut p = [[0.0f32; 3]; 3];
            let mut ok = true;
            for (k, &i) in tri.iter().enumerate() {
                match data.vertices.get(i as usize) {
                    Some(v) if v.iter().all(|c| c.is_finite()) => p[k] = *v,
                    _ => ok = false,
                }
            }
            let n = normalize(cross(sub(p[1], p[0]), sub(p[2], p[0])));
            if !ok || n == [0.0; 3] {
                continue;
            }
            let a = self.vertex(p[0], n);
            let b = self.vertex(p[1], n);
            let c = self.vertex(p[2], n);
            self.triangles.push([a, b, c]);
            // Fewer than 2^32 triangles: see `vertex`.
            self.source.push(index as u32);
        }
    }
}

/// Bounding sphere of `points`: the centre of their box and the largest distance from
/// it; radius 0 for no points.
fn bound(points: &[[f32; 3]]) -> ([f32; 3], f32) {
    if points.is_empty() {
        return ([0.0; 3], 0.0);
    }
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let c = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0, (lo[2] + hi[2]) / 2.0];
    let r2 = points
        .iter()
        .map(|p| dot(sub(*p, c), sub(*p, c)))
        .fold(0.0f32, f32::max);
    (c, r2.sqrt())
}

fn positive(v: f64) -> Option<f32> {
    (v.is_finite() && v > 0.0).then_some(v as f32)
}

fn non_negative(v: f64) -> Option<f32> {
    (v.is_finite() && v >= 0.0).then_some(v as f32)
}

fn positive3(v: [f64; 3]) -> Option<[f32; 3]> {
    Some([positive(v[0])?, positive(v[1])?, positive(v[2])?])
}

pub(crate) fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The unit vector along `v`, or zero for a zero or non-finite vector.
fn normalize(v: [f32; 3]) -> [f32; 3] {
    let n = dot(v, v).sqrt();
    if n.is_finite() && n > 1e-20 {
        [v[0] / n, v[1] / n, v[2] / n]
    } else {
        [0.0; 3]
    }
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;
    use std::sync::Arc;

    use super::*;

    fn convex_cases() -> Vec<(&'static str, TriMesh)> {
        vec![
            (
                "box",
                TriMesh::from_geometry(&Geometry::Box {
                    half_extents: [0.1, 0.2, 0.3],
                }),
            ),
            ("sphere", TriMesh::from_geometry(&Geometry::Sphere { radius: 0.5 })),
            (
                "cylinder",
                TriMesh::from_geometry(&Geometry::Cylinder {
                    radius: 0.05,
                    length: 0.2,
                }),
            ),
            (
                "capsule",
                TriMesh::from_geometry(&Geometry::Capsule {
                    radius: 0.1,
                    length: 0.4,
                }),
            ),
        ]
    }

    #[test]
    fn primitives_are_closed_and_wound_outwards() {
        for (name, m) in convex_cases() {
            assert!(m.closed, "{name}");
            assert!(!m.triangles.is_empty(), "{name}");
            for (chunk, t) in m
                .chunks
                .iter()
                .flat_map(|c| m.chunk_triangles(c).iter().map(move |t| (c, t)))
            {
                let [a, b, c] = t.map(|i| m.chunk_positions(chunk)[i as usize]);
                let n = cross(sub(b, a), sub(c, a));
                let centroid = [
                    (a[0] + b[0] + c[0]) / 3.0,
                    (a[1] + b[1] + c[1]) / 3.0,
                    (a[2] + b[2] + c[2]) / 3.0,
                ];
                // Convex and centred on the origin: outward means away from the origin.
                assert!(dot(n, centroid) > 0.0, "{name}: triangle {t:?} faces inwards");
            }
            let Normals::Vertex(normals) = &m.normals else {
                panic!("{name}: primitives have vertex normals");
            };
            assert_eq!(normals.len(), m.positions.len(), "{name}");
            for n in normals {
                assert!((dot(*n, *n) - 1.0).abs() < 1e-5, "{name}: normal {n:?} is not unit");
            }
        }
    }

    #[test]
    fn triangle_counts_and_bounds() {
        let b = TriMesh::from_geometry(&Geometry::Box {
            half_extents: [1.0, 1.0, 1.0],
        });
        assert_eq!(b.triangles.len(), 12);
        assert!((b.radius - 3f32.sqrt()).abs() < 1e-6);
        let c = TriMesh::from_geometry(&Geometry::Cylinder {
            radius: 1.0,
            length: 2.0,
        });
        assert_eq!(c.triangles.len(), 4 * AROUND);
        // Two polar caps of AROUND triangles, 2 * AROUND per other band.
        let s = TriMesh::from_geometry(&Geometry::Sphere { radius: 1.0 });
        assert_eq!(s.triangles.len(), 2 * AROUND * (BANDS - 1));
    }

    #[test]
    fn invalid_sizes_give_empty_meshes() {
        for g in [
            Geometry::Sphere { radius: f64::NAN },
            Geometry::Box {
                half_extents: [1.0, 0.0, 1.0],
            },
            Geometry::Cylinder {
                radius: -1.0,
                length: 1.0,
            },
        ] {
            let m = TriMesh::from_geometry(&g);
            assert!(m.triangles.is_empty() && m.radius == 0.0);
        }
    }

    #[test]
    fn meshes_skip_bad_triangles() {
        let data = MeshData {
            source: PathBuf::from("test"),
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [f32::NAN, 0.0, 0.0]],
            indices: vec![[0, 1, 2], [0, 1, 3], [0, 1, 9], [0, 0, 1]],
            parts: Vec::new(),
        };
        let m = TriMesh::from_geometry(&Geometry::Mesh(Arc::new(data)));
        assert_eq!(m.triangles.len(), 1);
        assert_eq!(m.source, [0]);
        assert!(!m.closed);
        let Normals::Face(normals) = &m.normals else {
            panic!("meshes are shaded flat");
        };
        assert_eq!(normals, &[[0.0, 0.0, 1.0]]);
    }
}
