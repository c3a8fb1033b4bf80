//! Kinematic joints move as CoppeliaSim's manual describes them ("Joint modes"): placed
//! at once by `sim.setJointPosition`, but following a motion profile when given a
//! target with `sim.setJointTargetPosition` or a speed with `sim.setJointTargetVelocity`.
//! gantry's profile is speed-limited: the joint's `sim.jointfloatparam_maxvel` (URDF
//! `velocity`), else 180 deg/s for revolute joints.

use crate::util;

use std::f64::consts::PI;

use gantry_sim_core::api::{self, CallContext};
use gantry_sim_core::{Handle, Sim, Value};
use gantry_test_support::{assert_close, floats};
use util::find;

const SCENE: &str = r#"
[simulation]
dt = 0.05

[[object]]
name = "hinge"
kind = "joint"
joint = "revolute"
position = [0, 0, 0.5]
limits = [-90, 90]

[[object]]
name = "tip"
kind = "dummy"
parent = "hinge"
position = [0.5, 0, 0]

[[object]]
name = "wheel"
kind = "joint"
joint = "revolute"
cyclic = true
position = [1, 0, 0.5]
"#;

const DT: f64 = 0.05;

fn world() -> Sim {
    util::text_scene("kinematic_motion.toml", SCENE)
}

fn call(w: &mut Sim, name: &str, args: &[Value]) -> Vec<Value> {
    let ctx = CallContext {
        script_object: None,
        source: "kinematic_motion.lua",
    };
    api::call(w, &ctx, name, args).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn get(w: &mut Sim, name: &str, h: Handle) -> f64 {
    call(w, name, &[Value::Int(h)])[0].as_f64().expect("a number")
}

fn step(w: &mut Sim) {
    w.step();
}

#[test]
fn a_target_is_reached_at_the_joint_speed_not_at_once() {
    let mut w = world();
    let (hinge, tip) = (find(&w, "/hinge"), find(&w, "/hinge/tip"));
    call(
        &mut w,
        "sim.setJointTargetPosition",
        &[Value::Int(hinge), Value::Float(1.0)],
    );
    assert_eq!(
        get(&mut w, "sim.getJointPosition", hinge),
        0.0,
        "nothing moves before the step"
    );
    assert_eq!(get(&mut w, "sim.getJointTargetPosition", hinge), 1.0);
    step(&mut w);
    let q = get(&mut w, "sim.getJointPosition", hinge);
    assert!((q - PI * DT).abs() < 1e-12, "one step at 180 deg/s: {q}");
    assert!((get(&mut w, "sim.getJointVelocity", hinge) - PI).abs() < 1e-9);
    // The child follows the joint.
    let p = call(&mut w, "sim.getObjectPosition", &[Value::Int(tip), Value::Int(-1)]);
    let y = p[0].clone();
    let Value::Array(xyz) = y else { panic!("a position") };
    assert!((xyz[1].as_f64().unwrap() - 0.5 * q.sin()).abs() < 1e-9);
    // 1 rad at pi rad/s: 0.318 s, so reached at the 7th step and still afterwards.
    for _ in 0..5 {
        step(&mut w);
    }
    assert!(get(&mut w, "sim.getJointPosition", hinge) < 1.0);
    step(&mut w);
    assert_eq!(get(&mut w, "sim.getJointPosition", hinge), 1.0);
    step(&mut w);
    assert_eq!(get(&mut w, "sim.getJointPosition", hinge), 1.0);
    assert_eq!(get(&mut w, "sim.getJointVelocity", hinge), 0.0);
}

#[test]
fn the_speed_limit_is_the_joints_own() {
    let mut w = world();
    let hinge = find(&w, "/hinge");
    // sim.jointfloatparam_maxvel
    call(
        &mut w,
        "sim.setObjectFloatParam",
        &[Value::Int(hinge), Value::Int(2036), Value::Float(0.5)],
    );
    call(
        &mut w,
        "sim.setJointTargetPosition",
        &[Value::Int(hinge), Value::Float(-0.1)],
    );
    step(&mut w);
    assert!((get(&mut w, "sim.getJointPosition", hinge) + 0.025).abs() < 1e-12);
    // A new target turns it round from where it is.
    call(
        &mut w,
        "sim.setJointTargetPosition",
        &[Value::Int(hinge), Value::Float(0.0)],
    );
    step(&mut w);
    assert!(get(&mut w, "sim.getJointPosition", hinge).abs() < 1e-12);
}

#[test]
fn a_target_velocity_moves_it_until_a_limit() {
    let mut w = world();
    let hinge = find(&w, "/hinge");
    call(
        &mut w,
        "sim.setJointTargetVelocity",
        &[Value::Int(hinge), Value::Float(2.0)],
    );
    step(&mut w);
    assert!((get(&mut w, "sim.getJointPosition", hinge) - 0.1).abs() < 1e-12);
    assert!((get(&mut w, "sim.getJointVelocity", hinge) - 2.0).abs() < 1e-9);
    for _ in 0..30 {
        step(&mut w);
    }
    // Stopped at the upper limit, 90 deg.
    assert!((get(&mut w, "sim.getJointPosition", hinge) - PI / 2.0).abs() < 1e-12);
    step(&mut w);
    assert_eq!(get(&mut w, "sim.getJointVelocity", hinge), 0.0);
}

#[test]
fn a_cyclic_joint_turns_on_and_takes_the_short_way() {
    let mut w = world();
    let wheel = find(&w, "/wheel");
    call(
        &mut w,
        "sim.setJointTargetVelocity",
        &[Value::Int(wheel), Value::Float(4.0)],
    );
    for _ in 0..20 {
        step(&mut w); // 4 rad in all: past +pi, so wrapped
    }
    let q = get(&mut w, "sim.getJointPosition", wheel);
    assert!((q - (4.0 - 2.0 * PI)).abs() < 1e-9, "wrapped: {q}");
    call(
        &mut w,
        "sim.setJointTargetVelocity",
        &[Value::Int(wheel), Value::Float(0.0)],
    );
    step(&mut w);
    assert_eq!(get(&mut w, "sim.getJointPosition", wheel), q, "a zero speed stops it");
    // From -2.28 rad to 3.0 rad the short way is through pi: 1.0 rad, down.
    call(
        &mut w,
        "sim.setJointTargetPosition",
        &[Value::Int(wheel), Value::Float(3.0)],
    );
    step(&mut w);
    let q2 = get(&mut w, "sim.getJointPosition", wheel);
    assert!((q2 - (q - PI * DT)).abs() < 1e-9, "{q} -> {q2}");
}

#[test]
fn placing_the_joint_ends_its_motion() {
    let mut w = world();
    let hinge = find(&w, "/hinge");
    call(
        &mut w,
        "sim.setJointTargetPosition",
        &[Value::Int(hinge), Value::Float(1.0)],
    );
    step(&mut w);
    call(&mut w, "sim.setJointPosition", &[Value::Int(hinge), Value::Float(-0.5)]);
    step(&mut w);
    assert_eq!(get(&mut w, "sim.getJointPosition", hinge), -0.5);
}

/// `sim.handleflag_reljointbaseframe` on the object's handle: a joint given as the
/// reference frame counts with its base frame, without its own rotation, for reading
/// and for setting (CoppeliaSim's omni-wheel scripts keep their rollers at 45 degrees
/// to the wheel's base this way while the wheel turns).
#[test]
fn a_joint_reference_frame_without_its_motion() {
    let mut w = world();
    let hinge = find(&w, "/hinge");
    let tip = find(&w, "/hinge/tip");
    let base_flag = api::CONSTANTS
        .iter()
        .find(|(n, _)| *n == "handleflag_reljointbaseframe")
        .map(|(_, v)| *v)
        .expect("sim.handleflag_reljointbaseframe");
    call(
        &mut w,
        "sim.setJointPosition",
        &[Value::Int(hinge), Value::Float(PI / 4.0)],
    );
    let moving = floats(&call(&mut w, "sim.getObjectPosition", &[Value::Int(tip), Value::Int(hinge)])[0]);
    let base = floats(
        &call(
            &mut w,
            "sim.getObjectPosition",
            &[Value::Int(tip | base_flag), Value::Int(hinge)],
        )[0],
    );
    // In the moving frame the tip is where the scene put it; in the base frame it has
    // turned 45 degrees about the joint's z axis.
    assert_close(&moving, &[0.5, 0.0, 0.0], 1e-9);
    let c = 0.5 * (PI / 4.0).cos();
    assert_close(&base, &[c, c, 0.0], 1e-9);
    // Setting in the base frame: the tip lands at 0 degrees in the base frame, so -45
    // degrees in the moving one.
    call(
        &mut w,
        "sim.setObjectPosition",
        &[
            Value::Int(tip | base_flag),
            Value::Int(hinge),
            Value::floats(&[0.5, 0.0, 0.0]),
        ],
    );
    let moving = floats(&call(&mut w, "sim.getObjectPosition", &[Value::Int(tip), Value::Int(hinge)])[0]);
    assert_close(&moving, &[c, -c, 0.0], 1e-9);
}
