//! `sim.setJointTargetForce` as CoppeliaSim documents it: in force/torque control
//! (`sim.jointdynctrl_force`) the joint applies the set torque, with its sign (or its
//! magnitude when `signedValue` is false); in velocity and position control the value's
//! magnitude is the controller's largest torque. `sim.getJointTargetForce` reads back
//! the signed value.
//!
//! The check is physical: a disc on a vertical hinge (no gravity torque about the axis,
//! no friction) with the scene format's joint damping `c` (0.1 N·m·s/rad) obeys
//! `I w' = tau - c w`, so from rest it turns at `w(t) = tau/c (1 - exp(-c t / I))`.

use crate::util;

use gantry_sim_core::api::{self, CallContext};
use gantry_sim_core::{Handle, Sim, Value};

/// A 1 kg cylinder of radius 0.2 m on a hinge about world Z: I = m r² / 2 = 0.02 kg·m².
const SCENE: &str = r#"
[simulation]
dt = 0.01
substeps = 4

[[object]]
name = "base"
kind = "shape"
shape = "box"
size = [0.1, 0.1, 0.1]
position = [0, 0, 0.5]

[[object]]
name = "hinge"
kind = "joint"
joint = "revolute"
mode = "velocity"
parent = "base"
position = [0, 0, 0.1]
max_force = 5.0
kd = 50.0

[[object]]
name = "disc"
kind = "shape"
shape = "cylinder"
radius = 0.2
length = 0.02
parent = "hinge"
dynamic = true
mass = 1.0
"#;

const INERTIA: f64 = 0.5 * 1.0 * 0.2 * 0.2;
/// The scene format's viscous joint damping (docs/scene-format.md), N·m·s/rad.
const DAMPING: f64 = 0.1;
const DT: f64 = 0.01;

/// Angular velocity after `t` s from rest under a constant torque `tau`.
fn spin_up(tau: f64, t: f64) -> f64 {
    tau / DAMPING * (1.0 - (-DAMPING * t / INERTIA).exp())
}

fn world() -> (Sim, Handle) {
    let w = util::text_scene("joint_force.toml", SCENE);
    let h = util::find(&w, "/hinge");
    (w, h)
}

fn call(w: &mut Sim, name: &str, args: &[Value]) -> Result<Vec<Value>, String> {
    let ctx = CallContext {
        script_object: None,
        source: "joint_force.lua",
    };
    api::call(w, &ctx, name, args).map_err(|e| e.to_string())
}

fn float(w: &mut Sim, name: &str, h: Handle) -> f64 {
    call(w, name, &[Value::Int(h)]).expect(name)[0]
        .as_f64()
        .expect("a number")
}

fn steps(w: &mut Sim, n: usize) {
    for _ in 0..n {
        w.step();
    }
}

fn force_mode(w: &mut Sim, h: Handle) {
    let ctrl = call(w, "sim.getObjectInt32Param", &[Value::Int(h), Value::Int(2039)]).expect("dynctrl");
    assert_eq!(ctrl, [Value::Int(4)], "the scene's joint starts in velocity control");
    call(
        w,
        "sim.setObjectInt32Param",
        &[Value::Int(h), Value::Int(2039), Value::Int(1)], // jointintparam_dynctrlmode, jointdynctrl_force
    )
    .expect("force mode");
    assert_eq!(
        call(w, "sim.getObjectInt32Param", &[Value::Int(h), Value::Int(2039)]).expect("dynctrl"),
        [Value::Int(1)]
    );
}

#[test]
fn force_mode_applies_the_signed_torque() {
    for tau in [0.2, -0.2] {
        let (mut w, h) = world();
        force_mode(&mut w, h);
        call(&mut w, "sim.setJointTargetForce", &[Value::Int(h), Value::Float(tau)]).expect("set");
        assert_eq!(float(&mut w, "sim.getJointTargetForce", h), tau);
        assert_eq!(float(&mut w, "sim.getJointMaxForce", h), tau.abs());
        steps(&mut w, 50); // 0.5 s
        let expected = spin_up(tau, 50.0 * DT); // ±1.84 rad/s
        let v = float(&mut w, "sim.getJointVelocity", h);
        assert!(
            (v - expected).abs() < 0.02 * expected.abs(),
            "tau {tau}: velocity {v}, expected {expected}"
        );
        assert!((float(&mut w, "sim.getJointForce", h) - tau).abs() < 1e-9);
        // Without torque the disc coasts, slowed by the joint's damping alone (no motor
        // brakes it): w decays as exp(-c t / I).
        call(&mut w, "sim.setJointTargetForce", &[Value::Int(h), Value::Float(0.0)]).expect("zero");
        steps(&mut w, 20);
        let coast = float(&mut w, "sim.getJointVelocity", h);
        let decayed = v * (-DAMPING * 20.0 * DT / INERTIA).exp();
        assert!(
            (coast - decayed).abs() < 0.03 * v.abs(),
            "coasting: {v} -> {coast}, expected {decayed}"
        );
    }
}

#[test]
fn unsigned_value_applies_the_magnitude() {
    let (mut w, h) = world();
    force_mode(&mut w, h);
    call(
        &mut w,
        "sim.setJointTargetForce",
        &[Value::Int(h), Value::Float(-0.2), Value::Bool(false)],
    )
    .expect("set");
    assert_eq!(float(&mut w, "sim.getJointTargetForce", h), 0.2);
    steps(&mut w, 20);
    let v = float(&mut w, "sim.getJointVelocity", h);
    assert!((v - spin_up(0.2, 20.0 * DT)).abs() < 0.02 * v, "velocity {v}");
}

#[test]
fn velocity_control_takes_the_magnitude_as_its_limit() {
    let (mut w, h) = world();
    call(
        &mut w,
        "sim.setJointTargetVelocity",
        &[Value::Int(h), Value::Float(2.0)],
    )
    .expect("target");
    // A negative value: the limit is its magnitude, and the joint still turns forwards.
    call(&mut w, "sim.setJointTargetForce", &[Value::Int(h), Value::Float(-0.1)]).expect("limit");
    assert_eq!(float(&mut w, "sim.getJointMaxForce", h), 0.1);
    assert_eq!(float(&mut w, "sim.getJointTargetForce", h), -0.1);
    steps(&mut w, 10);
    // Torque-limited: the controller pushes with 0.1 N·m, forwards.
    let v = float(&mut w, "sim.getJointVelocity", h);
    assert!((v - spin_up(0.1, 10.0 * DT)).abs() < 0.03 * v, "velocity {v}");
    // 0.1 N·m balances the damping at 1 rad/s, short of the 2 rad/s asked for.
    steps(&mut w, 300);
    let v = float(&mut w, "sim.getJointVelocity", h);
    assert!((v - 0.1 / DAMPING).abs() < 0.02, "velocity {v}");
    // With the limit raised, the target is reached.
    call(&mut w, "sim.setJointTargetForce", &[Value::Int(h), Value::Float(1.0)]).expect("limit");
    steps(&mut w, 100);
    assert!((float(&mut w, "sim.getJointVelocity", h) - 2.0).abs() < 0.05);
}

#[test]
fn bad_values_are_errors() {
    let (mut w, h) = world();
    let e = call(
        &mut w,
        "sim.setJointTargetForce",
        &[Value::Int(h), Value::Float(f64::NAN)],
    )
    .unwrap_err();
    assert!(e.contains("sim.setJointTargetForce"), "{e}");
    let e = call(
        &mut w,
        "sim.setObjectInt32Param",
        &[Value::Int(h), Value::Int(2039), Value::Int(7)],
    )
    .unwrap_err();
    assert!(e.contains("force (1)"), "{e}");
}
