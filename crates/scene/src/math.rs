//! Poses, rotations and CoppeliaSim's conventions, in f64.
//!
//! gantry keeps every pose of the object tree in double precision (as CoppeliaSim 4.6
//! does) and converts to rapier's f32 glam types only at the physics boundary. Forward
//! kinematics of a kinematic chain is therefore exact to ~1e-15 m, whatever rapier's
//! precision.
//!
//! Conventions (all SI, radians):
//! - Euler angles are CoppeliaSim's `alpha, beta, gamma` with `R = Rx(alpha) Ry(beta) Rz(gamma)`.
//! - Quaternions cross the API as `[qx, qy, qz, qw]`; poses as `[x, y, z, qx, qy, qz, qw]`.
//! - Matrices cross the API as 12 numbers, row-major 3x4 `[Xx Yx Zx Px; Xy Yy Zy Py; Xz Yz Zz Pz]`.

use nalgebra::{Isometry3, Matrix3, Quaternion, Rotation3, Translation3, UnitQuaternion, Vector3};

/// A rigid transform in f64: rotation then translation.
pub type Pose = Isometry3<f64>;
/// A 3D vector in f64 (metres, or m/s, or rad/s depending on context).
pub type Vec3 = Vector3<f64>;
/// A unit quaternion in f64.
pub type Quat = UnitQuaternion<f64>;

/// Builds a pose from a translation (m) and CoppeliaSim Euler angles (rad).
pub fn pose_from_euler(position: [f64; 3], euler: [f64; 3]) -> Pose {
    Isometry3::from_parts(
        Translation3::new(position[0], position[1], position[2]),
        quat_from_euler(euler),
    )
}

/// CoppeliaSim Euler angles (rad) to a quaternion: `R = Rx(a) Ry(b) Rz(g)`.
pub fn quat_from_euler([a, b, g]: [f64; 3]) -> Quat {
    UnitQuaternion::from_axis_angle(&Vector3::x_axis(), a)
        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), b)
        * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), g)
}

/// A quaternion to CoppeliaSim Euler angles (rad), with CoppeliaSim's gimbal-lock rule.
pub fn euler_from_quat(q: &Quat) -> [f64; 3] {
    let r = q.to_rotation_matrix();
    let m = r.matrix();
    let s = m[(0, 2)].clamp(-1.0, 1.0);
    // CoppeliaSim treats |R02| >= 0.999995 as gimbal lock: alpha = 0 and gamma carries
    // the whole remaining rotation about the (aligned) x/z axes.
    if s.abs() >= 0.999995 {
        let beta = if s > 0.0 {
            std::f64::consts::FRAC_PI_2
        } else {
            -std::f64::consts::FRAC_PI_2
        };
        [0.0, beta, m[(1, 0)].atan2(m[(1, 1)])]
    } else {
        [(-m[(1, 2)]).atan2(m[(2, 2)]), s.asin(), (-m[(0, 1)]).atan2(m[(0, 0)])]
    }
}

/// A quaternion as the API's `[qx, qy, qz, qw]`.
pub fn quat_to_array(q: &Quat) -> [f64; 4] {
    [q.i, q.j, q.k, q.w]
}

/// The API's `[qx, qy, qz, qw]` as a unit quaternion, or `None` for a zero or
/// non-finite quaternion (normalised otherwise, as CoppeliaSim does).
pub fn quat_from_array([x, y, z, w]: [f64; 4]) -> Option<Quat> {
    let q = Quaternion::new(w, x, y, z);
    let n = q.norm();
    if !n.is_finite() || n < 1e-12 {
        return None;
    }
    Some(UnitQuaternion::new_normalize(q))
}

/// A pose as the API's 12-number row-major 3x4 matrix.
pub fn pose_to_matrix12(p: &Pose) -> [f64; 12] {
    let r = p.rotation.to_rotation_matrix();
    let m = r.matrix();
    let t = p.translation.vector;
    [
        m[(0, 0)],
        m[(0, 1)],
        m[(0, 2)],
        t.x,
        m[(1, 0)],
        m[(1, 1)],
        m[(1, 2)],
        t.y,
        m[(2, 0)],
        m[(2, 1)],
        m[(2, 2)],
        t.z,
    ]
}

/// The API's 12-number matrix as a pose (the rotation part is re-orthonormalised).
pub fn pose_from_matrix12(m: &[f64; 12]) -> Option<Pose> {
    if m.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let rot = Matrix3::new(m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]);
    // The closed-form (trace) conversion: bounded work whatever the numbers. nalgebra's
    // `Rotation3::from_matrix` iterates until it converges, and on a reflection such
    // as -I it never does, which froze the simulation thread in `sim.setObjectMatrix`.
    // A rotation block gives its own quaternion, anything else some rotation.
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(rot)).into_inner();
    let q = quat_from_array([q.i, q.j, q.k, q.w])?;
    Some(Isometry3::from_parts(Translation3::new(m[3], m[7], m[11]), q))
}

/// The rotation that takes the local +Z axis onto `axis` (unit), choosing a rotation
/// about X for the antiparallel case so that the result is deterministic.
pub fn rotation_z_to(axis: &Vec3) -> Quat {
    let z = Vector3::z();
    UnitQuaternion::rotation_between(&z, axis)
        .unwrap_or_else(|| UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI))
}

/// A joint position as CoppeliaSim's `setJointPosition` takes it: a cyclic joint's
/// wrapped into (-pi, pi], any other clamped to its `(min, max)` limits when it has
/// some. The scene and the IK solver both constrain with this, so the solver never
/// works with a value the scene would not take.
pub fn constrain_joint(q: f64, cyclic: bool, limits: Option<(f64, f64)>) -> f64 {
    if cyclic {
        wrap_angle(q)
    } else if let Some((lo, hi)) = limits {
        q.clamp(lo, hi)
    } else {
        q
    }
}

/// Wraps an angle into CoppeliaSim's cyclic range (-pi, pi]. Angles already in range
/// are returned unchanged, bit for bit (a round trip through atan2 would not be).
pub fn wrap_angle(a: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    if a > -PI && a <= PI {
        return a;
    }
    if !a.is_finite() {
        return a;
    }
    let w = (a + PI).rem_euclid(TAU) - PI;
    // rem_euclid yields [-pi, pi); CoppeliaSim's range excludes -pi.
    if w <= -PI { PI } else { w }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn matrix_conversion_ends_on_any_block_and_keeps_rotations() {
        // A reflection (-I) made nalgebra's iterative orthonormalisation loop forever.
        let reflection = [-1.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0, 2.0, 0.0, 0.0, -1.0, 3.0];
        let p = pose_from_matrix12(&reflection).expect("some pose");
        assert_eq!(p.translation.vector, Vec3::new(1.0, 2.0, 3.0));
        // A rotation round-trips.
        let q = quat_from_euler([0.3, -1.2, 2.9]);
        let m = pose_to_matrix12(&Isometry3::from_parts(Translation3::new(0.1, 0.2, 0.3), q));
        let back = pose_from_matrix12(&m).expect("a pose");
        assert!(back.rotation.angle_to(&q) < 1e-12);
    }

    #[test]
    fn euler_round_trip_matches_coppeliasim_convention() {
        // R = Rx(a) Ry(b) Rz(g): rotating +X by gamma about z first.
        let e = [0.3, -0.4, 1.1];
        let back = euler_from_quat(&quat_from_euler(e));
        for i in 0..3 {
            assert!((e[i] - back[i]).abs() < 1e-12, "{e:?} vs {back:?}");
        }
        // Pure alpha rotates +Y towards +Z.
        let q = quat_from_euler([FRAC_PI_2, 0.0, 0.0]);
        let y = q * Vector3::y();
        assert!((y - Vector3::z()).norm() < 1e-12);
    }

    #[test]
    fn gimbal_lock_puts_everything_in_gamma() {
        let e = euler_from_quat(&quat_from_euler([0.2, FRAC_PI_2, 0.5]));
        assert_eq!(e[0], 0.0);
        assert!((e[1] - FRAC_PI_2).abs() < 1e-9);
        // Same rotation recovered.
        let q1 = quat_from_euler([0.2, FRAC_PI_2, 0.5]);
        let q2 = quat_from_euler(e);
        assert!(q1.angle_to(&q2) < 1e-6);
    }

    #[test]
    fn matrix_round_trip_and_layout() {
        let p = pose_from_euler([1.0, 2.0, 3.0], [0.1, 0.2, 0.3]);
        let m = pose_to_matrix12(&p);
        assert_eq!([m[3], m[7], m[11]], [1.0, 2.0, 3.0]);
        let back = pose_from_matrix12(&m).expect("finite");
        assert!((back.translation.vector - p.translation.vector).norm() < 1e-12);
        assert!(back.rotation.angle_to(&p.rotation) < 1e-12);
    }

    #[test]
    fn wrap_is_half_open() {
        assert!((wrap_angle(-std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-15);
        assert!((wrap_angle(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
        assert!((wrap_angle(0.5) - 0.5).abs() < 1e-15);
    }

    #[test]
    fn z_to_axis() {
        for axis in [Vector3::x(), -Vector3::y(), -Vector3::z(), Vector3::z()] {
            let q = rotation_z_to(&axis);
            assert!((q * Vector3::z() - axis).norm() < 1e-12);
        }
    }
}
