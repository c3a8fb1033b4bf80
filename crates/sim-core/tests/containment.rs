//! A body that blows up (non-finite state, a runaway speed, an absurd place) is stopped
//! and reported, and the rest of the world keeps stepping normally.

use crate::util;

use gantry_sim_core::api::{CallContext, call};
use gantry_sim_core::{Handle, Sim, Value};
use util::{find, step};

/// A floor, a box resting on it, a free ball, and an arm link on a velocity-servoed joint
/// strong enough to spin it up without bound.
const SCENE: &str = r#"
[simulation]
dt = 0.05

[floor]

[[object]]
name = "box"
kind = "shape"
shape = "box"
size = [0.2, 0.2, 0.2]
position = [2, 0, 0.1]
dynamic = true
mass = 1.0

[[object]]
name = "ball"
kind = "shape"
shape = "sphere"
radius = 0.05
position = [-2, 0, 0.5]
dynamic = true
mass = 0.5

[[object]]
name = "post"
kind = "shape"
shape = "box"
size = [0.1, 0.1, 1.0]
position = [0, 2, 0.5]

[[object]]
name = "shoulder"
kind = "joint"
joint = "revolute"
parent = "post"
position = [0, 0, 0.5]
orientation_deg = [90, 0, 0]
mode = "velocity"
kd = 1e9
max_force = 1e30

[[object]]
name = "link"
kind = "shape"
shape = "box"
size = [0.05, 0.5, 0.05]
parent = "shoulder"
position = [0, 0.25, 0]
dynamic = true
mass = 0.01
"#;

fn world() -> Sim {
    util::text_scene("tests/containment.toml", SCENE)
}

fn z(w: &Sim, h: Handle) -> f64 {
    w.world.object(h).expect("object").world.translation.z
}

fn physics_log(w: &Sim) -> Vec<String> {
    w.world
        .log
        .lines()
        .filter(|l| l.source == "physics")
        .map(|l| l.message.clone())
        .collect()
}

fn every_pose_is_finite(w: &Sim) -> bool {
    w.world.handles().iter().all(|&h| {
        let p = w.world.object(h).expect("object").world;
        p.translation.vector.iter().all(|v| v.is_finite()) && p.rotation.coords.iter().all(|v| v.is_finite())
    })
}

#[test]
fn a_runaway_joint_is_stopped_and_reported_and_the_rest_keeps_stepping() {
    let mut w = world();
    let (shoulder, ball, boxed) = (find(&w, "/shoulder"), find(&w, "/ball"), find(&w, "/box"));
    // Finite, so the API accepts it; no mechanism survives it.
    w.world.set_joint_target_velocity(shoulder, 1e12).expect("target");
    step(&mut w, 40);
    let log = physics_log(&w);
    assert!(
        log.iter()
            .any(|m| m.contains("'link'") && m.contains("was stopped because")),
        "the blow-up is reported naming the link: {log:?}"
    );
    assert_eq!(log.len(), 1, "reported once, not at every step: {log:?}");
    assert!(every_pose_is_finite(&w), "no NaN reaches the object tree");
    assert!(w.world.joint(shoulder).expect("joint").position.is_finite());
    // Everything else kept stepping: the ball fell onto the floor, the box rests.
    assert!((z(&w, ball) - 0.05).abs() < 0.01, "ball at {}", z(&w, ball));
    assert!((z(&w, boxed) - 0.1).abs() < 0.01, "box at {}", z(&w, boxed));
    assert!((w.world.time() - 2.0).abs() < 1e-9);
}

#[test]
fn a_body_sent_absurdly_far_is_stopped_and_placing_it_brings_it_back() {
    let mut w = world();
    let (ball, boxed) = (find(&w, "/ball"), find(&w, "/box"));
    let set = |w: &mut Sim, p: [f64; 3]| {
        call(
            w,
            &CallContext::default(),
            "sim.setObjectPosition",
            &[
                Value::Int(ball),
                Value::Array(p.iter().map(|&v| Value::Float(v)).collect()),
                Value::Int(-1),
            ],
        )
        .expect("setObjectPosition");
    };
    set(&mut w, [3.0e5, 0.0, 1.0]);
    step(&mut w, 5);
    let log = physics_log(&w);
    assert!(
        log.iter()
            .any(|m| m.contains("'ball'") && m.contains("from the origin")),
        "reported: {log:?}"
    );
    let parked = z(&w, ball);
    step(&mut w, 5);
    assert_eq!(z(&w, ball), parked, "a stopped body stays where it was stopped");
    assert!((z(&w, boxed) - 0.1).abs() < 0.01, "the box is undisturbed");
    // Placing it again re-enables it: it falls onto the floor.
    set(&mut w, [-2.0, 0.0, 0.5]);
    step(&mut w, 20);
    assert!(
        (z(&w, ball) - 0.05).abs() < 0.01,
        "ball back in play at {}",
        z(&w, ball)
    );
    assert_eq!(physics_log(&w).len(), 1);
}
