//! Run-time changes to settings the loader gave objects, for the functions PyRep calls
//! on a running scene: a joint's interval (`sim.setJointInterval`), a shape's friction
//! and restitution (the engine parameters `sim.bullet_body_friction` and kin), and the
//! bounding box of a whole model (`sim.objfloatparam_modelbbox_*`).

use super::edit::invalid;
use super::object::Handle;
use super::world::World;
use crate::error::SimError;
use crate::math::Vec3;
use crate::scene::JointType;

impl World {
    /// Sets a joint's interval (`sim.setJointInterval`): for a revolute joint, `cyclic`
    /// drops the limits and wraps its position into (-pi, pi]; otherwise (and always for
    /// a prismatic joint, which cannot be cyclic, as in CoppeliaSim) the limits become
    /// `min ..= min + range` (rad or m). The position is brought into the new interval,
    /// and a joint the physics simulates gets its new limits by having its subtree's
    /// physics rebuilt (their dynamics restart).
    ///
    /// # Errors
    /// No such object, not a joint, a fixed joint (which has no interval), or a
    /// non-finite minimum or a negative or non-finite range.
    pub fn set_joint_interval(&mut self, h: Handle, cyclic: bool, min: f64, range: f64) -> Result<(), SimError> {
        if !(min.is_finite() && range.is_finite() && range >= 0.0) {
            return Err(invalid(format!(
                "joint interval needs a finite minimum and a finite range >= 0, got min {min}, range {range}"
            )));
        }
        let j = self.joint_mut(h)?;
        match j.joint_type {
            JointType::Fixed => return Err(invalid(format!("joint {h} is fixed: it has no interval"))),
            JointType::Revolute if cyclic => {
                j.cyclic = true;
                j.limits = None;
            }
            JointType::Revolute | JointType::Prismatic => {
                j.cyclic = false;
                j.limits = Some((min, min + range));
            }
        }
        let position = j.position;
        if self.physics.joints.contains_key(&h) {
            self.rebuild_physics(&[h]);
        }
        self.set_joint_position(h, position)
    }

    /// Sets a shape's Coulomb friction coefficient (>= 0), at once for its colliders.
    ///
    /// # Errors
    /// No such object, not a shape, or a negative or non-finite coefficient.
    pub fn set_shape_friction(&mut self, h: Handle, friction: f64) -> Result<(), SimError> {
        if !(friction.is_finite() && friction >= 0.0) {
            return Err(invalid(format!(
                "friction must be a finite number >= 0, got {friction}"
            )));
        }
        self.shape_mut(h)?.friction = friction;
        for c in self.colliders_of(h).to_vec() {
            if let Some(col) = self.physics.world.colliders.get_mut(c) {
                col.set_friction(friction as f32);
            }
        }
        Ok(())
    }

    /// Sets a shape's restitution (0 ..= 1), at once for its colliders.
    ///
    /// # Errors
    /// No such object, not a shape, or a value outside 0 ..= 1.
    pub fn set_shape_restitution(&mut self, h: Handle, restitution: f64) -> Result<(), SimError> {
        if !(0.0..=1.0).contains(&restitution) {
            return Err(invalid(format!("restitution must be in 0..=1, got {restitution}")));
        }
        self.shape_mut(h)?.restitution = restitution;
        for c in self.colliders_of(h).to_vec() {
            if let Some(col) = self.physics.world.colliders.get_mut(c) {
                col.set_restitution(restitution as f32);
            }
        }
        Ok(())
    }

    /// The bounding box of `h` and everything below it, in `h`'s frame, `(min, max)` in
    /// m: the union of each object's [`World::bounding_box`] (a shape's geometry, a point
    /// at the origin of any other object), as CoppeliaSim's model bounding box.
    ///
    /// # Errors
    /// No such object.
    pub fn model_bounding_box(&self, h: Handle) -> Result<([f64; 3], [f64; 3]), SimError> {
        let base = self.object(h)?.world.inverse();
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for o in self.subtrees(&[h]) {
            let (a, b) = self.bounding_box(o)?;
            let to_base = base * self.objects[o as usize].world;
            // The 8 corners of the object's box, in the base frame.
            for k in 0..8 {
                let corner = Vec3::new(
                    if k & 1 == 0 { a[0] } else { b[0] },
                    if k & 2 == 0 { a[1] } else { b[1] },
                    if k & 4 == 0 { a[2] } else { b[2] },
                );
                let p = to_base * nalgebra::Point3::from(corner);
                for i in 0..3 {
                    lo[i] = lo[i].min(p[i]);
                    hi[i] = hi[i].max(p[i]);
                }
            }
        }
        Ok((lo, hi))
    }

    /// A shape's Coulomb friction coefficient.
    ///
    /// # Errors
    /// No such object, or not a shape.
    pub fn shape_friction(&self, h: Handle) -> Result<f64, SimError> {
        Ok(self.shape(h)?.friction)
    }

    /// A shape's restitution.
    ///
    /// # Errors
    /// No such object, or not a shape.
    pub fn shape_restitution(&self, h: Handle) -> Result<f64, SimError> {
        Ok(self.shape(h)?.restitution)
    }
}
