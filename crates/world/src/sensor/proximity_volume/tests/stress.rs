//! The long randomised comparison with the oracle (ignored by default).

use parry3d::math::{Pose, Vector};
use parry3d::shape::{Ball, Capsule, Cone, Cuboid, Cylinder, RoundShape, Shape, Triangle};

use super::oracle::{check_hit, oracle};
use super::{Rng, TOL, fibonacci_hull};
use crate::sensor::proximity_volume::ProximityVolume;

/// Long randomized comparison with the oracle over every convex shape type, cone shapes
/// and offsets (including large offsets, to exercise the near cap). Run with
/// `cargo test --release -- --ignored stress`.
#[test]
#[ignore = "slow: thousands of oracle evaluations"]
fn stress_against_oracle() {
    let mut rng = Rng(0x5eed);
    let hull = fibonacci_hull();
    let (mut cases, mut detected, mut cap_misses, mut oracle_misses) = (0, 0, 0, 0);
    let mut worst: f32 = 0.0;
    let mut cap_hits = 0;
    for i in 0..1500 {
        let half_angle = rng.range(3.0, 60.0).to_radians();
        let offset = if i % 3 == 0 {
            rng.range(0.02, 0.08)
        } else {
            rng.range(0.0, 0.01)
        };
        let vol = ProximityVolume::Cone {
            offset,
            range: rng.range(0.05, 0.4),
            half_angle,
        };
        let shape: Box<dyn Shape> = match i % 8 {
            0 => Box::new(Ball::new(rng.range(0.003, 0.06))),
            1 => Box::new(Cuboid::new(Vector::new(
                rng.range(0.002, 0.06),
                rng.range(0.002, 0.06),
                rng.range(0.002, 0.06),
            ))),
            2 => Box::new(Cylinder::new(rng.range(0.003, 0.06), rng.range(0.003, 0.06))),
            3 => Box::new(Capsule::new_x(rng.range(0.003, 0.06), rng.range(0.001, 0.03))),
            4 => Box::new(Cone::new(rng.range(0.003, 0.06), rng.range(0.003, 0.06))),
            5 => Box::new(hull.clone()),
            6 => Box::new(Triangle::new(
                Vector::new(rng.range(-0.05, 0.05), rng.range(-0.05, 0.05), rng.range(-0.05, 0.05)),
                Vector::new(rng.range(-0.05, 0.05), rng.range(-0.05, 0.05), rng.range(-0.05, 0.05)),
                Vector::new(rng.range(-0.05, 0.05), rng.range(-0.05, 0.05), rng.range(-0.05, 0.05)),
            )),
            _ => Box::new(RoundShape {
                inner_shape: Cuboid::new(Vector::new(
                    rng.range(0.002, 0.04),
                    rng.range(0.002, 0.04),
                    rng.range(0.002, 0.04),
                )),
                border_radius: rng.range(0.001, 0.01),
            }),
        };
        // One case in three (those with a large offset) is placed around the near cap.
        let (reach, z_min, z_max) = if i % 3 == 0 {
            (0.05, -0.02, offset + 0.05)
        } else {
            (0.15, -0.05, 0.3)
        };
        let pose = Pose::from_parts(
            Vector::new(
                rng.range(-reach, reach),
                rng.range(-reach, reach),
                rng.range(z_min, z_max),
            ),
            rng.rotation(),
        );
        cases += 1;
        let hit = vol.detect(shape.as_ref(), &pose);
        let expected = oracle(&vol, shape.as_ref(), &pose);
        match (hit, expected) {
            (None, None) => {}
            (Some(h), Some(e)) => {
                detected += 1;
                // The detection is a genuine point of the shape in the volume (so it is
                // >= the exact minimum) and no oracle sample, all feasible, beats it.
                check_hit(&vol, shape.as_ref(), &pose, &h);
                // The oracle accepts points within 1e-7 m of the surface, i.e. up to
                // 1e-7 / cos(incidence) m early along its rays at grazing incidence.
                let incidence = h.normal.dot(-h.point.normalize_or(Vector::Z)).max(0.01);
                assert!(
                    h.distance <= e + 2.0e-6 + 1.0e-7 / incidence,
                    "case {i} {:?}: detector {h:?} vs oracle {e} for {vol:?} {pose:?}",
                    shape.shape_type()
                );
                if h.distance < e - TOL {
                    // The oracle's search stalled on a vertex or an edge.
                    oracle_misses += 1;
                } else {
                    worst = worst.max((h.distance - e).abs());
                }
                if (h.distance - offset).abs() <= 1.0e-6 {
                    cap_hits += 1;
                }
            }
            (None, Some(e)) if (e - offset).abs() <= TOL && matches!(i % 8, 2 | 3 | 4 | 7) => {
                // The documented limitation: smooth solids barely reaching past the near cap.
                cap_misses += 1;
                eprintln!("near-cap miss: case {i} {:?} {vol:?} {pose:?}", shape.shape_type());
            }
            (Some(h), None) => {
                // The oracle's grid can miss a sliver of contact; the detection must still
                // be a genuine point of the shape in the volume.
                check_hit(&vol, shape.as_ref(), &pose, &h);
                oracle_misses += 1;
            }
            (h, e) => panic!(
                "case {i} {:?}: detector {h:?} vs oracle {e:?} for {vol:?} {pose:?}",
                shape.shape_type()
            ),
        }
    }
    eprintln!(
        "stress: {cases} cases, {detected} detections ({cap_hits} on the near cap), \
         {cap_misses} near-cap misses, \
         {oracle_misses} where the oracle's search fell short, worst distance difference \
         {worst:e} m otherwise"
    );
}
