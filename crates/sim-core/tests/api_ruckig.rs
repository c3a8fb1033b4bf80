//! `sim.ruckigPos`, `sim.ruckigVel`, `sim.ruckigStep` and `sim.ruckigRemove` through the
//! registry: moves reach their targets within the limits, result codes, CoppeliaSim's
//! table layouts and flags, and bad handles and arguments.

use crate::util;

use gantry_sim_core::{Sim, Value};
use gantry_test_support::floats;
use util::{err, ok};

/// `sim.ruckig_nosync`, `sim.ruckig_minvel`, `sim.ruckig_minaccel`.
const NOSYNC: i64 = 3;
const MINVEL: i64 = 0x100;
const MINACCEL: i64 = 0x200;
/// The base cycle CoppeliaSim's own motion functions use, s.
const BASE: f64 = 1e-4;
/// The simulation step used here, s.
const DT: f64 = 0.01;

fn world() -> Sim {
    util::text_scene("../../assets/scenes/empty.toml", "[simulation]\ndt = 0.05\n")
}

fn v(x: &[f64]) -> Value {
    Value::floats(x)
}

/// One `sim.ruckigStep`: result code, positions/velocities/accelerations, sync time.
fn step(w: &mut Sim, h: i64, dt: f64) -> (i64, Vec<f64>, f64) {
    let r = ok(w, "ruckigStep", &[h.into(), dt.into()]);
    assert_eq!(r.len(), 3);
    (
        r[0].as_i64().expect("code"),
        floats(&r[1]),
        r[2].as_f64().expect("time"),
    )
}

/// A 2-DoF position generator from rest at the origin.
fn two_dof(w: &mut Sim, flags: i64, limits: &[f64], target: &[f64]) -> i64 {
    let h = ok(
        w,
        "ruckigPos",
        &[
            2.into(),
            BASE.into(),
            flags.into(),
            v(&[0.0; 6]),
            v(limits),
            Value::Array(vec![1.into(), 1.into()]),
            v(target),
        ],
    );
    h[0].as_i64().expect("handle")
}

/// Steps until the result is not 0, checking the limits at every step; returns the
/// states and the steps taken.
fn run(w: &mut Sim, h: i64, vmax: [f64; 2], vmin: [f64; 2], amax: [f64; 2]) -> (Vec<Vec<f64>>, i64) {
    let mut states = Vec::new();
    let mut prev_sync = f64::INFINITY;
    for n in 1..10_000 {
        let (code, s, sync) = step(w, h, DT);
        assert!(code == 0 || code == 1, "step {n}: code {code}");
        for d in 0..2 {
            let (vel, acc) = (s[2 + d], s[4 + d]);
            assert!(
                vel <= vmax[d] + 1e-9 && vel >= vmin[d] - 1e-9,
                "step {n}: DoF {d} velocity {vel}"
            );
            assert!(acc.abs() <= amax[d] + 1e-9, "step {n}: DoF {d} acceleration {acc}");
        }
        // The time still needed drops by one cycle per step.
        if prev_sync.is_finite() {
            assert!((prev_sync - sync - DT).abs() < 1e-12, "step {n}: {prev_sync} -> {sync}");
        }
        prev_sync = sync;
        states.push(s);
        if code == 1 {
            assert!(sync <= 0.0 && sync > -DT, "finished with {sync} s to go");
            return (states, n);
        }
        assert!(sync > 0.0, "step {n}: still moving with {sync} s to go");
    }
    panic!("never finished");
}

#[test]
fn two_dof_move_reaches_its_target_within_the_limits() {
    let mut w = world();
    // maxVel, maxAccel, maxJerk for each DoF; target positions then velocities.
    let h = two_dof(&mut w, -1, &[1.0, 2.0, 2.0, 4.0, 10.0, 20.0], &[1.0, -0.5, 0.0, 0.0]);
    assert_eq!(h, 0, "CoppeliaSim's handles start at 0");
    let (states, n) = run(&mut w, h, [1.0, 2.0], [-1.0, -2.0], [2.0, 4.0]);
    let last = states.last().expect("a step");
    for (got, want) in last.iter().zip([1.0, -0.5, 0.0, 0.0, 0.0, 0.0]) {
        assert!((got - want).abs() < 1e-9, "{last:?}");
    }
    // Time-synchronised by default: DoF 2 arrives with DoF 1, not before.
    let before = &states[states.len() - 2];
    assert!((before[1] + 0.5).abs() > 1e-6, "{before:?}");
    // About as long as the slower DoF needs (1 m at 1 m/s, 2 m/s^2, 10 m/s^3: ~1.7 s).
    assert!((150..200).contains(&n), "{n} steps");
    // Finished stays finished, at the target.
    let (code, s, _) = step(&mut w, h, DT);
    assert_eq!(code, 1);
    assert!((s[0] - 1.0).abs() < 1e-9);
    ok(&mut w, "ruckigRemove", &[h.into()]);
    let e = err(&mut w, "ruckigStep", &[h.into(), DT.into()]);
    assert!(e.contains("Ruckig object does not exist (handle 0)"), "{e}");
    // Handles are not reused.
    assert_eq!(two_dof(&mut w, -1, &[1.0; 6], &[0.0; 4]), 1);
}

#[test]
fn flags_select_synchronisation_and_minimum_limits() {
    let mut w = world();
    // No synchronisation: the short DoF arrives first.
    let h = two_dof(&mut w, NOSYNC, &[1.0, 1.0, 2.0, 2.0, 10.0, 10.0], &[1.0, 0.2, 0.0, 0.0]);
    let (states, _) = run(&mut w, h, [1.0; 2], [-1.0; 2], [2.0; 2]);
    let late = &states[states.len() * 3 / 4];
    assert!((late[1] - 0.2).abs() < 1e-9 && (late[0] - 1.0).abs() > 1e-3, "{late:?}");
    // Minimum velocities and accelerations after the maximum tables, velocities first:
    // moving backwards at most 0.25 m/s with at most 0.5 m/s^2 of braking.
    let limits = [1.0, 1.0, 2.0, 2.0, 10.0, 10.0, -0.25, -0.5, -0.5, -1.0];
    let h = two_dof(&mut w, MINVEL | MINACCEL, &limits, &[-0.5, -0.5, 0.0, 0.0]);
    let (states, _) = run(&mut w, h, [1.0; 2], [-0.25, -0.5], [2.0; 2]);
    assert!(states.iter().all(|s| s[4] >= -0.5 - 1e-9 && s[5] >= -1.0 - 1e-9));
    assert!(
        states.iter().any(|s| (s[2] + 0.25).abs() < 1e-6),
        "DoF 1 cruises at its minimum velocity"
    );
    // A missing minimum table is an error naming the argument.
    let e = err(
        &mut w,
        "ruckigPos",
        &[
            2.into(),
            BASE.into(),
            MINVEL.into(),
            v(&[0.0; 6]),
            v(&[1.0; 6]),
            Value::Array(vec![1.into(), 1.into()]),
            v(&[0.0; 4]),
        ],
    );
    assert!(
        e.contains("argument 5 (maxVelAccelJerk): expected 8 numbers, got 6"),
        "{e}"
    );
}

#[test]
fn velocity_generator_reaches_its_target_velocity() {
    let mut w = world();
    // maxAccel then maxJerk per DoF; a target velocity per DoF.
    let h = ok(
        &mut w,
        "ruckigVel",
        &[
            2.into(),
            BASE.into(),
            (-1).into(),
            v(&[0.0, 1.0, 0.0, 0.5, 0.0, 0.0]),
            v(&[1.0, 1.0, 5.0, 5.0]),
            Value::Array(vec![Value::Bool(true), Value::Bool(true)]),
            v(&[2.0, -1.0]),
        ],
    )[0]
    .as_i64()
    .expect("handle");
    let mut last = Vec::new();
    for n in 0..1000 {
        let (code, s, _) = step(&mut w, h, DT);
        assert!(s[4].abs() <= 1.0 + 1e-9 && s[5].abs() <= 1.0 + 1e-9, "{s:?}");
        last = s;
        if code == 1 {
            break;
        }
        assert_eq!(code, 0, "step {n}");
    }
    assert!((last[2] - 2.0).abs() < 1e-9 && (last[3] + 1.0).abs() < 1e-9, "{last:?}");
    assert!(
        last[0] > 0.0 && last[1] < 1.0,
        "positions integrate the velocities: {last:?}"
    );
}

#[test]
fn cycle_times_are_whole_numbers_of_base_cycles() {
    let mut w = world();
    let h = two_dof(&mut w, -1, &[1.0, 1.0, 2.0, 2.0, 10.0, 10.0], &[1.0, 1.0, 0.0, 0.0]);
    // One 50 ms step lands where five 10 ms steps do.
    let h2 = two_dof(&mut w, -1, &[1.0, 1.0, 2.0, 2.0, 10.0, 10.0], &[1.0, 1.0, 0.0, 0.0]);
    let (_, one, sync1) = step(&mut w, h, 0.05);
    let mut five = Vec::new();
    let mut sync5 = 0.0;
    for _ in 0..5 {
        let (_, s, t) = step(&mut w, h2, DT);
        five = s;
        sync5 = t;
    }
    for (a, b) in one.iter().zip(&five) {
        assert!((a - b).abs() < 1e-12, "{one:?} vs {five:?}");
    }
    assert!((sync1 - sync5).abs() < 1e-12);
    for bad in [1.5 * BASE, 0.0, -DT, f64::NAN, 0.3 * BASE] {
        let e = err(&mut w, "ruckigStep", &[h.into(), bad.into()]);
        assert!(e.contains("argument 2 (cycleTime)"), "{bad}: {e}");
    }
}

#[test]
fn invalid_input_is_a_result_code_with_the_reason_logged() {
    let mut w = world();
    // A negative maximum velocity: accepted at creation, refused by Ruckig at the step.
    let h = two_dof(&mut w, -1, &[-1.0, 1.0, 2.0, 2.0, 10.0, 10.0], &[1.0, 1.0, 0.0, 0.0]);
    for _ in 0..3 {
        let (code, s, sync) = step(&mut w, h, DT);
        assert_eq!(code, -100);
        assert_eq!(s, [0.0; 6], "the state stays as it was");
        assert_eq!(sync, 0.0);
    }
    let logged: Vec<_> = w
        .world
        .log
        .lines()
        .filter(|l| l.message.contains("sim.ruckigStep"))
        .collect();
    assert_eq!(logged.len(), 1, "logged once: {logged:?}");
    assert!(logged[0].message.contains("velocity"), "{}", logged[0].message);
}

#[test]
fn flag_constants_have_coppeliasim_values() {
    let sim = gantry_sim_core::api::module("sim").expect("sim module");
    let get = |name: &str| sim.constants.iter().find(|(n, _)| *n == name).map(|(_, v)| *v);
    assert_eq!(get("ruckig_phasesync"), Some(0));
    assert_eq!(get("ruckig_timesync"), Some(1));
    assert_eq!(get("ruckig_nosync"), Some(NOSYNC));
    assert_eq!(get("ruckig_minvel"), Some(MINVEL));
    assert_eq!(get("ruckig_minaccel"), Some(MINACCEL));
}

#[test]
fn bad_handles_and_arguments() {
    let mut w = world();
    let e = err(&mut w, "ruckigStep", &[5.into(), DT.into()]);
    assert!(
        e.contains("does not exist") && e.ends_with("(in function 'sim.ruckigStep')"),
        "{e}"
    );
    let e = err(&mut w, "ruckigRemove", &[5.into()]);
    assert!(e.contains("does not exist"), "{e}");
    let sel = Value::Array(vec![1.into(), 1.into()]);
    let good = || {
        vec![
            2.into(),
            BASE.into(),
            (-1).into(),
            v(&[0.0; 6]),
            v(&[1.0; 6]),
            sel.clone(),
            v(&[0.0; 4]),
        ]
    };
    let with = |i: usize, x: Value| {
        let mut a = good();
        a[i] = x;
        a
    };
    let cases = [
        (with(0, 0.into()), "argument 1 (dofs)"),
        (with(0, 100_000.into()), "argument 1 (dofs)"),
        (with(1, 0.0.into()), "argument 2 (baseCycleTime)"),
        (
            with(3, v(&[0.0; 5])),
            "argument 4 (currentPosVelAccel): expected 6 numbers, got 5",
        ),
        (
            with(3, v(&[0.0, f64::NAN, 0.0, 0.0, 0.0, 0.0])),
            "element 2 must be a finite number",
        ),
        (
            with(4, v(&[1.0, 1.0, 1.0, f64::NAN, 1.0, 1.0])),
            "argument 5 (maxVelAccelJerk): element 4",
        ),
        (with(5, Value::Array(vec![1.into()])), "argument 6 (selection)"),
        (
            with(6, v(&[0.0, 0.0, f64::INFINITY, 0.0])),
            "argument 7 (targetPosVel): element 3",
        ),
    ];
    for (args, expected) in cases {
        let e = err(&mut w, "ruckigPos", &args);
        assert!(e.contains(expected), "{e}");
    }
    // Infinite limits are Ruckig's way of saying "unlimited".
    ok(
        &mut w,
        "ruckigPos",
        &with(4, v(&[1.0, 1.0, 1.0, 1.0, f64::INFINITY, f64::INFINITY])),
    );
    let e = err(
        &mut w,
        "ruckigVel",
        &[
            1.into(),
            BASE.into(),
            (-1).into(),
            v(&[0.0; 3]),
            v(&[1.0]),
            Value::Array(vec![1.into()]),
            v(&[1.0]),
        ],
    );
    assert!(
        e.contains("argument 5 (maxAccelJerk): expected 2 numbers, got 1"),
        "{e}"
    );
}
