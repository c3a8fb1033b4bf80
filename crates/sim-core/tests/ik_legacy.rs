//! `simIK`'s CoppeliaSim 4.2 names on the arm6 scene: a 4.2-style set-up (createIkGroup,
//! addIkElementFromScene, setIk* and handleIkGroup, the target placed with the 4.2
//! argument order of simIK.setObjectMatrix) reaches the target as the 4.3 calls do, with
//! the same joint values, and the adapters refuse what gantry cannot honour.

use crate::util;

use std::f64::consts::PI;

use gantry_sim_core::math::Pose;
use gantry_sim_core::{Handle, Sim, Value};
use gantry_test_support::int;
use util::{Arm, arm, call, int_values};

const DEG: f64 = PI / 180.0;
const POS_TOL: f64 = 1e-3;
const ANG_TOL: f64 = 0.5 * DEG;
/// The paper's start pose: joint5 = -90 deg, tool pointing down.
const START: [f64; 6] = [0.0, 0.0, 0.0, 0.0, -90.0 * DEG, 0.0];
/// A reachable goal configuration (the one of `ik.rs`'s API test).
const GOAL: [f64; 6] = [0.4, -0.3, 0.5, 0.2, -1.2, 0.3];

fn set_joints(a: &mut Arm, q: &[f64; 6]) {
    for (&h, &qi) in a.joints.iter().zip(q) {
        a.sim.world.set_joint_position(h, qi).expect("joint");
    }
}

fn joint_values(a: &Arm) -> [f64; 6] {
    a.joints.map(|h| a.sim.world.joint(h).expect("joint").position)
}

fn pose(w: &Sim, h: Handle) -> Pose {
    w.world.object(h).expect("object").world
}

fn pose_error(a: &Pose, b: &Pose) -> (f64, f64) {
    (
        (a.translation.vector - b.translation.vector).norm(),
        a.rotation.angle_to(&b.rotation),
    )
}

/// The tip's pose at `GOAL`, relative to the base, as `sim.getObjectMatrix` gives it; the
/// arm is put back at `START`.
fn goal_matrix(a: &mut Arm) -> (Value, Pose) {
    set_joints(a, &GOAL);
    let m = call(&mut a.sim, "sim.getObjectMatrix", &int_values(&[a.tip, a.base])).expect("matrix");
    let goal = pose(&a.sim, a.tip);
    set_joints(a, &START);
    (m[0].clone(), goal)
}

/// The 4.2 set-up of CoppeliaSim's IK tutorials: a named group, DLS, an element from the
/// scene, its precision, weights, constraints and base. Returns env, group and element.
fn setup_42(a: &mut Arm) -> (i64, i64, i64) {
    let w = &mut a.sim;
    let env = int(&call(w, "simIK.createEnvironment", &[]).expect("env")[0]);
    let group = int(&call(w, "simIK.createIkGroup", &[Value::Int(env), "arm".into()]).expect("createIkGroup")[0]);
    let found = call(w, "simIK.getIkGroupHandle", &[Value::Int(env), "arm".into()]).expect("getIkGroupHandle");
    assert_eq!(int(&found[0]), group);
    call(
        w,
        "simIK.setIkGroupCalculation",
        &[
            Value::Int(env),
            Value::Int(group),
            Value::Int(1),
            Value::Float(0.3),
            Value::Int(100),
        ],
    )
    .expect("setIkGroupCalculation");
    let r = call(
        w,
        "simIK.addIkElementFromScene",
        &int_values(&[env, group, a.base, a.tip, a.target, 31]),
    )
    .expect("addIkElementFromScene");
    let element = int(&r[0]);
    let ege = [env, group, element];
    let with = |extra: Value| {
        let mut v = int_values(&ege);
        v.push(extra);
        v
    };
    call(
        w,
        "simIK.setIkElementPrecision",
        &with(Value::floats(&[0.0005, 0.1 * DEG])),
    )
    .expect("setIkElementPrecision");
    call(w, "simIK.setIkElementWeights", &with(Value::floats(&[1.0, 1.0]))).expect("setIkElementWeights");
    call(w, "simIK.setIkElementConstraints", &with(Value::Int(31))).expect("setIkElementConstraints");
    let mut base_args = with(Value::Int(a.base));
    base_args.push(Value::Int(-1));
    call(w, "simIK.setIkElementBase", &base_args).expect("setIkElementBase");
    let r = call(w, "simIK.getElementBase", &int_values(&ege)).expect("getElementBase");
    assert_eq!((int(&r[0]), int(&r[1])), (a.base, -1));
    (env, group, element)
}

#[test]
fn a_42_setup_reaches_the_target_like_the_43_calls() {
    let mut a = arm();
    let (goal_m, goal) = goal_matrix(&mut a);
    let (env, group, _) = setup_42(&mut a);

    // 4.2 order: (env, object, relativeTo, matrix). The target is its own IK counterpart.
    call(
        &mut a.sim,
        "simIK.setObjectMatrix",
        &[
            Value::Int(env),
            Value::Int(a.target),
            Value::Int(a.base),
            goal_m.clone(),
        ],
    )
    .expect("setObjectMatrix");
    let (dp, da) = pose_error(&pose(&a.sim, a.target), &goal);
    assert!(
        dp < 1e-12 && da < 1e-9,
        "target placed at {dp} m, {da} rad from the goal"
    );
    let back = call(
        &mut a.sim,
        "simIK.getObjectMatrix",
        &int_values(&[env, a.target, a.base]),
    )
    .expect("getObjectMatrix");
    let (Value::Array(x), Value::Array(y)) = (&back[0], &goal_m) else {
        panic!("matrices: {back:?}")
    };
    for (p, q) in x.iter().zip(y) {
        assert!((p.as_f64().expect("number") - q.as_f64().expect("number")).abs() < 1e-9);
    }

    let r = call(&mut a.sim, "simIK.handleIkGroup", &int_values(&[env, group])).expect("handleIkGroup");
    assert_eq!(int(&r[0]), 1, "result_success: {r:?}");
    let (dp, da) = pose_error(&pose(&a.sim, a.tip), &goal);
    assert!(dp < POS_TOL && da < ANG_TOL, "tip {dp} m, {da} rad from the goal");
    let q42 = joint_values(&a);
    // A 4.2 script then copies the IK joints onto the scene; here they are the same.
    for &j in &a.joints {
        let q = call(&mut a.sim, "simIK.getJointPosition", &int_values(&[env, j])).expect("getJointPosition");
        assert_eq!(q[0].as_f64(), Some(a.sim.world.joint(j).expect("joint").position));
    }

    // The 4.3 calls from the same start find the same joint values.
    set_joints(&mut a, &START);
    let w = &mut a.sim;
    let env43 = int(&call(w, "simIK.createEnvironment", &[]).expect("env")[0]);
    let g43 = int(&call(w, "simIK.createGroup", &[Value::Int(env43)]).expect("createGroup")[0]);
    call(
        w,
        "simIK.setGroupCalculation",
        &[
            Value::Int(env43),
            Value::Int(g43),
            Value::Int(1),
            Value::Float(0.3),
            Value::Int(100),
        ],
    )
    .expect("setGroupCalculation");
    call(
        w,
        "simIK.addElementFromScene",
        &int_values(&[env43, g43, a.base, a.tip, a.target, 31]),
    )
    .expect("addElementFromScene");
    let r = call(w, "simIK.handleGroup", &int_values(&[env43, g43])).expect("handleGroup");
    assert_eq!(int(&r[0]), 1);
    let q43 = joint_values(&a);
    for (x, y) in q42.iter().zip(&q43) {
        assert!((x - y).abs() < 1e-12, "4.2 {q42:?} vs 4.3 {q43:?}");
    }
}

#[test]
fn the_45_argument_order_of_set_object_matrix_works_too() {
    let mut a = arm();
    let (goal_m, goal) = goal_matrix(&mut a);
    let (env, group, _) = setup_42(&mut a);
    call(
        &mut a.sim,
        "simIK.setObjectMatrix",
        &[Value::Int(env), Value::Int(a.target), goal_m, Value::Int(a.base)],
    )
    .expect("setObjectMatrix");
    let r = call(
        &mut a.sim,
        "simIK.applyIkEnvironmentToScene",
        &int_values(&[env, group]),
    )
    .expect("apply");
    assert_eq!(int(&r[0]), 1);
    let (dp, da) = pose_error(&pose(&a.sim, a.tip), &goal);
    assert!(dp < POS_TOL && da < ANG_TOL);
}

#[test]
fn set_joint_position_writes_the_scene_joint() {
    let mut a = arm();
    let (env, _, _) = setup_42(&mut a);
    let j = a.joints[1];
    call(
        &mut a.sim,
        "simIK.setJointPosition",
        &[Value::Int(env), Value::Int(j), Value::Float(0.25)],
    )
    .expect("setJointPosition");
    assert!((a.sim.world.joint(j).expect("joint").position - 0.25).abs() < 1e-12);
    let q = call(&mut a.sim, "simIK.getJointPosition", &int_values(&[env, j])).expect("get");
    assert!((q[0].as_f64().expect("number") - 0.25).abs() < 1e-12);
}

#[test]
fn unsupported_uses_fail_loudly_and_name_the_function() {
    let mut a = arm();
    let (env, group, element) = setup_42(&mut a);
    let ege = int_values(&[env, group, element]);

    // Constraints relative to another frame than the base.
    let mut args = ege.clone();
    args.extend(int_values(&[a.base, a.target]));
    let e = call(&mut a.sim, "simIK.setIkElementBase", &args).expect_err("other frame");
    assert!(e.contains("simIK.setIkElementBase") && e.contains("argument 5"), "{e}");

    // A base the tip does not hang below leaves the element as it was.
    let mut args = ege.clone();
    args.push(Value::Int(a.target));
    let e = call(&mut a.sim, "simIK.setElementBase", &args).expect_err("not a chain");
    assert!(e.contains("simIK.setElementBase"), "{e}");
    let r = call(&mut a.sim, "simIK.getElementBase", &ege).expect("getElementBase");
    assert_eq!(int(&r[0]), a.base);

    // Moving a joint object would reshape the robot in the scene.
    let m = call(&mut a.sim, "sim.getObjectMatrix", &int_values(&[a.joints[0], -1])).expect("matrix");
    let e = call(
        &mut a.sim,
        "simIK.setObjectMatrix",
        &[Value::Int(env), Value::Int(a.joints[0]), Value::Int(-1), m[0].clone()],
    )
    .expect_err("joint");
    assert!(e.contains("simIK.setObjectMatrix") && e.contains("joint"), "{e}");

    // A stale environment.
    call(&mut a.sim, "simIK.eraseEnvironment", &int_values(&[env])).expect("erase");
    let e = call(&mut a.sim, "simIK.getObjectMatrix", &int_values(&[env, a.target, -1])).expect_err("erased");
    assert!(e.contains("environment"), "{e}");

    // The 4.2 functions that build an IK world object by object (tests/ik_objects.rs)
    // work on the environment's own objects; on scene objects, those that would reshape
    // the scene's tree are refused, saying what to use instead.
    let env = int(&call(&mut a.sim, "simIK.createEnvironment", &[]).expect("env")[0]);
    for (f, args) in [
        ("simIK.setObjectParent", int_values(&[env, a.joints[1], -1])),
        ("simIK.setJointMode", int_values(&[env, a.joints[1], 0])),
        ("simIK.setLinkedDummy", int_values(&[env, a.tip, a.target])),
        ("simIK.eraseObject", int_values(&[env, a.target])),
    ] {
        let e = call(&mut a.sim, f, &args).expect_err(f);
        assert!(e.contains(f) && e.contains("scene object") && e.contains("use "), "{e}");
    }
}
