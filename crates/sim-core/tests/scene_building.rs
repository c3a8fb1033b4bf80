//! Building a scene through the registry, as the editor, a Lua script or a remote client
//! does: `sim.createPrimitiveShape`, `sim.createJoint`, `sim.createProximitySensor`,
//! `sim.createVisionSensor`, `sim.createForceSensor`, `sim.createDummy`,
//! `sim.setObjectParent`, `sim.setObjectAlias`, then `sim.saveScene`; the saved file
//! loads back equal object by object (poses within 1e-9 m or rad, every parameter).

use gantry_sim_core::scene::{DiskFiles, LoadOptions, ObjectModelKind, ProximityModel, load_scene};
use gantry_sim_core::{Handle, Sim, Value};
use gantry_test_support::{TempDir, assert_contains, int};

use crate::util::{err, ok};

fn h(v: i64) -> Value {
    Value::Int(v)
}

fn floats(v: &[f64]) -> Value {
    Value::floats(v)
}

/// An empty scene in a folder of its own, where `sim.saveScene` may write.
fn empty_scene(dir: &TempDir) -> Sim {
    let path = dir.write("empty.toml", "[simulation]\ndt = 0.05\n");
    Sim::new(&load_scene(&DiskFiles, &path, &LoadOptions::default()).expect("scene loads"))
}

fn create(s: &mut Sim, name: &str, args: &[Value]) -> Handle {
    int(&ok(s, name, args)[0])
}

/// Places `child` below `parent` at `position` (m, in the parent's frame), lined up
/// with it.
fn attach(s: &mut Sim, child: Handle, parent: Handle, position: [f64; 3]) {
    ok(s, "setObjectParent", &[h(child), h(parent), Value::Bool(true)]);
    ok(s, "setObjectPosition", &[h(child), h(parent), floats(&position)]);
    ok(s, "setObjectOrientation", &[h(child), h(parent), floats(&[0.0; 3])]);
}

/// The lab sheet's BubbleRob, made by calls: a body sphere, two wheels on velocity
/// joints, a caster, a cone proximity sensor, a vision sensor, a force sensor holding
/// the caster and a dummy, placed as the tutorial places them: the body's centre 0.12 m
/// up, the wheels' axles (radius 0.04 m) and the caster (0.05 m) touching the ground.
/// Returns the body.
fn build_bubble_rob(s: &mut Sim) -> Handle {
    let body = create(s, "createPrimitiveShape", &[h(4), floats(&[0.2, 0.2, 0.2])]);
    ok(s, "setObjectAlias", &[h(body), Value::Str("bubbleRob".into())]);
    ok(s, "setObjectPosition", &[h(body), h(-1), floats(&[0.0, 0.0, 0.12])]);
    ok(s, "setObjectInt32Param", &[h(body), h(3003), h(0)]);
    ok(s, "setObjectInt32Param", &[h(body), h(3004), h(1)]);
    for (side, y) in [("left", 0.1), ("right", -0.1)] {
        let joint = create(s, "createJoint", &[h(10), h(5), h(1)]);
        ok(s, "setObjectAlias", &[h(joint), Value::Str(format!("{side}Motor"))]);
        attach(s, joint, body, [0.05, y, -0.08]);
        ok(
            s,
            "setObjectOrientation",
            &[h(joint), h(body), floats(&[-std::f64::consts::FRAC_PI_2, 0.0, 0.0])],
        );
        let wheel = create(s, "createPrimitiveShape", &[h(5), floats(&[0.08, 0.08, 0.02])]);
        ok(s, "setObjectAlias", &[h(wheel), Value::Str(format!("{side}Wheel"))]);
        attach(s, wheel, joint, [0.0, 0.0, 0.0]);
        ok(s, "setObjectInt32Param", &[h(wheel), h(3003), h(0)]);
        ok(s, "setObjectInt32Param", &[h(wheel), h(3004), h(1)]);
    }
    let caster_mount = create(
        s,
        "createForceSensor",
        &[h(0), Value::Array(vec![h(0); 5]), floats(&[0.01]), Value::Nil],
    );
    attach(s, caster_mount, body, [-0.07, 0.0, -0.095]);
    let caster = create(s, "createPrimitiveShape", &[h(4), floats(&[0.05, 0.05, 0.05])]);
    ok(s, "setObjectAlias", &[h(caster), Value::Str("caster".into())]);
    attach(s, caster, caster_mount, [0.0, 0.0, 0.0]);
    ok(s, "setObjectInt32Param", &[h(caster), h(3003), h(0)]);
    ok(s, "setObjectInt32Param", &[h(caster), h(3004), h(1)]);
    // A cone 0.5 m deep, 60 degrees wide, looking forward (+X of the body).
    let cone = [
        0.0,
        0.5,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        60f64.to_radians(),
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ];
    let sensor = create(
        s,
        "createProximitySensor",
        &[
            h(33),
            h(16),
            h(0),
            Value::Array(vec![h(0); 8]),
            floats(&cone),
            Value::Nil,
        ],
    );
    ok(s, "setObjectAlias", &[h(sensor), Value::Str("sensingNose".into())]);
    attach(s, sensor, body, [0.1, 0.0, 0.0]);
    ok(
        s,
        "setObjectOrientation",
        &[h(sensor), h(body), floats(&[0.0, std::f64::consts::FRAC_PI_2, 0.0])],
    );
    let camera = create(
        s,
        "createVisionSensor",
        &[
            h(2),
            Value::Array(vec![h(256), h(256), h(0), h(0)]),
            floats(&[0.01, 1.0, 1.0, 0.01, 0.01, 0.01]),
        ],
    );
    attach(s, camera, body, [0.08, 0.0, 0.05]);
    let marker = create(s, "createDummy", &[Value::Float(0.01)]);
    attach(s, marker, body, [0.0, 0.0, 0.1]);
    body
}

/// `text` with every number rounded to 9 significant digits, so that two descriptions
/// of the same value through a decimal file compare equal.
fn rounded(text: &str) -> String {
    let mut out = String::new();
    let mut number = String::new();
    let flush = |number: &mut String, out: &mut String| {
        if let Ok(v) = number.parse::<f64>() {
            let v = if v.abs() < 1e-12 { 0.0 } else { v };
            out.push_str(&format!("{v:.8e}"));
        } else {
            out.push_str(number);
        }
        number.clear();
    };
    for c in text.chars() {
        let in_number = c.is_ascii_digit()
            || (c == '.' || c == 'e' || c == '-' || c == '+') && !number.is_empty()
            || c == '-' && number.is_empty();
        if in_number {
            number.push(c);
        } else {
            flush(&mut number, &mut out);
            out.push(c);
        }
    }
    flush(&mut number, &mut out);
    out
}

#[test]
fn a_robot_built_by_calls_saves_and_loads_back_equal() {
    let dir = TempDir::new("scene_building");
    let mut s = empty_scene(&dir);
    build_bubble_rob(&mut s);
    let out = dir.path().join("built/bubble_rob.toml");
    ok(&mut s, "saveScene", &[Value::Str(out.to_string_lossy().into())]);
    let back = Sim::new(&load_scene(&DiskFiles, &out, &LoadOptions::default()).expect("the saved scene loads"));
    let (before, after) = (
        s.world.export_scene(None).expect("export").model,
        back.world.export_scene(None).expect("export").model,
    );
    let made = before.objects.iter().filter(|o| o.alias != "floor").count();
    assert_eq!(made, 10, "{:#?}", before.objects);
    assert_eq!(before.objects.len(), after.objects.len());
    for (a, b) in before.objects.iter().zip(&after.objects) {
        assert_eq!(a.alias, b.alias);
        assert_eq!(a.parent, b.parent, "{}", a.alias);
        let (pa, pb) = (a.local.translation.vector, b.local.translation.vector);
        assert!((pa - pb).norm() < 1e-9, "{}: {pa:?} vs {pb:?}", a.alias);
        assert!(a.local.rotation.angle_to(&b.local.rotation) < 1e-9, "{}", a.alias);
        assert_eq!(
            rounded(&format!("{:?}", a.kind)),
            rounded(&format!("{:?}", b.kind)),
            "{}",
            a.alias
        );
    }
    // The kinds the calls asked for, with CoppeliaSim's defaults for new objects.
    let by_alias = |alias: &str| after.objects.iter().find(|o| o.alias == alias).expect(alias);
    match &by_alias("leftMotor").kind {
        ObjectModelKind::Joint(j) => {
            assert!(j.cyclic && j.limits.is_none(), "{j:?}");
            assert_eq!(j.mode, gantry_sim_core::scene::JointMode::Velocity);
            assert_eq!(j.max_force, 2.5);
        }
        other => panic!("{other:?}"),
    }
    match &by_alias("sensingNose").kind {
        ObjectModelKind::ProximitySensor(ProximityModel::Cone { range, half_angle, .. }) => {
            assert!((range - 0.5).abs() < 1e-12 && (half_angle - 30f64.to_radians()).abs() < 1e-12);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_robot_built_by_calls_drives_on_its_joints() {
    let dir = TempDir::new("scene_building_drive");
    let mut s = empty_scene(&dir);
    let body = build_bubble_rob(&mut s);
    // A floor to drive on.
    let floor = create(&mut s, "createPrimitiveShape", &[h(3), floats(&[5.0, 5.0, 0.1])]);
    ok(
        &mut s,
        "setObjectPosition",
        &[h(floor), h(-1), floats(&[0.0, 0.0, -0.05])],
    );
    ok(&mut s, "setObjectInt32Param", &[h(floor), h(3004), h(1)]);
    for side in ["left", "right"] {
        let j = int(&ok(&mut s, "getObject", &[Value::Str(format!("/bubbleRob/{side}Motor"))])[0]);
        ok(&mut s, "setJointTargetForce", &[h(j), Value::Float(10.0)]);
        ok(&mut s, "setJointTargetVelocity", &[h(j), Value::Float(5.0)]);
    }
    let start = s.world.object(body).expect("body").world.translation.vector;
    for _ in 0..60 {
        s.step();
    }
    let end = s.world.object(body).expect("body").world.translation.vector;
    let moved = (end - start).xy().norm();
    // 5 rad/s on wheels of 0.04 m radius: 0.6 m in 3 s without slip; the caster, held
    // rigidly by the force sensor, slides on the floor with friction and the wheels slip.
    assert!((0.25..0.65).contains(&moved), "the rover moved {moved} m in 3 s");
}

#[test]
fn creating_joints_and_proximity_sensors_refuses_bad_input_and_changes_nothing() {
    let dir = TempDir::new("scene_building_bad");
    let mut s = empty_scene(&dir);
    let before = s.world.handles().len();
    let cases: Vec<(&str, Vec<Value>, &[&str])> = vec![
        (
            "createJoint",
            vec![h(12), h(5)],
            &["spherical joints are not supported"],
        ),
        (
            "createJoint",
            vec![h(99), h(5)],
            &["argument 1", "invalid joint type 99"],
        ),
        (
            "createJoint",
            vec![h(10), h(7)],
            &["argument 2", "invalid joint mode 7"],
        ),
        (
            "createJoint",
            vec![h(11), h(0), h(1)],
            &["only a revolute joint can be cyclic"],
        ),
        (
            "createJoint",
            vec![h(10), h(0), h(0), floats(&[f64::NAN, 0.1])],
            &["argument 4", "finite number", "NaN"],
        ),
        (
            "createJoint",
            vec![h(10), h(0), h(0), floats(&[0.1, -1.0])],
            &["argument 4", "finite and > 0"],
        ),
        (
            "createJoint",
            vec![h(10), h(0), h(0), Value::Str("big".into())],
            &["argument 4", "got string"],
        ),
    ];
    let mut cone = vec![0.0; 15];
    cone[1] = 0.5;
    cone[9] = 1.0;
    let proximity = |kind: i64, options: i64, f: &[f64]| {
        vec![
            h(kind),
            h(16),
            h(options),
            Value::Array(vec![h(0); 8]),
            floats(f),
            Value::Nil,
        ]
    };
    let mut negative_range = cone.clone();
    negative_range[1] = -0.5;
    let mut infinite_offset = cone.clone();
    infinite_offset[0] = f64::INFINITY;
    let mut wide_cone = cone.clone();
    wide_cone[9] = 4.0;
    let zero_pyramid = cone.clone();
    let mut zero_disc = cone.clone();
    zero_disc[3] = 0.0;
    let cases_p: Vec<(Vec<Value>, &[&str])> = vec![
        (proximity(33, 0, &negative_range), &["argument 5", "range", "-0.5"]),
        (proximity(33, 0, &infinite_offset), &["argument 5", "element 1", "inf"]),
        (proximity(33, 0, &wide_cone), &["cone angle", "4"]),
        (proximity(30, 0, &zero_pyramid), &["four sizes", "cannot all be 0"]),
        (proximity(32, 0, &zero_disc), &["disc thickness"]),
        (
            proximity(35, 0, &cone),
            &["argument 1", "invalid proximity sensor type 35"],
        ),
        (
            proximity(33, 512, &cone),
            &["randomized ray detection", "not supported"],
        ),
        (proximity(33, 0, &cone[..5]), &["argument 5", "at least 10 numbers"]),
    ];
    for (name, args, expected) in cases {
        let e = err(&mut s, name, &args);
        assert_contains(&e, expected);
    }
    for (args, expected) in cases_p {
        let e = err(&mut s, "createProximitySensor", &args);
        assert_contains(&e, expected);
    }
    assert_eq!(s.world.handles().len(), before, "a refused call created an object");
}
