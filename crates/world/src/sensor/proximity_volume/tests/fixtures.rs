//! Fixtures shared by the unit tests of the detection volumes and by
//! `benches/proximity.rs` (which includes this file with `#[path]`), so that both time
//! and test the same poses and meshes.

use core::f32::consts::TAU;

use parry3d::math::{Rotation, Vector};
use parry3d::shape::TriMesh;

/// Tiny deterministic xorshift generator (no external dependency).
pub struct Rng(pub u64);

impl Rng {
    pub fn next_f32(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next_f32()
    }
    pub fn rotation(&mut self) -> Rotation {
        let axis =
            Vector::new(self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0)).normalize_or(Vector::X);
        Rotation::from_axis_angle(axis, self.range(0.0, TAU))
    }
}

/// A closed box mesh of half-extents `h` (m): 12 triangles, outward-facing.
pub fn box_trimesh(h: Vector) -> TriMesh {
    let v: Vec<Vector> = (0..8)
        .map(|i| {
            Vector::new(
                if i & 1 == 0 { -h.x } else { h.x },
                if i & 2 == 0 { -h.y } else { h.y },
                if i & 4 == 0 { -h.z } else { h.z },
            )
        })
        .collect();
    let idx = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    TriMesh::new(v, idx).expect("a closed box is a valid trimesh")
}
