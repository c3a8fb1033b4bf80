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
//!
//! A state can also turn NaN inside one rapier step, between its internal substeps, and
//! rapier then panics (a joint-limit clamp of a NaN coordinate): mechanisms with tiny
//! links and no closed loop do that. [`World::step_rapier_contained`] catches it, stops
//! every mechanism whose state is no longer finite (all of them when none can be
//! found), and the simulator keeps running with the error in the log.

use std::panic::{AssertUnwindSafe, catch_unwind};

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

/// Stops a body where it is: no velocity, out of the simulation until re-enabled.
fn halt(rb: &mut RigidBody) {
    rb.set_linvel(Vector::ZERO, false);
    rb.set_angvel(Vector::ZERO, false);
    rb.set_enabled(false);
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
    /// One rapier step that cannot take the simulator down (see the module comment),
    /// followed by [`Self::contain_blow_ups`].
    pub(crate) fn step_rapier_contained(&mut self) {
        let physics = &mut self.physics_mut().world;
        if let Err(payload) = catch_unwind(AssertUnwindSafe(|| physics.step())) {
            let why = payload
                .downcast_ref::<&str>()
                .map(|s| (*s).to_owned())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown failure".to_owned());
            self.contain_engine_failure(&why);
        }
        self.contain_blow_ups();
    }

    /// Stops the mechanisms whose generalized coordinates or velocities are no longer
    /// finite after rapier failed inside a step; every dynamic body when none is found,
    /// since the failure's cause is then unknown.
    fn contain_engine_failure(&mut self, why: &str) {
        let physics = &mut self.physics_mut().world;
        let finite = |mb: &rapier3d::dynamics::Multibody| {
            mb.generalized_velocity().iter().all(|v| v.is_finite())
                && mb.links().all(|l| {
                    let c = l.joint().coords();
                    c.iter().all(|v| v.is_finite())
                })
        };
        let mut stopped: Vec<RigidBodyHandle> = physics
            .multibody_joints
            .multibodies()
            .filter(|mb| !finite(mb))
            .flat_map(|mb| mb.links().map(|l| l.rigid_body_handle()).collect::<Vec<_>>())
            .collect();
        let everything = stopped.is_empty();
        if everything {
            stopped = physics
                .bodies
                .iter()
                .filter(|(_, rb)| rb.is_dynamic())
                .map(|(h, _)| h)
                .collect();
        }
        for &b in &stopped {
            if let Some(rb) = physics.bodies.get_mut(b) {
                halt(rb);
            }
        }
        let t = self.time();
        let what = if everything {
            "every dynamic body was stopped".to_owned()
        } else {
            let mut names: Vec<String> = stopped
                .iter()
                .filter_map(|&b| self.body_owner(b))
                .map(|o| self.describe_object(o))
                .collect();
            names.truncate(8);
            format!("the mechanisms of {} were stopped", names.join(", "))
        };
        let msg = format!(
            "physics: the engine failed inside a step ({why}); {what} and the simulation goes on (a restart brings them back). Very light links (grams) on free joints with no closed loop are the usual cause."
        );
        self.log.push(t, 300, "physics", &msg);
        tracing::error!("{msg}");
    }

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
                    halt(rb);
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

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::scene::{EmbeddedFiles, LoadOptions, load_scene_text};

    /// An arm link on a position-controlled revolute joint with limits: rapier clamps
    /// the joint's velocity bound with the joint coordinate, and panics once it is NaN.
    const ARM: &str = r#"
[[object]]
name = "post"
kind = "shape"
shape = "box"
size = [0.1, 0.1, 1.0]
position = [0, 0, 0.5]

[[object]]
name = "shoulder"
kind = "joint"
joint = "revolute"
parent = "post"
position = [0, 0, 0.5]
orientation_deg = [90, 0, 0]
mode = "position"
limits = [-90, 90]

[[object]]
name = "link"
kind = "shape"
shape = "box"
size = [0.05, 0.5, 0.05]
parent = "shoulder"
position = [0, 0.25, 0]
dynamic = true
mass = 0.5
"#;

    #[test]
    fn a_failure_inside_rapier_stops_the_mechanism_and_the_world_keeps_stepping() {
        let model = load_scene_text(
            &EmbeddedFiles::default(),
            ARM,
            Path::new("/arm.toml"),
            &LoadOptions::default(),
        )
        .expect("scene");
        let mut world = World::new(&model);
        world.step_physics();
        // What an unstable mechanism reaches between two of rapier's substeps.
        let shoulder = world.find("/shoulder", None, 0).expect("shoulder");
        let joint = world.physics.joints[&shoulder].joint;
        let (mb, _) = world
            .physics_mut()
            .world
            .multibody_joints
            .get_mut(joint)
            .expect("the arm is a multibody");
        mb.generalized_velocity_mut().fill(f32::NAN);
        world.step_physics();
        world.step_physics();
        let log: Vec<&str> = world.log.lines().map(|l| l.message.as_str()).collect();
        assert!(
            log.iter()
                .any(|m| m.contains("the engine failed inside a step") || m.contains("NaN")),
            "{log:?}"
        );
        let link = world.find("/link", None, 0).expect("link");
        let pose = world.object(link).expect("object").world;
        assert!(pose.translation.x.is_finite() && pose.translation.z.is_finite());
    }
}
