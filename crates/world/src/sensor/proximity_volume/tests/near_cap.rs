//! Obstacles closer than the offset: the near cap.

use parry3d::math::{Pose, Rotation, Vector};
use parry3d::shape::{Ball, Cuboid};

use super::oracle::{assert_matches_oracle, oracle};
use super::small_cone;
use crate::sensor::proximity_volume::ProximityVolume;

#[test]
fn closer_than_offset() {
    let vol = small_cone();
    // A thick wall starting 2 mm ahead: the volume starts inside it, at the near cap.
    let wall = Cuboid::new(Vector::new(0.1, 0.1, 0.02));
    let pose = Pose::translation(0.0, 0.0, 0.022);
    let hit = assert_matches_oracle(&vol, &wall, &pose).expect("wall fills the near cap");
    assert!((hit.distance - 0.005).abs() <= 1.0e-6);
    assert!((hit.normal + hit.point / hit.distance).length() <= 1.0e-5);
    // A thin plate entirely inside the dead zone: 1 mm thick at 2–3 mm. Its points in
    // the cone are at most 3 mm / cos 15° = 3.1 mm < 5 mm away.
    let plate = Cuboid::new(Vector::new(0.1, 0.1, 0.0005));
    let pose = Pose::translation(0.0, 0.0, 0.0025);
    assert_eq!(vol.detect(&plate, &pose), None);
    assert_eq!(oracle(&vol, &plate, &pose), None);
    // The same plate tilted by 80°: it now extends beyond the near cap inside the cone.
    let pose = Pose::from_parts(
        Vector::new(0.0, 0.0, 0.0025),
        Rotation::from_axis_angle(Vector::X, 80f32.to_radians()),
    );
    assert_matches_oracle(&vol, &plate, &pose).expect("tilted plate crosses the near cap");
    // A ball containing the sensor.
    let ball = Ball::new(0.05);
    let pose = Pose::translation(0.01, 0.0, 0.0);
    let hit = assert_matches_oracle(&vol, &ball, &pose).expect("sensor inside a ball");
    assert!((hit.distance - 0.005).abs() <= 1.0e-6);
    // A small ball partly inside the dead zone, off axis (lateral minimum below offset).
    let ball = Ball::new(0.003);
    for c in [
        Vector::new(0.003, 0.0, 0.004),
        Vector::new(0.0, 0.0, 0.004),
        Vector::new(0.0025, 0.001, 0.0035),
    ] {
        assert_matches_oracle(&vol, &ball, &Pose::from_translation(c));
    }
    // Offset zero and the sensor inside a solid: distance zero.
    let vol0 = ProximityVolume::Cone {
        offset: 0.0,
        range: 0.15,
        half_angle: 0.2,
    };
    let hit = vol0.detect(&Ball::new(0.05), &Pose::IDENTITY).expect("inside");
    assert_eq!(hit.distance, 0.0);
}
