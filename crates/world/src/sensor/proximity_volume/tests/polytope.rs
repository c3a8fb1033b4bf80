//! The pyramid, cylinder and disc volumes: closed-form cases, and random boxes against a
//! brute-force oracle that samples the box's faces and keeps the points inside the volume.

use core::f32::consts::PI;

use parry3d::math::{Pose, Rotation, Vector};
use parry3d::shape::{Ball, Cuboid, HalfSpace};

use super::{Rng, box_trimesh};
use crate::sensor::proximity_volume::ProximityVolume;

fn at(x: f32, y: f32, z: f32) -> Pose {
    Pose::from_translation(Vector::new(x, y, z))
}

fn pyramid() -> ProximityVolume {
    ProximityVolume::Pyramid {
        offset: 0.02,
        range: 0.2,
        near_size: [0.02, 0.01],
        far_size: [0.2, 0.1],
    }
}

/// Exact membership in the pyramid above: `0.02 <= z <= 0.22`, half-widths growing linearly
/// from (0.01, 0.005) to (0.1, 0.05).
fn in_pyramid(p: Vector) -> bool {
    let t = (p.z - 0.02) / 0.2;
    let (hx, hy) = (0.01 + 0.09 * t, 0.005 + 0.045 * t);
    (-1.0e-6..=1.0 + 1.0e-6).contains(&t) && p.x.abs() <= hx + 1.0e-6 && p.y.abs() <= hy + 1.0e-6
}

#[test]
fn a_wall_facing_the_pyramid_is_seen_at_its_distance() {
    let vol = pyramid();
    let wall = Cuboid::new(Vector::new(0.5, 0.5, 0.01));
    let hit = vol
        .detect(&wall, &at(0.0, 0.0, 0.11))
        .expect("the wall crosses the volume");
    assert!((hit.distance - 0.1).abs() < 1.0e-6, "{hit:?}");
    assert!((hit.normal - -Vector::Z).length() < 1.0e-6, "{hit:?}");
    // The same wall as a mesh, and a floor (a half-space) at the same place.
    let mesh = box_trimesh(Vector::new(0.5, 0.5, 0.01));
    assert!((vol.detect(&mesh, &at(0.0, 0.0, 0.11)).unwrap().distance - 0.1).abs() < 1.0e-6);
    let floor = HalfSpace::new(Vector::Z);
    let below = Pose::from_parts(Vector::new(0.0, 0.0, 0.1), Rotation::from_rotation_x(PI));
    let hit = vol
        .detect(&floor, &below)
        .expect("the plane z = 0.1 crosses the volume");
    assert!((hit.distance - 0.1).abs() < 1.0e-6, "{hit:?}");
    // Nearer than the near face or beyond the far face: nothing.
    assert_eq!(vol.detect(&wall, &at(0.0, 0.0, 0.005)), None);
    assert_eq!(vol.detect(&wall, &at(0.0, 0.0, 0.24)), None);
}

#[test]
fn the_pyramid_sides_are_exact() {
    let vol = pyramid();
    // A thin post parallel to Z at x = 0.05: inside the volume from z = 0.02 + 0.2·(0.04/0.09).
    let post = Cuboid::new(Vector::new(0.001, 0.001, 0.3));
    let z0 = 0.02 + 0.2 * (0.049 - 0.01) / 0.09;
    let hit = vol
        .detect(&post, &at(0.05, 0.0, 0.3))
        .expect("the post enters through a side");
    let expected = (0.049f32 * 0.049 + z0 * z0).sqrt();
    assert!(
        (hit.distance - expected).abs() < 2.0e-6,
        "{} vs {expected}",
        hit.distance
    );
    // Along Y the pyramid is half as wide: the same post at y = 0.05 only enters at its far face.
    let hit = vol.detect(&post, &at(0.0, 0.05, 0.3)).expect("reaches the far corner");
    assert!(hit.point.z > 0.215, "{hit:?}");
    assert_eq!(vol.detect(&post, &at(0.0, 0.06, 0.3)), None);
}

#[test]
fn random_boxes_match_a_sampling_oracle() {
    let vol = pyramid();
    let mut rng = Rng(7);
    let mut seen = 0;
    for _ in 0..40 {
        let h = Vector::new(rng.range(0.005, 0.05), rng.range(0.005, 0.05), rng.range(0.005, 0.05));
        let pose = Pose::from_parts(
            Vector::new(rng.range(-0.1, 0.1), rng.range(-0.06, 0.06), rng.range(0.0, 0.25)),
            rng.rotation(),
        );
        let mesh = box_trimesh(h);
        let found = vol.detect(&mesh, &pose);
        let oracle = sampled_nearest(&mesh, &pose, 120);
        match (found, oracle) {
            (None, None) => {}
            (Some(hit), Some(o)) => {
                seen += 1;
                assert!(in_pyramid(hit.point), "{hit:?}");
                assert!((hit.point.length() - hit.distance).abs() < 1.0e-6);
                // The oracle samples, so it can only be farther, by at most a grid step.
                let step = 2.0 * h.max_element() / 120.0 * 1.5;
                assert!(
                    hit.distance <= o + 1.0e-6 && o - hit.distance <= step,
                    "{} vs {o}",
                    hit.distance
                );
            }
            // A sliver thinner than the grid may escape the oracle, never the detector.
            (Some(hit), None) => assert!(in_pyramid(hit.point), "{hit:?}"),
            (None, Some(o)) => panic!("the oracle saw a point at {o} m"),
        }
    }
    assert!(seen >= 10, "only {seen} random boxes reached the volume");
}

/// Nearest sampled point of the mesh's faces inside the pyramid, on an `n`-step grid.
fn sampled_nearest(mesh: &parry3d::shape::TriMesh, pose: &Pose, n: usize) -> Option<f32> {
    let mut best: Option<f32> = None;
    for tri in mesh.triangles() {
        let [a, b, c] = [tri.a, tri.b, tri.c].map(|v| pose.transform_point(v));
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
                let p = a + (b - a) * u + (c - a) * v;
                if in_pyramid(p) && best.is_none_or(|d| p.length() < d) {
                    best = Some(p.length());
                }
            }
        }
    }
    best
}

#[test]
fn the_cylinder_is_round_within_its_facets() {
    let vol = ProximityVolume::Cylinder {
        offset: 0.01,
        range: 0.2,
        radius: 0.05,
        radius_far: 0.05,
    };
    let post = Cuboid::new(Vector::new(0.001, 0.001, 0.3));
    // A post inside the radius in any direction is seen where it crosses the near face.
    for k in 0..12 {
        let a = k as f32 * PI / 6.0 + 0.1;
        let (s, c) = a.sin_cos();
        let hit = vol
            .detect(&post, &at(0.046 * c, 0.046 * s, 0.3))
            .expect("inside the radius");
        assert!((hit.point.z - 0.01).abs() < 1.0e-6, "{hit:?}");
        // ... and one outside it is not.
        assert_eq!(vol.detect(&post, &at(0.053 * c, 0.053 * s, 0.3)), None);
    }
    // A ball on the axis: its tessellated surface is within 0.5 % of its radius.
    let hit = vol.detect(&Ball::new(0.02), &at(0.0, 0.0, 0.1)).expect("on the axis");
    assert!((hit.distance - 0.08).abs() < 1.0e-4, "{hit:?}");
    // A widening cylinder reaches farther out at its far end.
    let cone = ProximityVolume::Cylinder {
        offset: 0.0,
        range: 0.2,
        radius: 0.01,
        radius_far: 0.1,
    };
    assert!(
        cone.detect(&post, &at(0.08, 0.0, 0.3))
            .is_some_and(|h| h.point.z > 0.15)
    );
    assert_eq!(cone.detect(&post, &at(0.08, 0.0, -0.16)), None);
}

#[test]
fn the_disc_sees_around_its_ring() {
    let ring = ProximityVolume::Disc {
        offset: 0.1,
        range: 0.2,
        half_angle: PI,
        thickness: 0.02,
    };
    let cube = Cuboid::new(Vector::splat(0.02));
    // In every direction of the XZ plane, a cube 0.2 m away facing the sensor is seen at 0.18 m.
    for k in 0..8 {
        let a = k as f32 * PI / 4.0 + 0.05;
        let (s, c) = a.sin_cos();
        let facing = Pose::from_parts(Vector::new(0.2 * s, 0.0, 0.2 * c), Rotation::from_rotation_y(a));
        let hit = ring
            .detect(&cube, &facing)
            .unwrap_or_else(|| panic!("{a} {facing:?} {:?}", ring.local_aabb()));
        assert!((hit.distance - 0.18).abs() < 1.0e-5, "{a}: {hit:?}");
    }
    // Above the disc's thickness, inside its inner radius, or beyond its outer one: nothing.
    assert_eq!(ring.detect(&cube, &at(0.0, 0.05, 0.2)), None);
    assert_eq!(ring.detect(&cube, &at(0.0, 0.0, 0.05)), None);
    assert_eq!(ring.detect(&cube, &at(0.0, 0.0, 0.35)), None);
    // A fan of 90° sees ahead but not sideways.
    let fan = ProximityVolume::Disc {
        offset: 0.0,
        range: 0.3,
        half_angle: PI / 4.0,
        thickness: 0.02,
    };
    assert!(fan.detect(&cube, &at(0.05, 0.0, 0.2)).is_some());
    assert_eq!(fan.detect(&cube, &at(0.2, 0.0, 0.0)), None);
    assert_eq!(fan.detect(&cube, &at(0.0, 0.0, -0.2)), None);
}

#[test]
fn bad_polytope_volumes_detect_nothing() {
    let cube = Cuboid::new(Vector::splat(1.0));
    for vol in [
        ProximityVolume::Pyramid {
            offset: 0.0,
            range: 0.0,
            near_size: [0.1, 0.1],
            far_size: [0.1, 0.1],
        },
        ProximityVolume::Cylinder {
            offset: 0.0,
            range: 1.0,
            radius: 0.0,
            radius_far: 0.0,
        },
        ProximityVolume::Disc {
            offset: 0.0,
            range: 1.0,
            half_angle: 4.0,
            thickness: 0.1,
        },
        ProximityVolume::Disc {
            offset: f32::NAN,
            range: 1.0,
            half_angle: 1.0,
            thickness: 0.1,
        },
    ] {
        assert!(!vol.is_valid(), "{vol:?}");
        assert_eq!(vol.detect(&cube, &Pose::IDENTITY), None);
    }
}

#[test]
fn polytope_boxes_bound_their_volumes() {
    let aabb = pyramid().local_aabb();
    assert!((aabb.maxs - Vector::new(0.1, 0.05, 0.22)).length() < 1.0e-6, "{aabb:?}");
    assert!(
        (aabb.mins - Vector::new(-0.1, -0.05, 0.02)).length() < 1.0e-6,
        "{aabb:?}"
    );
    let ring = ProximityVolume::Disc {
        offset: 0.1,
        range: 0.2,
        half_angle: PI,
        thickness: 0.02,
    }
    .local_aabb();
    assert!(
        (ring.maxs.x - 0.3).abs() < 1.0e-6 && (ring.mins.z + 0.3).abs() < 1.0e-6,
        "{ring:?}"
    );
    assert!((ring.maxs.y - 0.01).abs() < 1.0e-6, "{ring:?}");
}
