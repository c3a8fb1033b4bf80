//! World-level contracts: scenes load and step, kinematics, dynamics, determinism.

use crate::util;

use gantry_sim_core::scene::{DiskFiles, JointMode, JointType, LoadOptions, ObjectModelKind, load_scene};
use gantry_sim_core::world::ObjectKind;
use gantry_sim_core::{Handle, Sim};
use util::{asset, find};

fn world(rel: &str) -> Sim {
    util::asset_scene(rel)
}

/// Every bundled scene, left alone (no scripts, no commands), settles: after 10 s each
/// step is exactly one time step, nothing fell through the floor or flew off, and
/// every object has come to rest where the first second left it.
#[test]
fn every_scene_loads_steps_and_settles() {
    for scene in [
        "scenes/fk_arm.toml",
        "scenes/bubble_rob.toml",
        "scenes/showroom.toml",
        "robots/arm6/arm6.urdf",
    ] {
        let mut w = world(scene);
        let dt = w.world.settings().dt;
        let positions = |w: &gantry_sim_core::Sim| -> Vec<(Handle, [f64; 3])> {
            w.world
                .handles()
                .iter()
                .map(|&h| {
                    let p = w.world.object(h).expect("exists").world.translation.vector;
                    (h, [p.x, p.y, p.z])
                })
                .collect()
        };
        for _ in 0..200 {
            w.step();
        }
        let settled = positions(&w);
        for _ in 0..20 {
            w.step();
        }
        assert_eq!(w.world.steps(), 220, "{scene}");
        assert!(
            (w.world.time() - 220.0 * dt).abs() < 1e-9,
            "{scene}: time {}",
            w.world.time()
        );
        for ((h, a), (_, b)) in settled.iter().zip(positions(&w)) {
            assert!(
                b.iter().all(|v| v.is_finite()),
                "{scene}: object {h} has a non-finite pose"
            );
            assert!(
                b[2] > -0.01,
                "{scene}: object {h} fell through the floor to z = {}",
                b[2]
            );
            assert!(
                b.iter().all(|v| v.abs() < 100.0),
                "{scene}: object {h} flew off to {b:?}"
            );
            let moved = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt();
            assert!(
                moved < 1e-3,
                "{scene}: object {h} still moves ({moved} m in the last 20 steps)"
            );
        }
    }
}

#[test]
fn rover_drives_straight_at_wheel_speed() {
    let mut w = world("scenes/bubble_rob.toml");
    let base = find(&w, "/bubbleRob");
    let (l, r) = (find(&w, "/bubbleRob/leftMotor"), find(&w, "/bubbleRob/rightMotor"));
    let rate = 3.054; // rad/s, the tutorial's initial speed
    w.world.set_joint_target_velocity(l, rate).expect("joint");
    w.world.set_joint_target_velocity(r, rate).expect("joint");
    // Let it accelerate for 1 s, then measure over 3 s.
    for _ in 0..20 {
        w.step();
    }
    let x0 = w.world.object(base).expect("base").world.translation.vector;
    for _ in 0..60 {
        w.step();
    }
    let x1 = w.world.object(base).expect("base").world.translation.vector;
    let speed = (x1 - x0).norm() / 3.0;
    let expected = 0.04 * rate;
    eprintln!(
        "rover speed {speed:.4} m/s, expected {expected:.4}, dy {:.4}",
        x1.y - x0.y
    );
    assert!(
        (speed - expected).abs() / expected < 0.05,
        "speed {speed} vs {expected}"
    );
    assert!(x1.x > x0.x, "a positive wheel speed drives towards +X");
}

#[test]
fn proximity_sensor_sees_obstacle_ahead() {
    let mut w = world("scenes/bubble_rob.toml");
    let base = find(&w, "/bubbleRob");
    let nose = find(&w, "/bubbleRob/sensingNose");
    // Put an obstacle 0.1 m in front of the nose: obstacle0 at x + 0.1 (sensor) + 0.05 + 0.05 (radius).
    let obstacle = find(&w, "/obstacle");
    let mut pose = w.world.object(base).expect("base").world;
    pose.translation.vector.x += 0.1 + 0.1 + 0.05;
    pose.translation.vector.z = 0.1;
    pose.rotation = nalgebra::UnitQuaternion::identity();
    w.world.set_world_pose(obstacle, pose).expect("moves");
    w.step_dynamics();
    let hit = gantry_sim_core::sensor::handle_proximity_sensor(&mut w.world, nose)
        .expect("sensor")
        .expect("detects");
    assert_eq!(hit.object, obstacle);
    assert!((hit.distance - 0.1).abs() < 0.01, "distance {}", hit.distance);
    assert!(matches!(
        w.world.object(nose).expect("nose").kind,
        ObjectKind::ProximitySensor(_)
    ));
}

#[test]
fn position_target_settles() {
    let model = load_scene(&DiskFiles, &asset("scenes/fk_arm.toml"), &LoadOptions::default()).expect("loads");
    let mut model = model;
    for o in &mut model.objects {
        match &mut o.kind {
            ObjectModelKind::Joint(j) if j.joint_type != JointType::Fixed => j.mode = JointMode::Position,
            ObjectModelKind::Shape(s) if o.alias.starts_with("link") || o.alias == "tip" => s.dynamic = true,
            _ => {}
        }
    }
    let mut w = Sim::new(&model);
    let j1 = find(&w, "/arm6/joint1");
    let j2 = find(&w, "/arm6/joint2");
    w.world.set_joint_target_position(j1, 0.5).expect("joint");
    w.world.set_joint_target_position(j2, 0.3).expect("joint");
    for _ in 0..60 {
        w.step();
    }
    let q1 = w.world.joint(j1).expect("joint").position;
    let q2 = w.world.joint(j2).expect("joint").position;
    eprintln!("q1 {q1} q2 {q2}");
    assert!((q1 - 0.5).abs() < 0.01, "joint1 at {q1}");
    assert!((q2 - 0.3).abs() < 0.02, "joint2 at {q2}");
    // The tree and rapier agree on where the links are.
    let link2 = find(&w, "/arm6/link2");
    let tree = w.world.object(link2).expect("link").world;
    let phys = w.world.physics_pose(link2).expect("body");
    assert!(
        (tree.translation.vector - phys.translation.vector).norm() < 1e-3,
        "{tree:?} vs {phys:?}"
    );
}
