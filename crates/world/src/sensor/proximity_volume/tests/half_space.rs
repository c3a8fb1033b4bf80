//! Half-spaces in closed form, checked against the oracle.

use parry3d::math::{Pose, Rotation, Vector};
use parry3d::shape::HalfSpace;

use super::oracle::{assert_matches_oracle, check_hit, oracle};
use super::small_cone;

#[test]
fn half_space_floor() {
    // The floor is the world half-space y <= 0; `sensor_in_world` places the sensor.
    let vol = small_cone();
    let floor = HalfSpace::new(Vector::Y);
    let floor_pose = |height: f32, pitch_down_deg: f32| {
        let rot = Rotation::from_axis_angle(Vector::X, pitch_down_deg.to_radians());
        Pose::from_parts(Vector::new(0.0, height, 0.0), rot).inverse()
    };
    // 0.05 m above the floor, looking 20° down: the lowest rays dip 35°.
    let pose = floor_pose(0.05, 20.0);
    let hit = vol.detect(&floor, &pose).expect("floor in view");
    let expected = 0.05 / 35f32.to_radians().sin();
    assert!((hit.distance - expected).abs() <= 1.0e-6, "{hit:?} vs {expected}");
    check_hit(&vol, &floor, &pose, &hit);
    assert!((hit.normal - pose.rotation * Vector::Y).length() <= 1.0e-6);
    assert_matches_oracle(&vol, &floor, &pose);
    // Looking straight down from 0.1 m: fast path.
    let hit = vol.detect(&floor, &floor_pose(0.1, 90.0)).expect("floor below");
    assert!((hit.distance - 0.1).abs() <= 1.0e-6);
    // Looking up, or horizontally from too high: nothing.
    assert_eq!(vol.detect(&floor, &floor_pose(0.1, -90.0)), None);
    assert_eq!(vol.detect(&floor, &floor_pose(0.05, 0.0)), None);
    assert_eq!(oracle(&vol, &floor, &floor_pose(0.05, 0.0)), None);
    // Sensor below the floor surface (inside the solid): near cap.
    for pitch in [20.0, -20.0, 90.0, -90.0] {
        let pose = floor_pose(-0.01, pitch);
        let hit = vol.detect(&floor, &pose).expect("sensor inside the floor");
        assert!((hit.distance - 0.005).abs() <= 1.0e-6);
        check_hit(&vol, &floor, &pose, &hit);
    }
    // Sensor 2 mm under the surface looking up: the cap at 5 mm is above the floor.
    assert_eq!(vol.detect(&floor, &floor_pose(-0.002, -90.0)), None);
    // Floor 2 mm below the sensor: reached inside the dead zone, detected at the offset.
    let pose = floor_pose(0.002, 20.0);
    let hit = assert_matches_oracle(&vol, &floor, &pose).expect("floor crosses the cap");
    assert!((hit.distance - 0.005).abs() <= 1.0e-6);
}
