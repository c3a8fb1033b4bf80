//! The contacts of the last physics step (`sim.getContactInfo`), read from rapier's
//! narrow phase.

use rapier3d::prelude::PairContacts;

use super::object::Handle;
use super::world::World;
use crate::math::Vec3;

/// `sim.handle_all`: contacts between any objects.
const HANDLE_ALL: Handle = -2;

/// One contact point of the last step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// The two objects in contact.
    pub objects: [Handle; 2],
    /// The contact point in the world frame, m (on the first object's surface).
    pub point: Vec3,
    /// The force the contact applied to the first object over the step, N, world frame.
    pub force: Vec3,
    /// The contact normal in the world frame, from the first object to the second.
    pub normal: Vec3,
}

fn v64(v: rapier3d::math::Vector) -> Vec3 {
    Vec3::new(f64::from(v.x), f64::from(v.y), f64::from(v.z))
}

impl World {
    /// The touching contact points of the last step that involve `h` (any object for
    /// `sim.handle_all`), pair by pair and point by point in rapier's order. Pairs with
    /// a collider gantry does not map to an object (none in practice) are left out.
    pub fn contacts(&self, h: Handle) -> Vec<Contact> {
        let w = &self.physics.world;
        let ip = &w.integration_parameters;
        // A contact's impulse sums the substeps of rapier's step (unlike a joint's,
        // which is the last substep's), so the step's force is impulse / dt.
        let per_second = if ip.dt > 0.0 { 1.0 / f64::from(ip.dt) } else { 0.0 };
        let mut out = Vec::new();
        for pair in w.narrow_phase.contact_pairs() {
            let (Some(&o1), Some(&o2)) = (
                self.physics.collider_object.get(&pair.collider1),
                self.physics.collider_object.get(&pair.collider2),
            ) else {
                continue;
            };
            if h != HANDLE_ALL && o1 != h && o2 != h {
                continue;
            }
            let PairContacts::Rigid(rigid) = &pair.contacts else {
                continue;
            };
            let Some(c1) = w.colliders.get(pair.collider1) else {
                continue;
            };
            for m in &rigid.manifolds {
                let normal = v64(m.data.normal);
                for p in m.points.iter().filter(|p| p.dist <= 0.0) {
                    let point = v64(c1.position().transform_point(p.local_p1));
                    // The impulse pushes the second object along the normal; the first
                    // feels the opposite.
                    let force = -normal * f64::from(p.data.impulse) * per_second;
                    out.push(Contact {
                        objects: [o1, o2],
                        point,
                        force,
                        normal,
                    });
                }
            }
        }
        out
    }
}
