//! Levels of detail for dense imported meshes, so that a small view of a vendor arm
//! does not fetch and test 100,000 triangles smaller than its pixels.
//!
//! A public arm's visual meshes (a Panda, a UR5) hold about 100,000 triangles, a few
//! millimetres each. A 128 x 128 view of the arm from a metre away has pixels of about
//! a centimetre: most triangles cover no pixel centre and draw nothing, yet each is
//! transformed, fetched and tested, which was nearly all of such a frame's time. Each
//! dense mesh therefore also keeps coarser copies made by *vertex clustering*: space is
//! cut into cubic cells of side `cell`, the vertices in a cell are replaced by their
//! mean, and triangles left with fewer than three distinct corners are dropped.
//!
//! # The error is below half a pixel
//! A vertex moves to the mean of its cell's vertices, which lies in the cell, so it
//! moves by less than the cell's diagonal, `sqrt(3) * cell`; each level records the
//! largest move it actually made (`max_shift`, usually well under the diagonal). A point
//! of a triangle is a weighted mean of its corners, so it moves by at most as much as
//! they do. The renderer picks, per visual and per view, the coarsest copy whose
//! largest move is at most [`MAX_ERROR_PX`] of a pixel's footprint at the visual's
//! nearest point ([`pick`]): every silhouette and surface is then within half a pixel of
//! where the full mesh puts it, and depths within that distance too (well under 1 % of
//! the depth). Views whose pixels are
//! small next to the triangles (a 640 x 480 camera close to the arm) keep the full mesh.
//! The choice depends only on the mesh and the view, so images stay the same from run
//! to run.

use std::sync::Arc;

use super::tessellate::TriMesh;
use crate::mesh_cluster::cluster;
use crate::scene::Geometry;

/// The largest displacement a coarser copy may make, in pixels at the visual's nearest
/// point.
pub(crate) const MAX_ERROR_PX: f32 = 0.5;
/// Meshes with fewer triangles are always drawn whole: a coarse copy would save little.
const MIN_TRIANGLES: usize = 2048;
/// Cell sides tried, as fractions of the mesh's bounding radius: 1/256 to 1/16 in steps
/// of a factor sqrt(2) (with a factor 2, a view often fell just short of the next level).
const CELL_FRACTIONS: [f32; 9] = [
    1.0 / 256.0,
    1.0 / 181.0,
    1.0 / 128.0,
    1.0 / 90.5,
    1.0 / 64.0,
    1.0 / 45.3,
    1.0 / 32.0,
    1.0 / 22.6,
    1.0 / 16.0,
];
/// A level is kept only with at most this share of the triangles of the finer one it
/// would replace.
const MIN_SAVING: f32 = 0.8;

/// A coarser copy of a mesh: its cell side and the largest distance a vertex moved,
/// metres, and its triangles.
#[derive(Debug, Clone)]
pub(crate) struct Level {
    /// Read by the tests, which check each level's vertices against their cells.
    #[cfg_attr(not(test), expect(dead_code, reason = "the tests' bound on each level"))]
    pub cell: f32,
    pub max_shift: f32,
    pub mesh: TriMesh,
}

/// The coarser copies of an imported mesh worth keeping, finest first; none for a
/// primitive or a mesh of fewer than [`MIN_TRIANGLES`] triangles.
pub(crate) fn levels(geometry: &Geometry, full: &TriMesh) -> Vec<Level> {
    let Geometry::Mesh(data) = geometry else {
        return Vec::new();
    };
    if full.triangles.len() < MIN_TRIANGLES || full.radius.is_nan() || full.radius <= 0.0 {
        return Vec::new();
    }
    let mut out: Vec<Level> = Vec::new();
    let mut previous = full.triangles.len();
    for fraction in CELL_FRACTIONS {
        let cell = full.radius * fraction;
        let (clustered, max_shift) = cluster(data, cell);
        let mesh = TriMesh::coarse_copy(Arc::new(clustered));
        if mesh.triangles.is_empty() {
            break;
        }
        if (mesh.triangles.len() as f32) <= MIN_SAVING * previous as f32 {
            previous = mesh.triangles.len();
            out.push(Level { cell, max_shift, mesh });
        }
    }
    out
}

/// The level to draw: the coarsest whose vertices moved at most [`MAX_ERROR_PX`] of
/// `footprint`, the side of a pixel (metres) at the visual's nearest point; `None` for
/// the full mesh.
pub(crate) fn pick(levels: &[Level], footprint: f32) -> Option<&Level> {
    let allowed = MAX_ERROR_PX * footprint;
    levels.iter().rev().find(|l| l.max_shift <= allowed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::MeshData;

    /// A bumpy, finely tessellated sphere of radius about 0.1 m: `n` x `2n` quads.
    fn dense_sphere(n: u32) -> MeshData {
        let mut vertices = Vec::new();
        for i in 0..=n {
            let phi = std::f32::consts::PI * i as f32 / n as f32;
            for j in 0..2 * n {
                let th = std::f32::consts::PI * j as f32 / n as f32;
                let r = 0.1 + 0.004 * (5.0 * th).sin() * (3.0 * phi).cos();
                vertices.push([r * phi.sin() * th.cos(), r * phi.sin() * th.sin(), r * phi.cos()]);
            }
        }
        let at = |i: u32, j: u32| i * 2 * n + j % (2 * n);
        let mut indices = Vec::new();
        for i in 0..n {
            for j in 0..2 * n {
                indices.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                indices.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        MeshData {
            source: "sphere".into(),
            vertices,
            indices,
            parts: Vec::new(),
        }
    }

    #[test]
    fn coarser_levels_move_no_vertex_beyond_their_cell() {
        let data = dense_sphere(100);
        let geometry = Geometry::Mesh(Arc::new(data.clone()));
        let full = TriMesh::from_geometry(&geometry);
        let levels = levels(&geometry, &full);
        assert!(levels.len() >= 2, "{} levels", levels.len());
        let mut previous = full.triangles.len();
        for level in &levels {
            assert!(level.mesh.triangles.len() as f32 <= MIN_SAVING * previous as f32);
            previous = level.mesh.triangles.len();
            // Every vertex of the coarse mesh is the mean of a cell's vertices: within a
            // cell diagonal of one of the original vertices.
            let diag = 3f32.sqrt() * level.cell;
            // The largest move recorded is within it too.
            assert!(level.max_shift > 0.0 && level.max_shift <= diag * 1.0001);
            for p in &level.mesh.positions {
                let nearest = data
                    .vertices
                    .iter()
                    .map(|v| (0..3).map(|k| (v[k] - p[k]).powi(2)).sum::<f32>().sqrt())
                    .fold(f32::INFINITY, f32::min);
                assert!(nearest <= diag * 1.0001, "{nearest} > {diag}");
            }
        }
        // Coarse enough levels keep far fewer triangles.
        assert!(
            levels
                .last()
                .is_some_and(|l| l.mesh.triangles.len() * 3 < full.triangles.len())
        );
    }

    #[test]
    fn the_pick_keeps_the_error_below_half_a_pixel() {
        let data = dense_sphere(100);
        let geometry = Geometry::Mesh(Arc::new(data));
        let full = TriMesh::from_geometry(&geometry);
        let levels = levels(&geometry, &full);
        // Pixels whose half is less than the finest level's largest move: the full mesh.
        assert!(pick(&levels, levels[0].max_shift).is_none());
        for footprint in [0.001f32, 0.004, 0.01, 0.05, 1.0] {
            if let Some(l) = pick(&levels, footprint) {
                assert!(l.max_shift <= MAX_ERROR_PX * footprint);
                // And it is the coarsest such level.
                assert!(
                    levels
                        .iter()
                        .filter(|m| m.cell > l.cell)
                        .all(|m| m.max_shift > MAX_ERROR_PX * footprint)
                );
            }
        }
        // Small meshes and primitives have no levels.
        let small = Geometry::Mesh(Arc::new(dense_sphere(10)));
        assert!(levels_of(&small).is_empty());
        assert!(levels_of(&Geometry::Sphere { radius: 0.1 }).is_empty());
    }

    fn levels_of(g: &Geometry) -> Vec<Level> {
        levels(g, &TriMesh::from_geometry(g))
    }

    #[test]
    fn non_finite_vertices_stay_out_of_every_level() {
        let mut data = dense_sphere(60);
        data.vertices[5] = [f32::NAN, 0.0, 0.0];
        data.vertices[6] = [f32::INFINITY, 0.0, 0.0];
        let geometry = Geometry::Mesh(Arc::new(data));
        let full = TriMesh::from_geometry(&geometry);
        for level in levels(&geometry, &full) {
            assert!(level.mesh.positions.iter().flatten().all(|c| c.is_finite()));
        }
    }
}
