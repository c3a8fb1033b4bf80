//! Containment of physics blow-ups: a body whose state turned non-finite or ran away is
//! stopped and reported, and the rest of the world keeps stepping.
//!
//! rapier already quarantines bodies whose pose or velocity became NaN or infinite
//! (disabled, rolled back to their last valid pose; `PhysicsWorld::quarantine`). A body
//! can also blow up while staying finite: an unstable joint gain or a teleport to an
//! absurd place sends it off at hundreds of metres per second. Both end the same way
//! here: the body (with every link of its multibody, since a mechanism cannot keep
//! running with one link frozen) is disabled with zero velocity, and the simulation log
//! says which object, why, and how to recover (`sim.setObjectPosition` re-enables it).

use rapier3d::prelude::*;

use super::object::Handle;
use super::world::World;

/// Faster than any robot part moves (a bullet is ~400 m/s), m/s.
const MAX_LINEAR_SPEED: f32 = 300.0;
/// About 95,000 rpm: beyond any motor, rad/s.
const MAX_ANGULAR_SPEED: f32 = 1.0e4;
/// Farther from the origin than any lab scene, m.
const MAX_DISTANCE: f32 = 1.0e5;

/// Why a body was stopped.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Fault {
    NonFinite,
    Speed(f32),
    Spin(f32),
    Distance(f32),
}

impl Fault {
    fn describe(self) -> String {
        match self {
            Fault::NonFinite => "its pose or velocity became NaN or infinite".to_owned(),
            Fault::Speed(v) => format!("it moved at {v:.3e} m/s (limit {MAX_LINEAR_SPEED} m/s)"),
            Fault::Spin(w) => format!("it spun at {w:.3e} rad/s (limit {MAX_ANGULAR_SPEED:.0} rad/s)"),
            Fault::Distance(d) => format!("it went {d:.3e} m from the origin (limit {MAX_DISTANCE:.0} m)"),
        }
    }
}

fn check(rb: &RigidBody) -> Option<Fault> {
    let (p, v, w) = (rb.translation(), rb.linvel(), rb.angvel());
    if !(p.is_finite() && v.is_finite() && w.is_finite() && rb.rotation().is_finite()) {
        return Some(Fault::NonFinite);
    }
    if v.length() > MAX_LINEAR_SPEED {
        return Some(Fault::Speed(v.length()));
    }
    if w.length() > MAX_ANGULAR_SPEED {
        return Some(Fault::Spin(w.length()));
    }
    if p.length() > MAX_DISTANCE {
        return Some(Fault::Distance(p.length()));
    }
    None
}

impl World {
    /// Stops and reports every body that blew up in the last physics step. Called after
    /// each rapier step, before the tree reads poses back.
    pub(crate) fn contain_blow_ups(&mut self) {
        let physics = &mut self.physics_mut().world;
        let mut faults: Vec<(RigidBodyHandle, Fault)> = physics
            .quarantine()
            .bodies()
            .iter()
            .map(|&h| (h, Fault::NonFinite))
            .collect();
        for (h, rb) in physics.bodies.iter() {
            if rb.is_dynamic()
                && rb.is_enabled()
                && let Some(f) = check(rb)
            {
                faults.push((h, f));
            }
        }
        if faults.is_empty() {
            return;
        }
        let mut reports = Vec::new();
        for (h, fault) in faults {
            // The whole mechanism stops: a multibody with one frozen link is no robot.
            let mut group = vec![h];
            if let Some(link) = physics.multibody_joints.rigid_body_link(h).copied()
                && let Some(mb) = physics.multibody_joints.get_multibody(link.multibody)
            {
                group = mb.links().map(|l| l.rigid_body_handle()).collect();
            }
            let mut newly_stopped = false;
            for b in group {
                if let Some(rb) = physics.bodies.get_mut(b) {
                    // Quarantined bodies are already disabled (and rolled back) by rapier.
                    newly_stopped |= rb.is_enabled() || b == h;
                    rb.set_linvel(Vector::ZERO, false);
                    rb.set_angvel(Vector::ZERO, false);
                    rb.set_enabled(false);
                }
            }
            if newly_stopped {
                reports.push((h, fault));
            }
        }
        let t = self.time();
        for (h, fault) in reports {
            let name = self
                .body_owner(h)
                .map_or_else(|| "a body".to_owned(), |o| self.describe_object(o));
            let msg = format!(
                "physics: {name} was stopped because {}; it and its mechanism are disabled and the rest of the world keeps stepping (sim.setObjectPosition or a restart brings it back)",
                fault.describe()
            );
            self.log.push(t, 300, "physics", &msg);
        }
    }

    fn describe_object(&self, h: Handle) -> String {
        match self.object(h) {
            Ok(o) => format!("'{}' (handle {h})", o.alias),
            Err(_) => format!("object {h}"),
        }
    }
}
