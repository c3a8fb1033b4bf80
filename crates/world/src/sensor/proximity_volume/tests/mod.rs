//! Unit tests of the detection volumes, most of them against an independent brute-force
//! oracle (`oracle.rs`). Fixtures shared by the files below live here.

mod composite;
mod convex;
mod fixtures;
mod half_space;
mod near_cap;
mod oracle;
mod polytope;
mod stress;
mod volume;

use parry3d::math::Vector;
use parry3d::shape::ConvexPolyhedron;

pub(super) use fixtures::{Rng, box_trimesh};

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
        _ => panic!("the oracle handles cones only"),
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
