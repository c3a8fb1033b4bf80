//! An IK world built object by object, as CoppeliaSim 4.2-4.5 scripts do: dummies and
//! joints created in an environment, parented, placed, linked, then an element added on
//! the tip and solved with `handleIkGroup` and `getConfigForTipPose`. The arm is checked
//! against forward kinematics written out here, independently of gantry's chain code; its
//! joint intervals, joint modes and group flags are honoured; bad input fails with a
//! message naming the function and what is wrong.

use crate::util;

use std::f64::consts::PI;

use gantry_sim_core::{Handle, Sim, Value};
use gantry_test_support::{floats, int, num};
use nalgebra::{Rotation3, Vector3};
use util::{call, int_values};

/// A scene with one dummy, so that mixing scene and IK objects can be tried.
fn sim() -> Sim {
    let text = "[simulation]\ndt = 0.05\n\n[[object]]\nname = \"ref\"\nkind = \"dummy\"\nposition = [1, 0, 0]\n";
    util::text_scene("../../assets/scenes/ik_objects.toml", text)
}

/// Calls a function that must succeed.
#[track_caller]
fn ok(s: &mut Sim, name: &str, args: &[Value]) -> Vec<Value> {
    call(s, name, args).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Calls a function that must fail, and returns its message.
#[track_caller]
fn err(s: &mut Sim, name: &str, args: &[Value]) -> String {
    match call(s, name, args) {
        Ok(v) => panic!("{name} succeeded with {v:?}"),
        Err(e) => {
            assert!(e.contains(name), "the message names the function: {e}");
            e
        }
    }
}

fn args(head: &[i64], tail: Value) -> Vec<Value> {
    let mut v = int_values(head);
    v.push(tail);
    v
}

/// A 3x4 row-major matrix (CoppeliaSim's layout) of a rotation and a translation.
fn matrix(r: Rotation3<f64>, p: [f64; 3]) -> Value {
    let m = r.matrix();
    Value::floats(&[
        m[(0, 0)],
        m[(0, 1)],
        m[(0, 2)],
        p[0],
        m[(1, 0)],
        m[(1, 1)],
        m[(1, 2)],
        p[1],
        m[(2, 0)],
        m[(2, 1)],
        m[(2, 2)],
        p[2],
    ])
}

/// Link lengths of the arm (m): base to shoulder height, shoulder to the slide's start,
/// slide's start to the tip.
const SHOULDER: f64 = 0.4;
const UPPER: f64 = 0.3;
const TOOL: f64 = 0.1;

/// The arm's forward kinematics, written out: joint 1 turns about world Z, joint 2 about
/// the (turned) Y axis at shoulder height, joint 3 slides along the upper arm. The tip
/// position in the world frame.
fn forward(q: [f64; 3]) -> Vector3<f64> {
    let reach = UPPER + TOOL + q[2];
    let in_plane = Rotation3::from_axis_angle(&Vector3::y_axis(), q[1]) * Vector3::new(reach, 0.0, 0.0);
    Rotation3::from_axis_angle(&Vector3::z_axis(), q[0]) * (Vector3::new(0.0, 0.0, SHOULDER) + in_plane)
}

/// The arm in an environment: base, three joints, tip, target.
struct Arm {
    s: Sim,
    env: i64,
    base: i64,
    joints: [i64; 3],
    tip: i64,
    target: i64,
    group: i64,
}

/// Builds the arm the way the 4.2 scripts do: create, place in the world, set the
/// position, then parent keeping the pose; link tip and target; a DLS group with one
/// position element based on the base dummy.
fn arm() -> Arm {
    let mut s = sim();
    let env = int(&ok(&mut s, "simIK.createEnvironment", &[])[0]);
    let base = int(&ok(&mut s, "simIK.createDummy", &int_values(&[env]))[0]);
    ok(
        &mut s,
        "simIK.setObjectMatrix",
        &[
            Value::Int(env),
            Value::Int(base),
            Value::Int(-1),
            matrix(Rotation3::identity(), [0.0; 3]),
        ],
    );
    // Joint 1 about world Z; joint 2 about world Y (its Z turned onto Y); joint 3 slides
    // along world X (its Z turned onto X), limited to [0, 0.3] m.
    let frames = [
        (10, Rotation3::identity(), [0.0, 0.0, 0.2]),
        (
            10,
            Rotation3::from_axis_angle(&Vector3::x_axis(), -PI / 2.0),
            [0.0, 0.0, SHOULDER],
        ),
        (
            11,
            Rotation3::from_axis_angle(&Vector3::y_axis(), PI / 2.0),
            [UPPER, 0.0, SHOULDER],
        ),
    ];
    let mut parent = base;
    let mut joints = [0; 3];
    for (k, (kind, r, p)) in frames.into_iter().enumerate() {
        let j = int(&ok(&mut s, "simIK.createJoint", &int_values(&[env, kind]))[0]);
        ok(&mut s, "simIK.setJointMode", &int_values(&[env, j, 2]));
        if kind == 11 {
            ok(
                &mut s,
                "simIK.setJointInterval",
                &[
                    Value::Int(env),
                    Value::Int(j),
                    Value::Bool(false),
                    Value::floats(&[0.0, 0.3]),
                ],
            );
        }
        ok(
            &mut s,
            "simIK.setJointPosition",
            &[Value::Int(env), Value::Int(j), Value::Float(0.0)],
        );
        ok(
            &mut s,
            "simIK.setObjectMatrix",
            &[Value::Int(env), Value::Int(j), Value::Int(-1), matrix(r, p)],
        );
        ok(
            &mut s,
            "simIK.setObjectParent",
            &[Value::Int(env), Value::Int(j), Value::Int(parent), Value::Bool(true)],
        );
        parent = j;
        joints[k] = j;
    }
    let tip = int(&ok(&mut s, "simIK.createDummy", &int_values(&[env]))[0]);
    ok(
        &mut s,
        "simIK.setObjectMatrix",
        &[
            Value::Int(env),
            Value::Int(tip),
            Value::Int(-1),
            matrix(Rotation3::identity(), [UPPER + TOOL, 0.0, SHOULDER]),
        ],
    );
    ok(
        &mut s,
        "simIK.setObjectParent",
        &[Value::Int(env), Value::Int(tip), Value::Int(parent), Value::Bool(true)],
    );
    let target = int(&ok(&mut s, "simIK.createDummy", &int_values(&[env]))[0]);
    ok(&mut s, "simIK.setLinkedDummy", &int_values(&[env, tip, target]));
    let group = int(&ok(&mut s, "simIK.createIkGroup", &int_values(&[env]))[0]);
    ok(
        &mut s,
        "simIK.setIkGroupCalculation",
        &[
            Value::Int(env),
            Value::Int(group),
            Value::Int(1),
            Value::Float(0.1),
            Value::Int(100),
        ],
    );
    let element = int(&ok(&mut s, "simIK.addIkElement", &int_values(&[env, group, tip]))[0]);
    ok(
        &mut s,
        "simIK.setIkElementBase",
        &int_values(&[env, group, element, base]),
    );
    ok(
        &mut s,
        "simIK.setIkElementConstraints",
        &int_values(&[env, group, element, 7]),
    );
    Arm {
        s,
        env,
        base,
        joints,
        tip,
        target,
        group,
    }
}

impl Arm {
    fn q(&mut self) -> [f64; 3] {
        let (env, joints) = (self.env, self.joints);
        joints.map(|j| num(&ok(&mut self.s, "simIK.getJointPosition", &int_values(&[env, j]))[0]))
    }

    fn set_q(&mut self, q: [f64; 3]) {
        for (j, v) in self.joints.into_iter().zip(q) {
            ok(
                &mut self.s,
                "simIK.setJointPosition",
                &[Value::Int(self.env), Value::Int(j), Value::Float(v)],
            );
        }
    }

    fn place_target(&mut self, p: Vector3<f64>) {
        ok(
            &mut self.s,
            "simIK.setObjectMatrix",
            &[
                Value::Int(self.env),
                Value::Int(self.target),
                Value::Int(-1),
                matrix(Rotation3::identity(), [p.x, p.y, p.z]),
            ],
        );
    }

    /// The tip's world position as the environment reports it.
    fn tip(&mut self) -> Vector3<f64> {
        let m = floats(
            &ok(
                &mut self.s,
                "simIK.getObjectMatrix",
                &int_values(&[self.env, self.tip, -1]),
            )[0],
        );
        Vector3::new(m[3], m[7], m[11])
    }

    fn handle(&mut self) -> i64 {
        int(&ok(&mut self.s, "simIK.handleIkGroup", &int_values(&[self.env, self.group]))[0])
    }
}

#[test]
fn the_built_arm_matches_forward_kinematics_at_any_configuration() {
    let mut a = arm();
    for q in [[0.0, 0.0, 0.0], [0.5, -0.4, 0.1], [-2.0, 0.9, 0.25], [3.0, -1.2, 0.05]] {
        a.set_q(q);
        let d = (a.tip() - forward(q)).norm();
        assert!(d < 1e-12, "q {q:?}: tip {} m from forward kinematics", d);
    }
    // The base is at the origin, and the tip relative to the base is the same.
    let m = floats(&ok(&mut a.s, "simIK.getObjectMatrix", &int_values(&[a.env, a.tip, a.base]))[0]);
    let q = a.q();
    assert!((Vector3::new(m[3], m[7], m[11]) - forward(q)).norm() < 1e-12);
}

#[test]
fn handle_ik_group_drives_the_tip_onto_the_linked_target() {
    let mut a = arm();
    let goal = [0.5, -0.4, 0.1];
    let target = forward(goal);
    a.place_target(target);
    assert_eq!(a.handle(), 1, "result_success");
    let q = a.q();
    let d = (forward(q) - target).norm();
    assert!(d < 5e-4, "forward kinematics of {q:?} is {d} m from the target");
    assert!((a.tip() - target).norm() < 5e-4);
    assert!(
        (0.0..=0.3).contains(&q[2]),
        "the slide stays within its interval: {q:?}"
    );

    // The 4.3 call reads the same: result, flags, precision.
    a.place_target(forward([-0.3, 0.2, 0.2]));
    let r = ok(&mut a.s, "simIK.handleGroup", &int_values(&[a.env, a.group]));
    assert_eq!(int(&r[0]), 1, "{r:?}");
    assert!(floats(&r[2])[0] < 5e-4);
}

#[test]
fn get_config_for_tip_pose_finds_a_configuration_without_moving_the_joints() {
    let mut a = arm();
    let target = forward([2.8, -0.6, 0.2]);
    a.place_target(target);
    let before = a.q();
    let r = ok(
        &mut a.s,
        "simIK.getConfigForTipPose",
        &[
            Value::Int(a.env),
            Value::Int(a.group),
            Value::Array(int_values(&a.joints)),
            Value::Float(0.65),
            Value::Int(100),
            Value::floats(&[1.0, 1.0, 1.0, 0.1]),
            Value::Str(String::new()),
        ],
    );
    let q = floats(&r[0]);
    assert_eq!(q.len(), 3);
    let d = (forward([q[0], q[1], q[2]]) - target).norm();
    assert!(d < 5e-4, "configuration {q:?} puts the tip {d} m from the target");
    assert_eq!(a.q(), before, "the IK joints did not move");

    // Out of reach: nil.
    a.place_target(Vector3::new(2.0, 0.0, SHOULDER));
    let r = ok(
        &mut a.s,
        "simIK.getConfigForTipPose",
        &[
            Value::Int(a.env),
            Value::Int(a.group),
            Value::Array(int_values(&a.joints)),
        ],
    );
    assert_eq!(r, vec![Value::Nil]);
}

#[test]
fn joint_intervals_and_modes_are_honoured() {
    // A limited shoulder stops on its limit.
    let mut a = arm();
    ok(
        &mut a.s,
        "simIK.setJointInterval",
        &[
            Value::Int(a.env),
            Value::Int(a.joints[1]),
            Value::Bool(false),
            Value::floats(&[-0.2, 0.4]),
        ],
    );
    let r = ok(&mut a.s, "simIK.getJointInterval", &int_values(&[a.env, a.joints[1]]));
    assert_eq!((&r[0], floats(&r[1])), (&Value::Bool(false), vec![-0.2, 0.4]));
    a.place_target(forward([0.3, -0.8, 0.1]));
    assert_eq!(a.handle(), 2, "result_fail: the shoulder cannot reach -0.8 rad");
    let q = a.q();
    assert!((-0.2 - 1e-12..=0.2 + 1e-12).contains(&q[1]), "{q:?}");
    assert!((q[1] + 0.2).abs() < 1e-6, "stopped on the limit: {q:?}");

    // A passive joint stays where it is: reachable with it fixed...
    let mut a = arm();
    ok(&mut a.s, "simIK.setJointMode", &int_values(&[a.env, a.joints[0], 0]));
    let r = ok(&mut a.s, "simIK.getJointMode", &int_values(&[a.env, a.joints[0]]));
    assert_eq!(int(&r[0]), 0);
    a.set_q([0.7, 0.0, 0.0]);
    let target = forward([0.7, 0.5, 0.2]);
    a.place_target(target);
    assert_eq!(a.handle(), 1);
    let q = a.q();
    assert_eq!(q[0], 0.7, "the passive joint kept its value");
    assert!((forward(q) - target).norm() < 5e-4);
    // ...and not when the target needs it to turn.
    a.place_target(forward([-0.7, 0.5, 0.2]));
    assert_eq!(a.handle(), 2);
    assert_eq!(a.q()[0], 0.7);

    // A cyclic joint wraps; a prismatic one clamps.
    let mut a = arm();
    a.set_q([3.0 * PI / 2.0, 0.0, 0.5]);
    let q = a.q();
    assert!((q[0] + PI / 2.0).abs() < 1e-12 && q[2] == 0.3, "{q:?}");
}

#[test]
fn group_flags_restore_the_joints_when_the_target_is_missed() {
    let mut a = arm();
    let start = [0.2, 0.1, 0.05];
    a.set_q(start);
    let far = Vector3::new(2.0, 0.0, SHOULDER);
    a.place_target(far);
    // Default flags (enabled, ignore max steps): a failed solve still moves the arm.
    assert_eq!(
        int(&ok(&mut a.s, "simIK.getGroupFlags", &int_values(&[a.env, a.group]))[0]),
        3
    );
    assert_eq!(a.handle(), 2);
    assert_ne!(a.q(), start);
    // With "restore on bad position", the joints keep their values.
    a.set_q(start);
    ok(
        &mut a.s,
        "simIK.setIkGroupFlags",
        &int_values(&[a.env, a.group, 1 + 2 + 4 + 8]),
    );
    assert_eq!(a.handle(), 2);
    assert_eq!(a.q(), start);
    // A disabled group is not performed.
    ok(&mut a.s, "simIK.setGroupFlags", &int_values(&[a.env, a.group, 0]));
    assert_eq!(a.handle(), 0, "result_not_performed");
}

#[test]
fn environments_have_their_own_namespaces() {
    let mut a = arm();
    let other = int(&ok(&mut a.s, "simIK.createEnvironment", &[])[0]);
    let d = int(&ok(&mut a.s, "simIK.createDummy", &args(&[other], "first".into()))[0]);
    assert_eq!(d, a.base, "each environment numbers its objects from the same start");
    assert_eq!(
        int(&ok(&mut a.s, "simIK.getObjectHandle", &args(&[other], "first".into()))[0]),
        d
    );
    assert_eq!(
        ok(&mut a.s, "simIK.doesObjectExist", &args(&[a.env], "first".into())),
        vec![Value::Bool(false)]
    );
    // Moving the other environment's object leaves this one's alone.
    ok(
        &mut a.s,
        "simIK.setObjectMatrix",
        &[
            Value::Int(other),
            Value::Int(d),
            matrix(Rotation3::identity(), [5.0, 0.0, 0.0]),
        ],
    );
    let m = floats(&ok(&mut a.s, "simIK.getObjectMatrix", &int_values(&[a.env, a.base]))[0]);
    assert_eq!((m[3], m[7], m[11]), (0.0, 0.0, 0.0));
    let pose = floats(&ok(&mut a.s, "simIK.getObjectPose", &int_values(&[other, d]))[0]);
    assert_eq!(pose, vec![5.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
    // The parent, type and link read back.
    let r = ok(&mut a.s, "simIK.getObjectParent", &int_values(&[a.env, a.tip]));
    assert_eq!(int(&r[0]), a.joints[2]);
    assert_eq!(
        int(&ok(&mut a.s, "simIK.getObjectType", &int_values(&[a.env, a.tip]))[0]),
        4
    );
    assert_eq!(
        int(&ok(&mut a.s, "simIK.getObjectType", &int_values(&[a.env, a.joints[0]]))[0]),
        1
    );
    assert_eq!(
        int(&ok(&mut a.s, "simIK.getJointType", &int_values(&[a.env, a.joints[2]]))[0]),
        11
    );
    assert_eq!(
        int(&ok(&mut a.s, "simIK.getLinkedDummy", &int_values(&[a.env, a.target]))[0]),
        a.tip
    );
    // Erasing the tip removes its element: the group has nothing left to do.
    ok(&mut a.s, "simIK.eraseObject", &int_values(&[a.env, a.tip]));
    assert_eq!(a.handle(), 0);
    // Erasing the environment erases its objects.
    ok(&mut a.s, "simIK.eraseEnvironment", &int_values(&[a.env]));
    let e = err(&mut a.s, "simIK.getJointPosition", &int_values(&[a.env, a.joints[0]]));
    assert!(e.contains("environment"), "{e}");
}

#[test]
fn bad_input_is_refused_with_a_clear_message() {
    let mut a = arm();
    let (env, j, tip) = (a.env, a.joints[0], a.tip);
    let s = &mut a.s;
    let scene_dummy: Handle = s.world.find("/ref", None, 0).expect("ref");
    let checks: Vec<(&str, Vec<Value>, &[&str])> = vec![
        (
            "simIK.createDummy",
            int_values(&[99]),
            &["environment 99 does not exist"],
        ),
        ("simIK.createJoint", int_values(&[env, 12]), &["spherical"]),
        ("simIK.createJoint", int_values(&[env, 7]), &["unknown joint type 7"]),
        (
            "simIK.getJointPosition",
            int_values(&[env, 10_000_999]),
            &["IK object 10000999 does not exist"],
        ),
        ("simIK.setJointMode", int_values(&[env, tip, 2]), &["is not a joint"]),
        (
            "simIK.setJointMode",
            int_values(&[env, j, 4]),
            &["unsupported joint mode 4"],
        ),
        ("simIK.setLinkedDummy", int_values(&[env, j, tip]), &["is not a dummy"]),
        ("simIK.setLinkedDummy", int_values(&[env, tip, tip]), &["itself"]),
        (
            "simIK.addIkElement",
            int_values(&[env, a.group, j]),
            &["is not a dummy"],
        ),
        (
            "simIK.setObjectParent",
            int_values(&[env, a.base, tip]),
            &["cannot become the parent"],
        ),
        (
            "simIK.setObjectParent",
            int_values(&[env, tip, scene_dummy]),
            &["scene object"],
        ),
        (
            "simIK.getObjectMatrix",
            int_values(&[env, tip, scene_dummy]),
            &["same tree"],
        ),
        (
            "simIK.getObjectPose",
            int_values(&[env, scene_dummy, tip]),
            &["same tree"],
        ),
        (
            "simIK.setIkGroupFlags",
            int_values(&[env, a.group, 16]),
            &["unsupported group flags 16"],
        ),
        (
            "simIK.getObjectHandle",
            vec![Value::Int(env), "nothing".into()],
            &["no IK object named 'nothing'"],
        ),
        (
            "simIK.addElementFromScene",
            int_values(&[env, a.group, -1, tip, a.target, 31]),
            &["not of the scene", "simIK.addElement"],
        ),
        (
            "simIK.setJointInterval",
            vec![
                Value::Int(env),
                Value::Int(j),
                Value::Bool(false),
                Value::floats(&[0.5, -1.0]),
            ],
            &["negative range", "above max"],
        ),
        (
            "simIK.setJointInterval",
            vec![
                Value::Int(env),
                Value::Int(a.joints[2]),
                Value::Bool(true),
                Value::floats(&[0.0, 1.0]),
            ],
            &["only a revolute joint can be cyclic"],
        ),
    ];
    for (f, args, parts) in checks {
        let e = err(s, f, &args);
        for p in parts {
            assert!(e.contains(p), "{f}: {e:?} does not say {p:?}");
        }
    }
    // An element's base must be in its tip's tree.
    let el = int(&ok(s, "simIK.addIkElement", &int_values(&[env, a.group, tip]))[0]);
    let e = err(
        s,
        "simIK.setIkElementBase",
        &int_values(&[env, a.group, el, scene_dummy]),
    );
    assert!(e.contains("is not below base"), "{e}");
    // A name can only be used once.
    ok(s, "simIK.createDummy", &args(&[env], "named".into()));
    let e = err(s, "simIK.createDummy", &args(&[env], "named".into()));
    assert!(e.contains("already exists"), "{e}");
    // A tip with no linked dummy has no target: the solve says so.
    ok(s, "simIK.setLinkedDummy", &int_values(&[env, tip, -1]));
    let e = err(s, "simIK.handleIkGroup", &int_values(&[env, a.group]));
    assert!(e.contains("has no target") && e.contains("simIK.setLinkedDummy"), "{e}");
    // Nothing above changed the arm.
    assert_eq!(a.q(), [0.0; 3]);
}
