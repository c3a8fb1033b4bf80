//! `cargo bench -p gantry-sim-core --bench proximity`: nanoseconds per
//! `ProximityVolume::detect` call (the exact ray and cone volumes of
//! `gantry_sim_core::sensor`) on the paths the module documentation prices: the fast path
//! (one point projection), the lateral search on the cone's surface, the near cap, a mesh and
//! the ray.
//!
//! Prints one Markdown table. Each row times 200 fixed random poses (sensor frame, metres),
//! repeated; figures are the median and minimum over 31 rounds of the mean per call. On a
//! busy machine the minimum is the steadier figure for comparing two versions.

use std::f32::consts::TAU;
use std::hint::black_box;
use std::time::Instant;

use gantry_sim_core::sensor::ProximityVolume;
use parry3d::math::{Pose, Rotation, Vector};
use parry3d::shape::{Ball, ConvexPolyhedron, Cuboid, Cylinder, Shape, TriMesh};

/// Tiny deterministic xorshift generator, so that both versions time the same poses.
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

/// A closed box mesh of half-extents `h` (m): 12 triangles.
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
