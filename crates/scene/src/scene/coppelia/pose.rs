//! CoppeliaSim's poses as gantry's: the reader gives positions in metres and unit
//! quaternions as `[w, x, y, z]`, relative to the parent, as gantry's object tree wants.

use gantry_coppelia_file as cf;
use nalgebra::{Quaternion, Translation3, UnitQuaternion};

use crate::math::Pose;

/// The reader's pose (`[w, x, y, z]` quaternion) as gantry's.
pub(super) fn to_pose(p: &cf::Pose) -> Pose {
    let [w, x, y, z] = p.rotation;
    let [px, py, pz] = p.position;
    Pose::from_parts(
        Translation3::new(px, py, pz),
        UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z)),
    )
}
