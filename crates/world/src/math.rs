//! The scene's f64 math (poses, vectors, Euler angles and matrices, re-exported from
//! `gantry-scene`) and the conversions to and from rapier's f32 types, which only the
//! world and the floors above it need: the scene model knows no physics engine.

pub use gantry_scene::math::*;

/// Converts our f64 pose to rapier's f32 pose.
pub fn to_physics(p: &Pose) -> rapier3d::math::Pose {
    let q = p.rotation;
    let t = p.translation.vector;
    rapier3d::math::Pose::from_parts(
        rapier3d::glamx::Vec3::new(t.x as f32, t.y as f32, t.z as f32),
        rapier3d::glamx::Quat::from_xyzw(q.i as f32, q.j as f32, q.k as f32, q.w as f32).normalize(),
    )
}

/// Converts rapier's f32 pose to our f64 pose.
pub fn from_physics(p: &rapier3d::math::Pose) -> Pose {
    let q = p.rotation;
    let t = p.translation;
    nalgebra::Isometry3::from_parts(
        nalgebra::Translation3::new(f64::from(t.x), f64::from(t.y), f64::from(t.z)),
        nalgebra::UnitQuaternion::new_normalize(nalgebra::Quaternion::new(
            f64::from(q.w),
            f64::from(q.x),
            f64::from(q.y),
            f64::from(q.z),
        )),
    )
}

/// Converts our f64 vector to rapier's f32 vector.
pub fn vec_to_physics(v: &Vec3) -> rapier3d::math::Vector {
    rapier3d::math::Vector::new(v.x as f32, v.y as f32, v.z as f32)
}

/// Converts rapier's f32 vector to our f64 vector.
pub fn vec_from_physics(v: rapier3d::math::Vector) -> Vec3 {
    Vec3::new(f64::from(v.x), f64::from(v.y), f64::from(v.z))
}
