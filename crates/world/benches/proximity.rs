//! `cargo bench -p gantry-world --bench proximity`: nanoseconds per
//! `ProximityVolume::detect` call (the exact ray and cone volumes of
//! `gantry_world::sensor`) on the paths the module documentation prices: the fast path
//! (one point projection), the lateral search on the cone's surface, the near cap, a mesh and
//! the ray.
//!
//! Prints one Markdown table. Each row times 200 fixed random poses (sensor frame, metres),
//! repeated; figures are the median and minimum over 31 rounds of the mean per call. On a
//! busy machine the minimum is the steadier figure for comparing two versions.

use std::hint::black_box;
use std::time::Instant;

use gantry_world::sensor::ProximityVolume;
use parry3d::math::{Pose, Vector};
use parry3d::shape::{Ball, ConvexPolyhedron, Cuboid, Cylinder, Shape};

#[path = "../src/sensor/proximity_volume/tests/fixtures.rs"]
mod fixtures;

use fixtures::{Rng, box_trimesh};

/// Poses (sensor frame) whose translation is `centre` (m) plus a uniform offset of up to
/// `spread` (m) on each axis, randomly rotated.
fn poses(seed: u64, centre: Vector, spread: f32) -> Vec<Pose> {
    let mut rng = Rng(seed);
    (0..200)
        .map(|_| {
            let jitter = Vector::new(
                rng.range(-spread, spread),
                rng.range(-spread, spread),
                rng.range(-spread, spread),
            );
            Pose::from_parts(centre + jitter, rng.rotation())
        })
        .collect()
}

/// Median and minimum nanoseconds per `detect`, as "median (min)", and how many of the
/// poses were detected.
fn time(volume: &ProximityVolume, shape: &dyn Shape, poses: &[Pose]) -> (String, usize) {
    let hits = poses.iter().filter(|p| volume.detect(shape, p).is_some()).count();
    let reps = 20;
    let mut rounds: Vec<f64> = (0..31)
        .map(|_| {
            let t = Instant::now();
            for _ in 0..reps {
                for p in poses {
                    black_box(volume.detect(black_box(shape), black_box(p)));
                }
            }
            t.elapsed().as_secs_f64() * 1e9 / (reps * poses.len()) as f64
        })
        .collect();
    rounds.sort_by(f64::total_cmp);
    (format!("{:.0} ({:.0})", rounds[rounds.len() / 2], rounds[0]), hits)
}

fn main() {
    // BubbleRob's nose sensor: offset 0.005 m, range 0.15 m, full angle 30°.
    let cone = ProximityVolume::Cone {
        offset: 0.005,
        range: 0.15,
        half_angle: 15f32.to_radians(),
    };
    let ray = ProximityVolume::Ray {
        offset: 0.005,
        range: 0.15,
    };
    let hull = ConvexPolyhedron::from_convex_hull(
        &(0..12)
            .map(|i| {
                let a = i as f32 * 2.4;
                let z = 1.0 - 2.0 * (i as f32 + 0.5) / 12.0;
                Vector::new((1.0 - z * z).sqrt() * a.cos(), (1.0 - z * z).sqrt() * a.sin(), z) * 0.03
            })
            .collect::<Vec<_>>(),
    )
    .expect("a 12-point hull");
    let ball = Ball::new(0.02);
    let cuboid = Cuboid::new(Vector::new(0.03, 0.02, 0.025));
    let cylinder = Cylinder::new(0.03, 0.02);
    let mesh = box_trimesh(Vector::new(0.03, 0.02, 0.025));

    // Ahead on the axis (mostly the fast path) and beside the cone (mostly the lateral
    // search), for each shape.
    let ahead = Vector::new(0.0, 0.0, 0.1);
    let beside = Vector::new(0.045, 0.0, 0.1);
    let cases: [(&str, &ProximityVolume, &dyn Shape, Vec<Pose>); 11] = [
        ("cone, ball ahead", &cone, &ball, poses(1, ahead, 0.01)),
        ("cone, ball beside", &cone, &ball, poses(2, beside, 0.01)),
        ("cone, cuboid ahead", &cone, &cuboid, poses(3, ahead, 0.01)),
        ("cone, cuboid beside", &cone, &cuboid, poses(4, beside, 0.01)),
        ("cone, cylinder beside", &cone, &cylinder, poses(5, beside, 0.01)),
        ("cone, hull ahead", &cone, &hull, poses(6, ahead, 0.01)),
        ("cone, hull beside", &cone, &hull, poses(7, beside, 0.01)),
        ("cone, box mesh beside", &cone, &mesh, poses(8, beside, 0.01)),
        (
            "cone, cylinder across the near cap",
            &cone,
            &cylinder,
            poses(9, Vector::new(0.0, 0.0, 0.0), 0.02),
        ),
        ("ray, cylinder ahead", &ray, &cylinder, poses(10, ahead, 0.015)),
        ("ray, hull ahead", &ray, &hull, poses(11, ahead, 0.015)),
    ];

    println!("| proximity detect | ns per call, median (min) | detected / 200 |");
    println!("|---|---|---|");
    for (name, volume, shape, poses) in &cases {
        let (ns, hits) = time(volume, *shape, poses);
        println!("| {name} | {ns} | {hits} |");
    }
}
