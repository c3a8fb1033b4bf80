//! Vertex clustering of a triangle mesh: space is cut into cubic cells, the vertices
//! in a cell are replaced by their mean, and triangles left with fewer than three
//! distinct corners are dropped. The renderer's levels of detail for dense meshes
//! (`vision::detail`) and `sim.getDecimatedMesh` (`world::shape_mesh`) are built on it,
//! so it sits below both.

use std::collections::HashMap;

use crate::scene::MeshData;

/// `data` with its vertices clustered in cells of side `cell` (metres), each replaced by
/// the mean of its cell's vertices, and the triangles that keep three distinct corners,
/// once each, in the file's order; and the largest distance a finite vertex moved.
/// Non-finite vertices are left as they are (their triangles are then skipped by the
/// tessellation, as in the full mesh).
pub fn cluster(data: &MeshData, cell: f32) -> (MeshData, f32) {
    let mut cells: HashMap<[i64; 3], u32> = HashMap::new();
    // Per cluster: the sum of its vertices (f64, so the mean does not depend on how
    // many there are beyond rounding) and their count.
    let mut sums: Vec<([f64; 3], f64)> = Vec::new();
    let ids: Vec<u32> = data
        .vertices
        .iter()
        .map(|v| {
            let key = if v.iter().all(|c| c.is_finite()) {
                v.map(|c| (f64::from(c) / f64::from(cell)).floor() as i64)
            } else {
                // Its own cluster, never merged: the tessellation drops its triangles.
                [i64::MIN, i64::MIN, sums.len() as i64]
            };
            let next = sums.len() as u32;
            let id = *cells.entry(key).or_insert_with(|| {
                sums.push(([0.0; 3], 0.0));
                next
            });
            let (s, n) = &mut sums[id as usize];
            for k in 0..3 {
                s[k] += f64::from(v[k]);
            }
            *n += 1.0;
            id
        })
        .collect();
    let vertices: Vec<[f32; 3]> = sums.iter().map(|(s, n)| s.map(|c| (c / n) as f32)).collect();
    let max_shift = data
        .vertices
        .iter()
        .zip(&ids)
        .filter(|(v, _)| v.iter().all(|c| c.is_finite()))
        .map(|(v, &id)| {
            let m = vertices[id as usize];
            (0..3).map(|k| (v[k] - m[k]).powi(2)).sum::<f32>().sqrt()
        })
        .fold(0.0f32, f32::max);
    let mut seen = std::collections::HashSet::new();
    let indices = data
        .indices
        .iter()
        .filter_map(|t| {
            let c = t.map(|i| ids.get(i as usize).copied());
            let [Some(a), Some(b), Some(c)] = c else {
                return None;
            };
            if a == b || b == c || a == c {
                return None;
            }
            // Drawn two-sided: one triangle per set of corners, whichever its winding.
            let mut key = [a, b, c];
            key.sort_unstable();
            seen.insert(key).then_some([a, b, c])
        })
        .collect();
    let clustered = MeshData {
        source: data.source.clone(),
        vertices,
        indices,
        parts: Vec::new(),
    };
    (clustered, max_shift)
}
