//! Unit tests of the detection volumes, most of them against an independent brute-force
//! oracle (`oracle.rs`). Fixtures shared by the files below live here.

mod composite;
mod convex;
mod half_space;
mod near_cap;
mod oracle;
mod stress;
mod volume;

use core::f32::consts::TAU;

use parry3d::math::{Rotation, Vector};
use parry3d::shape::{ConvexPolyhedron, TriMesh};

use super::ProximityVolume;

/// Tolerance (m) required between the detector and the brute-force oracle.
const TOL: f32 = 1.0e-5;

/// The scene used in most tests: offset 0.005 m, range 0.15 m, full angle 30°.
fn small_cone() -> ProximityVolume {
    ProximityVolume::Cone {
        offset: 0.005,
        range: 0.15,
        half_angle: 15f32.to_radians(),
    }
}

fn cone_params(vol: &ProximityVolume) -> (f32, f32, f32) {
    match *vol {
        ProximityVolume::Cone {
            offset,
            range,
            half_angle,
        } => (offset, offset + range, half_angle),
        ProximityVolume::Ray { .. } => panic!("the oracle handles cones only"),
    }
}

/// Tiny deterministic xorshift generator (no external dependency).
struct Rng(u64);
impl Rng {
    fn next_f32(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next_f32()
    }
    fn rotation(&mut self) -> Rotation {
        let axis =
            Vector::new(self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0)).normalize_or(Vector::X);
        Rotation::from_axis_angle(axis, self.range(0.0, TAU))
    }
}

fn direction(theta: f32, phi: f32) -> Vector {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    Vector::new(st * cp, st * sp, ct)
}

/// A convex polyhedron of 12 points spread on a sphere of radius 0.03 m (a Fibonacci sphere).
fn fibonacci_hull() -> ConvexPolyhedron {
    ConvexPolyhedron::from_convex_hull(
        &(0..12)
            .map(|i| {
                let a = i as f32 * 2.4;
                let z = 1.0 - 2.0 * (i as f32 + 0.5) / 12.0;
                Vector::new((1.0 - z * z).sqrt() * a.cos(), (1.0 - z * z).sqrt() * a.sin(), z) * 0.03
            })
            .collect::<Vec<_>>(),
    )
    .expect("hull")
}

/// A closed box mesh of half-extents `h` (m): 12 triangles, outward-facing.
fn box_trimesh(h: Vector) -> TriMesh {
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
