//! Surfaces and unions: triangle meshes, compounds and height fields.

use parry3d::math::{Pose, Rotation, Vector};
use parry3d::query::PointQuery;
use parry3d::shape::{Compound, Cuboid, HalfSpace, HeightField, SharedShape};
use parry3d::utils::Array2;

use super::oracle::check_hit;
use super::{Rng, TOL, box_trimesh, cone_params, small_cone};
use crate::sensor::proximity_volume::{ProximityHit, ProximityVolume, keep_nearest};

#[test]
fn trimesh_box_equals_cuboid() {
    let vol = small_cone();
    let h = Vector::new(0.03, 0.02, 0.025);
    let cuboid = Cuboid::new(h);
    let mesh = box_trimesh(h);
    let mut rng = Rng(0xdead_beef);
    let mut lateral = 0;
    for i in 0..24 {
        let pose = Pose::from_parts(
            Vector::new(rng.range(-0.06, 0.06), rng.range(-0.06, 0.06), rng.range(0.05, 0.15)),
            rng.rotation(),
        );
        let a = vol.detect(&cuboid, &pose);
        let b = vol.detect(&mesh, &pose);
        match (a, b) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                assert!(
                    (a.distance - b.distance).abs() <= TOL,
                    "case {i}: cuboid {a:?} mesh {b:?}"
                );
                check_hit(&vol, &mesh, &pose, &b);
                if !cuboid_fast_path(&vol, &cuboid, &pose) {
                    lateral += 1;
                }
            }
            (a, b) => panic!("case {i}: cuboid {a:?} mesh {b:?}"),
        }
    }
    assert!(lateral > 0, "the random poses should exercise the lateral path");
}

fn cuboid_fast_path(vol: &ProximityVolume, cuboid: &Cuboid, pose: &Pose) -> bool {
    let (_, _, alpha) = cone_params(vol);
    let p = cuboid.project_point(pose, Vector::ZERO, true).point;
    (p.z / p.length()).acos() <= alpha
}

#[test]
fn compound_is_the_nearest_part() {
    let vol = small_cone();
    let parts = vec![
        (Pose::translation(0.0, 0.0, 0.05), SharedShape::ball(0.01)),
        (
            Pose::from_parts(Vector::new(0.03, 0.0, 0.0), Rotation::from_axis_angle(Vector::Z, 0.4)),
            SharedShape::cuboid(0.01, 0.02, 0.01),
        ),
    ];
    let compound = Compound::new(parts.clone());
    let mut rng = Rng(42);
    for _ in 0..10 {
        let pose = Pose::from_parts(
            Vector::new(rng.range(-0.04, 0.04), rng.range(-0.04, 0.04), rng.range(0.02, 0.1)),
            rng.rotation(),
        );
        let whole = vol.detect(&compound, &pose);
        let mut best: Option<ProximityHit> = None;
        for (rel, part) in &parts {
            let h = vol.detect(part.as_ref(), &(pose * *rel));
            if let Some(h) = h {
                check_hit(&vol, part.as_ref(), &(pose * *rel), &h);
            }
            keep_nearest(&mut best, h);
        }
        assert_eq!(whole.map(|h| h.distance), best.map(|h| h.distance));
    }
}

#[test]
fn height_field_matches_half_space() {
    // A flat 2 m × 2 m height field (surface y = 0) and the floor half-space y <= 0, seen
    // from 0.05 m above, looking 20° down: a height field is a surface, but seen from above
    // it is detected like the solid floor.
    let vol = small_cone();
    let heights = Array2::repeat(5, 5, 0.0);
    let hf = HeightField::new(heights, Vector::new(2.0, 1.0, 2.0));
    let floor = HalfSpace::new(Vector::Y);
    for (height, pitch) in [(0.05f32, 20.0f32), (0.05, 90.0), (0.03, 45.0), (0.05, 0.0)] {
        let rot = Rotation::from_axis_angle(Vector::X, pitch.to_radians());
        let pose = Pose::from_parts(Vector::new(0.1, height, -0.2), rot).inverse();
        let a = vol.detect(&hf, &pose);
        let b = vol.detect(&floor, &pose);
        assert_eq!(a.is_some(), b.is_some(), "{a:?} vs {b:?}");
        if let (Some(a), Some(b)) = (a, b) {
            assert!((a.distance - b.distance).abs() <= 1.0e-6, "{a:?} vs {b:?}");
            assert!((a.normal - b.normal).length() <= 1.0e-5, "{a:?} vs {b:?}");
            check_hit(&vol, &hf, &pose, &a);
        }
    }
}
