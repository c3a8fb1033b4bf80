//! Determinism: two runs of a scene with the same inputs give bit-identical poses of every
//! object at every step (BubbleRob alone, and the showroom with the arm moving too).

use crate::util;

use gantry_sim_core::{Handle, Sim};
use util::find;

/// Steps per run: 20 s of simulated time at the scenes' 50 ms step.
const STEPS: usize = 400;

/// Wheel speed schedule (rad/s) as (first step, left, right): forward, two turns, reverse.
/// Changes at fixed steps exercise the motor updates mid-run.
const WHEEL_SCHEDULE: [(usize, f64, f64); 4] = [(0, 3.0, 3.0), (120, 3.0, -1.0), (200, -1.0, 3.0), (300, -1.0, -1.0)];

/// Every object's world pose as raw bits: translation x, y, z, then quaternion i, j, k, w.
type Snapshot = Vec<[u64; 7]>;

/// What one run recorded: a snapshot per step, and how far the rover got from its start.
struct Run {
    snapshots: Vec<Snapshot>,
    max_rover_distance: f64,
}

fn load(rel: &str) -> Sim {
    util::asset_scene(rel)
}

fn snapshot(w: &Sim) -> Snapshot {
    w.world
        .handles()
        .iter()
        .map(|&h| {
            let pose = w.world.object(h).expect("object exists").world;
            let t = pose.translation.vector;
            let q = pose.rotation;
            [t.x, t.y, t.z, q.i, q.j, q.k, q.w].map(f64::to_bits)
        })
        .collect()
}

/// Runs `scene` for [`STEPS`] steps with the wheel schedule and, if `arm` is set, moves the
/// six arm joints kinematically every step; sensors are handled every step as the
/// simulation loop does.
fn run(scene: &str, arm: bool) -> Run {
    let mut w = load(scene);
    let rover = find(&w, "/bubbleRob");
    let left = find(&w, "/bubbleRob/leftMotor");
    let right = find(&w, "/bubbleRob/rightMotor");
    let joints: Vec<Handle> = if arm {
        (1..=6).map(|i| find(&w, &format!("/arm6/joint{i}"))).collect()
    } else {
        Vec::new()
    };
    let start = w.world.object(rover).expect("rover").world.translation.vector;
    let mut out = Run {
        snapshots: Vec::with_capacity(STEPS),
        max_rover_distance: 0.0,
    };
    for step in 0..STEPS {
        if let Some(&(_, l, r)) = WHEEL_SCHEDULE.iter().find(|(at, _, _)| *at == step) {
            w.world.set_joint_target_velocity(left, l).expect("left motor");
            w.world.set_joint_target_velocity(right, r).expect("right motor");
        }
        for (i, &j) in joints.iter().enumerate() {
            // A smooth sweep per joint; out-of-limit values are clamped, which is fine.
            let q = 0.8 * (0.05 * step as f64 + i as f64).sin();
            w.world.set_joint_position(j, q).expect("arm joint");
        }
        w.step();
        out.snapshots.push(snapshot(&w));
        let p = w.world.object(rover).expect("rover").world.translation.vector;
        out.max_rover_distance = out.max_rover_distance.max((p - start).norm());
    }
    out
}

/// Asserts two runs are bit-identical, naming the first step and object that differ.
fn assert_identical(scene: &str, a: &Run, b: &Run) {
    assert_eq!(a.snapshots.len(), b.snapshots.len());
    for (step, (sa, sb)) in a.snapshots.iter().zip(&b.snapshots).enumerate() {
        assert_eq!(sa.len(), sb.len(), "{scene}: object count differs at step {step}");
        for (h, (pa, pb)) in sa.iter().zip(sb).enumerate() {
            assert!(
                pa == pb,
                "{scene}: object {h} diverges at step {step}: {:?} vs {:?}",
                pa.map(f64::from_bits),
                pb.map(f64::from_bits)
            );
        }
    }
}

#[test]
fn bubble_rob_runs_are_bit_identical() {
    let scene = "scenes/bubble_rob.toml";
    let (a, b) = (run(scene, false), run(scene, false));
    // Without motion, identical runs would prove nothing.
    assert!(
        a.max_rover_distance > 0.2,
        "the rover only moved {} m",
        a.max_rover_distance
    );
    assert_identical(scene, &a, &b);
}

#[test]
fn showroom_runs_with_moving_arm_are_bit_identical() {
    let scene = "scenes/showroom.toml";
    let (a, b) = (run(scene, true), run(scene, true));
    assert!(
        a.max_rover_distance > 0.2,
        "the rover only moved {} m",
        a.max_rover_distance
    );
    // The arm must have moved too: compare the tip's first and last recorded positions.
    let w = load(scene);
    let tip = find(&w, "/arm6/tip");
    let tip = w
        .world
        .handles()
        .iter()
        .position(|&h| h == tip)
        .expect("tip is in the snapshot");
    let (first, last) = (a.snapshots[0][tip], a.snapshots[STEPS - 1][tip]);
    let moved: f64 = (0..3)
        .map(|i| (f64::from_bits(first[i]) - f64::from_bits(last[i])).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(moved > 0.05, "the arm tip only moved {moved} m");
    assert_identical(scene, &a, &b);
}
