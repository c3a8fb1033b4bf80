//! The scene as data: objects created, copied, removed, re-parented and restyled at run
//! time through the `sim.*` registry, with CoppeliaSim 4.6's argument forms and results.

use crate::util;

use gantry_sim_core::api::{self, CallContext};
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene_text};
use gantry_sim_core::{Handle, Sim, Value};
use gantry_test_support::{floats, int};
use util::{find, step};

/// A floor, a rotated dummy, a box carrying a kinematic hinge with a dynamic link, and a
/// vision sensor.
const SCENE: &str = r#"
[simulation]
dt = 0.05
substeps = 10

[floor]

[[object]]
name = "base"
kind = "dummy"
position = [1, 0, 0.5]
orientation_deg = [0, 0, 90]

[[object]]
name = "stand"
kind = "shape"
shape = "box"
size = [0.2, 0.2, 0.2]
position = [-1, 0, 0.1]

[[object]]
name = "hinge"
kind = "joint"
joint = "revolute"
parent = "stand"
position = [0, 0, 0.2]
mode = "kinematic"
max_force = 5

[[object]]
name = "link"
kind = "shape"
shape = "box"
size = [0.05, 0.05, 0.3]
parent = "hinge"
position = [0, 0, 0.2]
dynamic = true
mass = 1.0

[[object]]
name = "camera"
kind = "vision_sensor"
position = [0, -2, 1]
resolution = [32, 24]
fov_deg = 60
far = 2.0
"#;

// CoppeliaSim's constant values, as scripts pass them.
const CUBOID: i64 = 3;
const SHAPE_STATIC: i64 = 3003;
const SHAPE_RESPONDABLE: i64 = 3004;
const GRAVITY: i64 = 0;
const AMBIENT_DIFFUSE: i64 = 0;
const DT: f64 = 0.05;

fn world() -> Sim {
    util::text_scene("tests/scene_edit.toml", SCENE)
}

fn call(w: &mut Sim, name: &str, args: Vec<Value>) -> Result<Vec<Value>, String> {
    api::call(w, &CallContext::default(), name, &args).map_err(|e| e.to_string())
}

fn ok(w: &mut Sim, name: &str, args: Vec<Value>) -> Vec<Value> {
    call(w, name, args).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn err(w: &mut Sim, name: &str, args: Vec<Value>) -> String {
    match call(w, name, args) {
        Ok(r) => panic!("{name} should fail, returned {r:?}"),
        Err(e) => e,
    }
}

fn f(x: f64) -> Value {
    Value::Float(x)
}

fn i(x: i64) -> Value {
    Value::Int(x)
}

fn v3(x: f64, y: f64, z: f64) -> Value {
    Value::floats(&[x, y, z])
}

fn handles(hs: &[Handle]) -> Value {
    Value::Array(hs.iter().map(|&h| Value::Int(h)).collect())
}

fn position(w: &mut Sim, h: Handle) -> Vec<f64> {
    floats(&ok(w, "sim.getObjectPosition", vec![i(h), i(-1)])[0])
}

fn velocity(w: &mut Sim, h: Handle) -> Vec<f64> {
    floats(&ok(w, "sim.getObjectVelocity", vec![i(h)])[0])
}

/// A 10 cm cube at `at`, made dynamic and respondable as CoppeliaSim scripts do.
fn dynamic_cube(w: &mut Sim, at: [f64; 3]) -> Handle {
    let h = int(&ok(w, "sim.createPrimitiveShape", vec![i(CUBOID), v3(0.1, 0.1, 0.1)])[0]);
    ok(w, "sim.setObjectPosition", vec![i(h), v3(at[0], at[1], at[2])]);
    ok(w, "sim.setObjectInt32Param", vec![i(h), i(SHAPE_STATIC), i(0)]);
    ok(w, "sim.setObjectInt32Param", vec![i(h), i(SHAPE_RESPONDABLE), i(1)]);
    h
}

#[test]
fn created_cuboid_is_static_until_made_dynamic_then_lands_on_the_floor() {
    let mut w = world();
    let h = int(&ok(
        &mut w,
        "sim.createPrimitiveShape",
        vec![i(CUBOID), v3(0.1, 0.1, 0.1), i(0)],
    )[0]);
    assert_eq!(int(&ok(&mut w, "sim.getObjectType", vec![i(h)])[0]), 0, "a shape");
    assert_eq!(
        int(&ok(&mut w, "sim.getObjectInt32Param", vec![i(h), i(SHAPE_STATIC)])[0]),
        1
    );
    assert_eq!(
        int(&ok(&mut w, "sim.getObjectInt32Param", vec![i(h), i(SHAPE_RESPONDABLE)])[0]),
        0
    );
    assert_eq!(position(&mut w, h), vec![0.0, 0.0, 0.0], "created at the origin");
    ok(&mut w, "sim.setObjectPosition", vec![i(h), v3(0.5, 0.5, 1.0)]);
    ok(&mut w, "sim.setObjectInt32Param", vec![i(h), i(SHAPE_STATIC), i(0)]);
    ok(
        &mut w,
        "sim.setObjectInt32Param",
        vec![i(h), i(SHAPE_RESPONDABLE), i(1)],
    );
    step(&mut w, 4);
    let z = position(&mut w, h)[2];
    assert!(z < 0.9, "falls: z = {z}");
    step(&mut w, 60);
    let p = position(&mut w, h);
    assert!((p[2] - 0.05).abs() < 0.01, "rests on the floor: {p:?}");
    assert!(velocity(&mut w, h)[2].abs() < 0.05);
}

#[test]
fn static_shape_stays_put() {
    let mut w = world();
    let h = int(&ok(&mut w, "sim.createPrimitiveShape", vec![i(CUBOID), v3(0.1, 0.1, 0.1)])[0]);
    ok(&mut w, "sim.setObjectPosition", vec![i(h), v3(0.5, 0.5, 1.0)]);
    ok(
        &mut w,
        "sim.setObjectInt32Param",
        vec![i(h), i(SHAPE_RESPONDABLE), i(1)],
    );
    step(&mut w, 20);
    assert_eq!(position(&mut w, h), vec![0.5, 0.5, 1.0]);
    // And a dynamic one made static again stops.
    let d = dynamic_cube(&mut w, [-0.5, 0.5, 1.0]);
    step(&mut w, 2);
    ok(&mut w, "sim.setObjectInt32Param", vec![i(d), i(SHAPE_STATIC), i(1)]);
    let before = position(&mut w, d);
    step(&mut w, 10);
    assert_eq!(position(&mut w, d), before);
}

#[test]
fn every_primitive_can_be_created_and_falls() {
    let mut w = world();
    for (k, kind) in [1, 2, 3, 4, 5, 6, 8].into_iter().enumerate() {
        for sizes in [[0.1, 0.1, 0.1], [0.1, 0.06, 0.08]] {
            let h = int(&ok(&mut w, "sim.createPrimitiveShape", vec![i(kind), Value::floats(&sizes)])[0]);
            let x = k as f64 * 0.3 - 1.0;
            let y = if sizes[1] == 0.1 { 1.0 } else { 1.5 };
            ok(&mut w, "sim.setObjectPosition", vec![i(h), v3(x, y, 0.5)]);
            ok(&mut w, "sim.setObjectInt32Param", vec![i(h), i(SHAPE_STATIC), i(0)]);
            ok(
                &mut w,
                "sim.setObjectInt32Param",
                vec![i(h), i(SHAPE_RESPONDABLE), i(1)],
            );
        }
    }
    let created: Vec<Handle> = (0..w.world.len() as Handle)
        .filter(|&h| w.world.object(h).is_ok_and(|o| o.kind.type_code() == 0) && h > find(&w, "/camera"))
        .collect();
    assert_eq!(created.len(), 14);
    step(&mut w, 60);
    for h in created {
        let z = position(&mut w, h)[2];
        assert!(z < 0.2 && z > -0.01, "shape {h} ends on the floor, z = {z}");
    }
}

#[test]
fn removed_handles_error_and_are_never_reused() {
    let mut w = world();
    let a = int(&ok(&mut w, "sim.createDummy", vec![f(0.05)])[0]);
    ok(&mut w, "sim.removeObjects", vec![handles(&[a])]);
    let e = err(&mut w, "sim.getObjectPosition", vec![i(a), i(-1)]);
    assert!(e.contains("object does not exist"), "{e}");
    assert!(e.ends_with("(in function 'sim.getObjectPosition')"), "{e}");
    for name in [
        "sim.getObjectAlias",
        "sim.getObjectParent",
        "sim.removeObject",
        "sim.getObjectType",
    ] {
        let e = err(&mut w, name, vec![i(a)]);
        assert!(e.contains("object does not exist"), "{name}: {e}");
    }
    let b = int(&ok(&mut w, "sim.createDummy", vec![f(0.05)])[0]);
    assert!(b > a, "handle {a} was reused as {b}");
    // The older one-object name.
    ok(&mut w, "sim.removeObject", vec![i(b)]);
    let c = int(&ok(&mut w, "sim.createDummy", vec![f(0.05)])[0]);
    assert!(c > b);
    // All or nothing: one bad handle removes nothing.
    let e = err(&mut w, "sim.removeObjects", vec![handles(&[c, b])]);
    assert!(e.contains("object does not exist"), "{e}");
    assert!(w.world.object(c).is_ok());
    // Removed objects are not found by path either, nor listed.
    assert!(!w.world.handles().contains(&a) && !w.world.handles().contains(&b));
    let all = floats(&ok(&mut w, "sim.getObjectsInTree", vec![i(-12)])[0]);
    assert!(!all.contains(&(a as f64)) && all.contains(&(c as f64)));
}

#[test]
fn removing_a_parent_keeps_its_children_where_they_are() {
    let mut w = world();
    let base = find(&w, "/base");
    let child = int(&ok(&mut w, "sim.createDummy", vec![f(0.05)])[0]);
    ok(
        &mut w,
        "sim.setObjectParent",
        vec![i(child), i(base), Value::Bool(true)],
    );
    ok(
        &mut w,
        "sim.setObjectPosition",
        vec![i(child), v3(0.2, 0.0, 0.0), i(base)],
    );
    let before = position(&mut w, child);
    // Things attached to the removed object go with it.
    let drawing = int(&ok(
        &mut w,
        "sim.addDrawingObject",
        vec![i(0), f(2.0), f(0.0), i(base), i(10), v3(1.0, 0.0, 0.0)],
    )[0]);
    let coll = int(&ok(&mut w, "sim.createCollection", vec![i(0)])[0]);
    ok(&mut w, "sim.addItemToCollection", vec![i(coll), i(-8), i(base), i(0)]);
    ok(&mut w, "sim.removeObjects", vec![handles(&[base])]);
    assert_eq!(int(&ok(&mut w, "sim.getObjectParent", vec![i(child)])[0]), -1);
    let after = position(&mut w, child);
    for k in 0..3 {
        assert!((after[k] - before[k]).abs() < 1e-9, "{after:?} vs {before:?}");
    }
    assert!(
        w.drawings.get(drawing).is_none(),
        "the drawing attached to the removed object is gone"
    );
    let stand = find(&w, "/stand");
    let r = ok(&mut w, "sim.checkDistance", vec![i(coll), i(stand)]);
    assert_eq!(int(&r[0]), 0, "the collection is empty now");
    // The moved child and a removed subtree root still step without trouble.
    step(&mut w, 3);
}

#[test]
fn removing_a_mechanism_part_leaves_a_working_world() {
    let mut w = world();
    let (stand, hinge, link) = (
        find(&w, "/stand"),
        find(&w, "/stand/hinge"),
        find(&w, "/stand/hinge/link"),
    );
    ok(&mut w, "sim.setJointMode", vec![i(hinge), i(5), i(0)]);
    ok(&mut w, "sim.removeObjects", vec![handles(&[hinge])]);
    // The dynamic link, no longer below a joint, is a free body on the stand and falls
    // until it lies somewhere.
    assert_eq!(int(&ok(&mut w, "sim.getObjectParent", vec![i(link)])[0]), stand);
    step(&mut w, 40);
    let z = position(&mut w, link)[2];
    assert!(z < 0.35, "the link fell: z = {z}");
    ok(&mut w, "sim.removeObjects", vec![handles(&[stand, link])]);
    step(&mut w, 3);
    assert!(w.world.handles().iter().all(|&h| w.world.object(h).is_ok()));
}

#[test]
fn copy_of_a_dynamic_shape_has_its_own_physics() {
    let mut w = world();
    let h = dynamic_cube(&mut w, [0.0, 0.5, 1.0]);
    ok(
        &mut w,
        "sim.setShapeColor",
        vec![i(h), Value::Nil, i(AMBIENT_DIFFUSE), v3(1.0, 0.0, 0.0)],
    );
    let copies = floats(&ok(&mut w, "sim.copyPasteObjects", vec![handles(&[h]), i(0)])[0]);
    assert_eq!(copies.len(), 1);
    let c = copies[0] as Handle;
    assert!(c > h);
    assert_eq!(
        ok(&mut w, "sim.getObjectAlias", vec![i(c)]),
        ok(&mut w, "sim.getObjectAlias", vec![i(h)])
    );
    assert_eq!(position(&mut w, c), position(&mut w, h), "pasted where the original is");
    assert_eq!(
        floats(&ok(&mut w, "sim.getShapeColor", vec![i(c), Value::Nil, i(0)])[1]),
        vec![1.0, 0.0, 0.0]
    );
    ok(&mut w, "sim.setObjectPosition", vec![i(c), v3(0.5, 0.5, 1.0)]);
    step(&mut w, 60);
    for (x, shape) in [(0.0, h), (0.5, c)] {
        let p = position(&mut w, shape);
        assert!((p[2] - 0.05).abs() < 0.01 && (p[0] - x).abs() < 0.01, "{shape}: {p:?}");
    }
}

#[test]
fn copying_a_subtree_keeps_it_together() {
    let mut w = world();
    let (stand, hinge, link) = (
        find(&w, "/stand"),
        find(&w, "/stand/hinge"),
        find(&w, "/stand/hinge/link"),
    );
    let copies = floats(&ok(&mut w, "sim.copyPasteObjects", vec![handles(&[stand, hinge, link])])[0]);
    let [s, j, l] = [copies[0], copies[1], copies[2]].map(|x| x as Handle);
    assert_eq!(int(&ok(&mut w, "sim.getObjectParent", vec![i(s)])[0]), -1);
    assert_eq!(int(&ok(&mut w, "sim.getObjectParent", vec![i(j)])[0]), s);
    assert_eq!(int(&ok(&mut w, "sim.getObjectParent", vec![i(l)])[0]), j);
    ok(&mut w, "sim.setObjectPosition", vec![i(s), v3(-1.0, 1.0, 0.1)]);
    ok(&mut w, "sim.setJointPosition", vec![i(j), f(0.5)]);
    let p = position(&mut w, l);
    assert!((p[1] - 1.0).abs() < 1e-9 && (p[2] - 0.5).abs() < 1e-9, "{p:?}");
    // The original did not move.
    assert_eq!(
        ok(&mut w, "sim.getJointPosition", vec![i(hinge)])[0].as_f64(),
        Some(0.0)
    );
}

#[test]
fn set_object_parent_keeps_or_moves_the_world_pose() {
    let mut w = world();
    let base = find(&w, "/base"); // at (1, 0, 0.5), turned 90° about Z
    let h = int(&ok(&mut w, "sim.createDummy", vec![f(0.05)])[0]);
    ok(&mut w, "sim.setObjectPosition", vec![i(h), v3(2.0, 0.0, 0.5)]);
    // keepInPlace defaults to true: the world pose stays, the local one changes.
    ok(&mut w, "sim.setObjectParent", vec![i(h), i(base)]);
    assert_eq!(int(&ok(&mut w, "sim.getObjectParent", vec![i(h)])[0]), base);
    let p = position(&mut w, h);
    assert!(
        (p[0] - 2.0).abs() < 1e-9 && p[1].abs() < 1e-9 && (p[2] - 0.5).abs() < 1e-9,
        "{p:?}"
    );
    let local = floats(&ok(&mut w, "sim.getObjectPosition", vec![i(h), i(-11)])[0]);
    assert!(
        local[0].abs() < 1e-9 && (local[1] + 1.0).abs() < 1e-9 && local[2].abs() < 1e-9,
        "{local:?}"
    );
    // keepInPlace false: the local pose stays, so the object moves with its new frame.
    ok(&mut w, "sim.setObjectParent", vec![i(h), i(-1), Value::Bool(false)]);
    let p = position(&mut w, h);
    assert!(
        p[0].abs() < 1e-9 && (p[1] + 1.0).abs() < 1e-9 && p[2].abs() < 1e-9,
        "{p:?}"
    );
    ok(&mut w, "sim.setObjectParent", vec![i(h), i(base), Value::Bool(false)]);
    let p = position(&mut w, h);
    assert!(
        (p[0] - 2.0).abs() < 1e-9 && p[1].abs() < 1e-9 && (p[2] - 0.5).abs() < 1e-9,
        "{p:?}"
    );
    // No loops.
    let e = err(&mut w, "sim.setObjectParent", vec![i(base), i(h), Value::Bool(true)]);
    assert!(e.contains("cannot become its parent"), "{e}");
    let e = err(&mut w, "sim.setObjectParent", vec![i(h), i(h)]);
    assert!(e.contains("cannot become its parent"), "{e}");
    // Paths follow the new tree.
    ok(&mut w, "sim.setObjectAlias", vec![i(h), Value::Str("marker".into())]);
    assert_eq!(find(&w, "/base/marker"), h);
}

#[test]
fn reparenting_a_dynamic_shape_keeps_it_simulated() {
    let mut w = world();
    let base = find(&w, "/base");
    let h = dynamic_cube(&mut w, [1.0, 1.0, 1.0]);
    ok(&mut w, "sim.setObjectParent", vec![i(h), i(base), Value::Bool(true)]);
    step(&mut w, 60);
    let p = position(&mut w, h);
    assert!(
        (p[2] - 0.05).abs() < 0.01,
        "a dynamic child of a dummy still falls: {p:?}"
    );
}

#[test]
fn get_object_child_follows_hierarchy_order() {
    let mut w = world();
    let base = find(&w, "/base");
    assert_eq!(int(&ok(&mut w, "sim.getObjectChild", vec![i(base), i(0)])[0]), -1);
    let kids: Vec<Handle> = (0..3)
        .map(|_| {
            let h = int(&ok(&mut w, "sim.createDummy", vec![f(0.01)])[0]);
            ok(&mut w, "sim.setObjectParent", vec![i(h), i(base), Value::Bool(true)]);
            h
        })
        .collect();
    for (k, &h) in kids.iter().enumerate() {
        assert_eq!(int(&ok(&mut w, "sim.getObjectChild", vec![i(base), i(k as i64)])[0]), h);
    }
    assert_eq!(int(&ok(&mut w, "sim.getObjectChild", vec![i(base), i(3)])[0]), -1);
    assert_eq!(int(&ok(&mut w, "sim.getObjectChild", vec![i(base), i(-1)])[0]), -1);
    // A re-parented child comes last.
    ok(&mut w, "sim.setObjectParent", vec![i(kids[0]), i(-1)]);
    ok(&mut w, "sim.setObjectParent", vec![i(kids[0]), i(base)]);
    let order: Vec<i64> = (0..3)
        .map(|k| int(&ok(&mut w, "sim.getObjectChild", vec![i(base), i(k)])[0]))
        .collect();
    assert_eq!(order, vec![kids[1], kids[2], kids[0]]);
    // The older enumeration: index-th object of a type, in creation order.
    let dummies: Vec<i64> = (0..10)
        .map(|k| int(&ok(&mut w, "sim.getObjects", vec![i(k), i(4)])[0]))
        .take_while(|&h| h != -1)
        .collect();
    assert_eq!(dummies, vec![base, kids[0], kids[1], kids[2]]);
    assert_eq!(int(&ok(&mut w, "sim.getObjects", vec![i(0), i(-2)])[0]), 0);
    assert_eq!(int(&ok(&mut w, "sim.getObjects", vec![i(1000), i(-2)])[0]), -1);
}

#[test]
fn colors_round_trip() {
    let mut w = world();
    let h = int(&ok(&mut w, "sim.createPrimitiveShape", vec![i(CUBOID), v3(0.1, 0.1, 0.1)])[0]);
    let r = ok(&mut w, "sim.getShapeColor", vec![i(h), Value::Nil, i(AMBIENT_DIFFUSE)]);
    assert_eq!((int(&r[0]), floats(&r[1])), (1, vec![1.0, 1.0, 1.0]), "created white");
    let rev = w.world.scene_revision();
    ok(
        &mut w,
        "sim.setShapeColor",
        vec![i(h), Value::Nil, i(AMBIENT_DIFFUSE), v3(0.2, 0.4, 0.6)],
    );
    assert!(w.world.scene_revision() > rev, "the viewer learns of the change");
    let r = ok(
        &mut w,
        "sim.getShapeColor",
        vec![i(h), Value::Str(String::new()), i(AMBIENT_DIFFUSE)],
    );
    assert_eq!(int(&r[0]), 1);
    for (got, want) in floats(&r[1]).iter().zip([0.2, 0.4, 0.6]) {
        assert!((got - want).abs() < 1e-6, "{got} vs {want}");
    }
    // Other components are kept; transparency has one value; values are clamped.
    ok(
        &mut w,
        "sim.setShapeColor",
        vec![i(h), Value::Nil, i(3), v3(2.0, 0.5, -1.0)],
    );
    assert_eq!(
        floats(&ok(&mut w, "sim.getShapeColor", vec![i(h), Value::Nil, i(3)])[1]),
        vec![1.0, 0.5, 0.0]
    );
    ok(
        &mut w,
        "sim.setShapeColor",
        vec![i(h), Value::Nil, i(4), Value::floats(&[0.3])],
    );
    assert_eq!(
        floats(&ok(&mut w, "sim.getShapeColor", vec![i(h), Value::Nil, i(4)])[1]),
        vec![0.3]
    );
    // gantry's shapes have no named parts: a name matches nothing.
    let r = ok(
        &mut w,
        "sim.getShapeColor",
        vec![i(h), Value::Str("wheel".into()), i(AMBIENT_DIFFUSE)],
    );
    assert_eq!(int(&r[0]), 0);
    let e = err(
        &mut w,
        "sim.setShapeColor",
        vec![i(h), Value::Nil, i(9), v3(0.0, 0.0, 0.0)],
    );
    assert!(e.contains("invalid color component"), "{e}");
    let e = err(
        &mut w,
        "sim.setShapeColor",
        vec![i(h), Value::Nil, i(0), Value::floats(&[0.1])],
    );
    assert!(e.contains("3 finite values"), "{e}");
}

#[test]
fn mass_sets_how_a_force_accelerates_a_body() {
    let mut w = world();
    ok(&mut w, "sim.setArrayParam", vec![i(GRAVITY), v3(0.0, 0.0, 0.0)]);
    let h = dynamic_cube(&mut w, [0.0, 0.0, 2.0]);
    let density_mass = ok(&mut w, "sim.getShapeMass", vec![i(h)])[0].as_f64().expect("mass");
    assert!(
        (density_mass - 1.0).abs() < 1e-9,
        "1000 kg/m³ over a litre: {density_mass}"
    );
    for (mass, force) in [(2.0, 10.0), (4.0, 10.0), (0.5, 3.0)] {
        ok(&mut w, "sim.setShapeMass", vec![i(h), f(mass)]);
        assert_eq!(ok(&mut w, "sim.getShapeMass", vec![i(h)])[0].as_f64(), Some(mass));
        let v0 = velocity(&mut w, h)[0];
        let com = position(&mut w, h);
        ok(
            &mut w,
            "sim.addForce",
            vec![i(h), Value::floats(&com), v3(force, 0.0, 0.0)],
        );
        step(&mut w, 1);
        let dv = velocity(&mut w, h)[0] - v0;
        let expected = force / mass * DT; // F = m a over one step
        assert!(
            (dv - expected).abs() < 0.02 * expected,
            "m = {mass}: dv {dv} vs {expected}"
        );
        // The force acted for that step only.
        let v1 = velocity(&mut w, h)[0];
        step(&mut w, 2);
        let v2 = velocity(&mut w, h)[0];
        assert!((v2 - v1).abs() < 1e-4 * v1.abs().max(1.0), "m = {mass}: {v1} then {v2}");
    }
    // addForceAndTorque acts at the centre of mass; forces added before a step add up.
    ok(&mut w, "sim.setShapeMass", vec![i(h), f(1.0)]);
    let v0 = velocity(&mut w, h);
    ok(&mut w, "sim.addForceAndTorque", vec![i(h), v3(0.0, 2.0, 0.0)]);
    ok(
        &mut w,
        "sim.addForceAndTorque",
        vec![i(h), v3(0.0, 2.0, 0.0), Value::Nil],
    );
    step(&mut w, 1);
    let dv = velocity(&mut w, h)[1] - v0[1];
    assert!((dv - 4.0 * DT).abs() < 0.02 * 4.0 * DT, "dv {dv}");
    // sim.handleflag_resetforce clears what was added.
    ok(&mut w, "sim.addForceAndTorque", vec![i(h), v3(0.0, 0.0, 5.0)]);
    ok(&mut w, "sim.addForceAndTorque", vec![i(h | 0x40_0000)]);
    let vz = velocity(&mut w, h)[2];
    step(&mut w, 1);
    assert!((velocity(&mut w, h)[2] - vz).abs() < 1e-6);
    // A force off the centre of mass also turns the body.
    let com = position(&mut w, h);
    ok(
        &mut w,
        "sim.addForce",
        vec![i(h), v3(com[0], com[1] + 0.05, com[2]), v3(0.0, 0.0, 1.0)],
    );
    step(&mut w, 1);
    let w_ang = floats(&ok(&mut w, "sim.getObjectVelocity", vec![i(h)])[1]);
    assert!(w_ang[0] > 0.1, "spins about +X: {w_ang:?}");
}

#[test]
fn gravity_parameter_changes_a_falling_bodys_acceleration() {
    let mut w = world();
    let g = floats(&ok(&mut w, "sim.getArrayParam", vec![i(GRAVITY)])[0]);
    assert_eq!(g, vec![0.0, 0.0, -9.81]);
    let h = dynamic_cube(&mut w, [0.0, 0.0, 10.0]);
    let v0 = velocity(&mut w, h)[2];
    step(&mut w, 1);
    let v1 = velocity(&mut w, h)[2];
    assert!(((v1 - v0) + 9.81 * DT).abs() < 0.01 * 9.81 * DT, "dv {}", v1 - v0);
    ok(&mut w, "sim.setArrayParam", vec![i(GRAVITY), v3(0.0, 0.0, -2.0)]);
    assert_eq!(
        floats(&ok(&mut w, "sim.getArrayParam", vec![i(GRAVITY)])[0]),
        vec![0.0, 0.0, -2.0]
    );
    step(&mut w, 1);
    let v2 = velocity(&mut w, h)[2];
    assert!(((v2 - v1) + 2.0 * DT).abs() < 0.01 * 2.0 * DT, "dv {}", v2 - v1);
    ok(&mut w, "sim.setArrayParam", vec![i(GRAVITY), v3(1.0, 0.0, 0.0)]);
    step(&mut w, 1);
    let v3_ = velocity(&mut w, h);
    assert!((v3_[0] - DT).abs() < 0.01 * DT && (v3_[2] - v2).abs() < 1e-6, "{v3_:?}");
    let e = err(
        &mut w,
        "sim.setArrayParam",
        vec![i(GRAVITY), Value::floats(&[0.0, 1.0])],
    );
    assert!(e.contains("argument 2"), "{e}");
}

#[test]
fn joint_mode_and_max_force() {
    let mut w = world();
    let (hinge, link) = (find(&w, "/stand/hinge"), find(&w, "/stand/hinge/link"));
    assert_eq!(ok(&mut w, "sim.getJointMode", vec![i(hinge)]), vec![i(0), i(0)]);
    let before = position(&mut w, link);
    ok(&mut w, "sim.setJointMode", vec![i(hinge), i(5), i(0)]);
    assert_eq!(ok(&mut w, "sim.getJointMode", vec![i(hinge)]), vec![i(5), i(0)]);
    assert_eq!(
        int(&ok(&mut w, "sim.getObjectInt32Param", vec![i(hinge), i(2039)])[0]),
        8,
        "position control"
    );
    ok(&mut w, "sim.setJointMaxForce", vec![i(hinge), f(7.0)]);
    assert_eq!(
        ok(&mut w, "sim.getJointMaxForce", vec![i(hinge)])[0].as_f64(),
        Some(7.0)
    );
    assert_eq!(
        ok(&mut w, "sim.getJointTargetForce", vec![i(hinge)])[0].as_f64(),
        Some(7.0)
    );
    // Simulated now, held where it was (gravity acts along the hinge axis).
    step(&mut w, 10);
    let after = position(&mut w, link);
    for k in 0..3 {
        assert!((after[k] - before[k]).abs() < 2e-3, "{after:?} vs {before:?}");
    }
    // A velocity controller turns it.
    ok(&mut w, "sim.setObjectInt32Param", vec![i(hinge), i(2039), i(4)]);
    ok(&mut w, "sim.setJointTargetVelocity", vec![i(hinge), f(1.0)]);
    ok(&mut w, "sim.setObjectFloatParam", vec![i(hinge), i(2004), f(5.0)]);
    assert_eq!(
        ok(&mut w, "sim.getObjectFloatParam", vec![i(hinge), i(2004)])[0].as_f64(),
        Some(5.0)
    );
    step(&mut w, 20);
    let q = ok(&mut w, "sim.getJointPosition", vec![i(hinge)])[0]
        .as_f64()
        .expect("q");
    assert!(q > 0.3, "turned: {q}");
    ok(&mut w, "sim.setJointMode", vec![i(hinge), i(0)]);
    assert_eq!(ok(&mut w, "sim.getJointMode", vec![i(hinge)]), vec![i(0), i(0)]);
    let e = err(&mut w, "sim.setJointMode", vec![i(hinge), i(3)]);
    assert!(e.contains("invalid joint mode"), "{e}");
    let e = err(&mut w, "sim.setJointMode", vec![i(hinge), i(4)]);
    assert!(e.contains("mimic"), "{e}");
    let e = err(&mut w, "sim.setJointMode", vec![i(link), i(0)]);
    assert!(e.contains("not a joint"), "{e}");
    ok(&mut w, "sim.setObjectFloatParam", vec![i(hinge), i(2036), f(0.5)]);
    assert_eq!(
        ok(&mut w, "sim.getObjectFloatParam", vec![i(hinge), i(2036)])[0].as_f64(),
        Some(0.5)
    );
}

#[test]
fn reset_dynamic_object_stops_a_falling_body() {
    let mut w = world();
    let h = dynamic_cube(&mut w, [0.0, 0.0, 3.0]);
    step(&mut w, 5);
    assert!(velocity(&mut w, h)[2] < -1.0);
    let p = position(&mut w, h);
    ok(&mut w, "sim.resetDynamicObject", vec![i(h)]);
    assert_eq!(velocity(&mut w, h), vec![0.0, 0.0, 0.0]);
    assert_eq!(position(&mut w, h), p);
    step(&mut w, 1);
    assert!(velocity(&mut w, h)[2] < 0.0, "and it falls on from rest");
    ok(&mut w, "sim.resetDynamicObject", vec![i(-2)]);
}

#[test]
fn object_and_simulation_parameters() {
    let mut w = world();
    let h = int(&ok(&mut w, "sim.createPrimitiveShape", vec![i(CUBOID), v3(0.1, 0.2, 0.3)])[0]);
    let bbox: Vec<f64> = (15..=20)
        .map(|id| {
            ok(&mut w, "sim.getObjectFloatParam", vec![i(h), i(id)])[0]
                .as_f64()
                .expect("number")
        })
        .collect();
    let want = [-0.05, -0.1, -0.15, 0.05, 0.1, 0.15];
    for (g, e) in bbox.iter().zip(want) {
        assert!((g - e).abs() < 1e-12, "{bbox:?}");
    }
    assert_eq!(
        int(&ok(&mut w, "sim.getObjectInt32Param", vec![i(h), i(10)])[0]),
        1,
        "layer 1"
    );
    ok(&mut w, "sim.setObjectInt32Param", vec![i(h), i(10), i(0)]);
    assert_eq!(int(&ok(&mut w, "sim.getObjectInt32Param", vec![i(h), i(10)])[0]), 0);
    let mass = ok(&mut w, "sim.getObjectFloatParam", vec![i(h), i(3005)])[0]
        .as_f64()
        .expect("kg");
    assert!((mass - 6.0).abs() < 1e-9, "1000 kg/m³ over 6 litres: {mass}");
    // A parameter that does not apply is "not retrieved": nothing comes back, no error.
    assert!(ok(&mut w, "sim.getObjectInt32Param", vec![i(h), i(123_456)]).is_empty());
    assert!(ok(&mut w, "sim.getObjectFloatParam", vec![i(h), i(2002)]).is_empty());
    ok(&mut w, "sim.setObjectInt32Param", vec![i(h), i(123_456), i(1)]);
    // Vision sensors.
    let cam = find(&w, "/camera");
    assert_eq!(
        int(&ok(&mut w, "sim.getObjectInt32Param", vec![i(cam), i(1002)])[0]),
        32
    );
    assert_eq!(
        int(&ok(&mut w, "sim.getObjectInt32Param", vec![i(cam), i(1003)])[0]),
        24
    );
    ok(&mut w, "sim.setObjectInt32Param", vec![i(cam), i(1002), i(64)]);
    assert_eq!(
        int(&ok(&mut w, "sim.getObjectInt32Param", vec![i(cam), i(1002)])[0]),
        64
    );
    assert_eq!(
        ok(&mut w, "sim.getObjectFloatParam", vec![i(cam), i(1001)])[0].as_f64(),
        Some(2.0)
    );
    ok(&mut w, "sim.setObjectFloatParam", vec![i(cam), i(1001), f(5.0)]);
    assert_eq!(
        ok(&mut w, "sim.getObjectFloatParam", vec![i(cam), i(1001)])[0].as_f64(),
        Some(5.0)
    );
    let e = err(&mut w, "sim.setObjectFloatParam", vec![i(cam), i(1000), f(9.0)]);
    assert!(e.contains("0 < near < far"), "{e}");
    ok(&mut w, "sim.handleVisionSensor", vec![i(cam)]);
    // Simulation parameters.
    assert_eq!(int(&ok(&mut w, "sim.getInt32Param", vec![i(1)])[0]), 40600);
    assert_eq!(
        int(&ok(&mut w, "sim.getInt32Param", vec![i(48)])[0]),
        1,
        "one object created"
    );
    assert_eq!(ok(&mut w, "sim.getFloatParam", vec![i(1)])[0].as_f64(), Some(0.05));
    let r = ok(&mut w, "sim.getFloatParam", vec![i(0)])[0].as_f64().expect("random");
    assert!((0.0..1.0).contains(&r));
    ok(&mut w, "sim.setFloatParam", vec![i(1), f(0.02)]);
    assert_eq!(ok(&mut w, "sim.getSimulationTimeStep", vec![])[0].as_f64(), Some(0.02));
    assert_eq!(ok(&mut w, "sim.getBoolParam", vec![i(25)]), vec![Value::Bool(false)]);
    ok(&mut w, "sim.setBoolParam", vec![i(25), Value::Bool(true)]);
    assert_eq!(ok(&mut w, "sim.getBoolParam", vec![i(25)]), vec![Value::Bool(true)]);
    let e = err(&mut w, "sim.getInt32Param", vec![i(9999)]);
    assert!(e.contains("parameter 9999"), "{e}");
    let e = err(&mut w, "sim.setInt32Param", vec![i(1), i(5)]);
    assert!(e.contains("could not set"), "{e}");
    let e = err(&mut w, "sim.getObjectInt32Param", vec![i(99_999), i(10)]);
    assert!(e.contains("object does not exist"), "{e}");
}

#[test]
fn bad_arguments_give_clear_errors() {
    let mut w = world();
    let e = err(&mut w, "sim.createPrimitiveShape", vec![i(99), v3(1.0, 1.0, 1.0)]);
    assert!(e.contains("invalid primitive type 99"), "{e}");
    let e = err(
        &mut w,
        "sim.createPrimitiveShape",
        vec![i(CUBOID), Value::floats(&[1.0, 1.0])],
    );
    assert!(e.contains("argument 2"), "{e}");
    let e = err(&mut w, "sim.createPrimitiveShape", vec![i(CUBOID), v3(1.0, -1.0, 1.0)]);
    assert!(e.contains("sizes must be positive"), "{e}");
    let e = err(&mut w, "sim.removeObjects", vec![Value::Str("x".into())]);
    assert!(e.contains("expected table of handles"), "{e}");
    let base = find(&w, "/base");
    let e = err(&mut w, "sim.setShapeMass", vec![i(base), f(1.0)]);
    assert!(e.contains("not a shape"), "{e}");
    let stand = find(&w, "/stand");
    let e = err(
        &mut w,
        "sim.addForce",
        vec![i(stand), v3(0.0, 0.0, 0.0), v3(1.0, 0.0, 0.0)],
    );
    assert!(e.contains("not dynamically simulated"), "{e}");
    let e = err(&mut w, "sim.setObjectAlias", vec![i(base), Value::Str(String::new())]);
    assert!(e.contains("must not be empty"), "{e}");
    ok(&mut w, "sim.setObjectAlias", vec![i(base), Value::Str("a/b c".into())]);
    assert_eq!(
        ok(&mut w, "sim.getObjectAlias", vec![i(base)]),
        vec![Value::Str("a_b_c".into())]
    );
    let e = err(&mut w, "sim.getObjectChild", vec![i(12_345), i(0)]);
    assert!(e.contains("object does not exist"), "{e}");
    let e = err(&mut w, "sim.copyPasteObjects", vec![handles(&[12_345])]);
    assert!(e.contains("object does not exist"), "{e}");
    // Removing everything the calls above touched leaves an empty, steppable world.
    let all: Vec<Handle> = w.world.handles().to_vec();
    ok(&mut w, "sim.removeObjects", vec![handles(&all)]);
    assert!(w.world.handles().is_empty() && w.world.roots().is_empty());
    step(&mut w, 2);
}

#[test]
fn scene_revision_tracks_what_the_viewer_shows() {
    let mut w = world();
    let (r0, s0) = (w.world.scene_revision(), w.world.structure_revision());
    let h = int(&ok(&mut w, "sim.createDummy", vec![f(0.1)])[0]);
    assert!(w.world.scene_revision() > r0 && w.world.structure_revision() > s0);
    let (r1, s1) = (w.world.scene_revision(), w.world.structure_revision());
    ok(&mut w, "sim.setObjectAlias", vec![i(h), Value::Str("named".into())]);
    assert!(w.world.scene_revision() > r1);
    assert_eq!(w.world.structure_revision(), s1, "a rename keeps the object list");
    // Moving objects is not a scene change: poses stream separately.
    let r2 = w.world.scene_revision();
    ok(&mut w, "sim.setObjectPosition", vec![i(h), v3(1.0, 2.0, 3.0)]);
    assert_eq!(w.world.scene_revision(), r2);
    ok(&mut w, "sim.removeObject", vec![i(h)]);
    assert!(w.world.structure_revision() > s1);
}

#[test]
fn constants_have_coppeliasim_values() {
    let sim = api::module("sim").expect("sim module");
    let value = |name: &str| {
        sim.constants
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, v)| *v)
            .unwrap_or_else(|| panic!("sim.{name} is missing"))
    };
    for (name, v) in [
        ("primitiveshape_plane", 1),
        ("primitiveshape_disc", 2),
        ("primitiveshape_cuboid", 3),
        ("primitiveshape_spheroid", 4),
        ("primitiveshape_cylinder", 5),
        ("primitiveshape_cone", 6),
        ("primitiveshape_capsule", 8),
        ("colorcomponent_ambient_diffuse", 0),
        ("colorcomponent_emission", 3),
        ("shapeintparam_static", 3003),
        ("shapeintparam_respondable", 3004),
        ("objintparam_visibility_layer", 10),
        ("objfloatparam_objbbox_max_x", 18),
        ("intparam_program_version", 1),
        ("floatparam_simulation_time_step", 1),
        ("boolparam_realtime_simulation", 25),
        ("arrayparam_gravity", 0),
        ("jointfloatparam_maxvel", 2036),
        ("handleflag_resetforce", 0x40_0000),
        ("handle_world", -1),
    ] {
        assert_eq!(value(name), v, "sim.{name}");
    }
}

#[test]
fn rebuilding_a_mimic_leader_keeps_its_follower_coupled() {
    let gripper = r#"<robot name="gripper">
  <link name="palm">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="left">
    <inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="right">
    <inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="left_slide" type="prismatic">
    <parent link="palm"/><child link="left"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" effort="20" velocity="1"/>
  </joint>
  <joint name="right_slide" type="prismatic">
    <parent link="palm"/><child link="right"/><axis xyz="0 1 0"/>
    <limit lower="-0.04" upper="0" effort="20" velocity="1"/>
    <mimic joint="left_slide" multiplier="-1" offset="0"/>
  </joint>
</robot>"#;
    let dir = std::env::temp_dir().join(format!("gantry-scene-edit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("tmp dir");
    std::fs::write(dir.join("gripper.urdf"), gripper).expect("write urdf");
    let scene = "[simulation]\ndt = 0.01\nsubsteps = 1\n\n[[robot]]\nname = \"r\"\nurdf = \"gripper.urdf\"\njoint_mode = \"position\"\n";
    let model = load_scene_text(&DiskFiles, scene, &dir.join("scene.toml"), &LoadOptions::default());
    std::fs::remove_dir_all(&dir).ok();
    let mut w = Sim::new(&model.expect("scene loads"));
    let (left, right) = (find(&w, "/r/left_slide"), find(&w, "/r/right_slide"));
    assert_eq!(
        ok(&mut w, "sim.getJointMode", vec![i(right)])[0],
        i(4),
        "a follower is dependent"
    );
    // The leader's link leaves rapier and comes back: the follower must follow it still.
    ok(&mut w, "sim.resetDynamicObject", vec![i(left)]);
    ok(&mut w, "sim.setJointTargetPosition", vec![i(left), f(0.03)]);
    step(&mut w, 200);
    let (l, r) = (
        w.world.joint(left).expect("joint").position,
        w.world.joint(right).expect("joint").position,
    );
    assert!((l - 0.03).abs() < 2e-3, "leader at {l}");
    assert!((r + l).abs() < 1e-3, "follower at {r} for leader at {l}");
    // Removing the leader frees the follower, which stops being dependent.
    ok(&mut w, "sim.removeObjects", vec![handles(&[left])]);
    assert_eq!(ok(&mut w, "sim.getJointMode", vec![i(right)])[0], i(5));
    step(&mut w, 5);
}

#[test]
fn objects_created_after_a_removal_are_measured() {
    let mut w = world();
    let gone = int(&ok(&mut w, "sim.createDummy", vec![f(0.01)])[0]);
    ok(&mut w, "sim.removeObject", vec![i(gone)]);
    // Its handle is past the number of live objects.
    let h = int(&ok(&mut w, "sim.createPrimitiveShape", vec![i(CUBOID), v3(0.1, 0.1, 0.1)])[0]);
    assert!(h as usize >= w.world.handles().len());
    ok(&mut w, "sim.setObjectPosition", vec![i(h), v3(-1.0, 1.0, 0.1)]);
    let stand = find(&w, "/stand");
    let r = ok(&mut w, "sim.checkDistance", vec![i(stand), i(h)]);
    assert_eq!(int(&r[0]), 1);
    let d = floats(&r[1])[6];
    assert!((d - 0.85).abs() < 1e-3, "distance {d}");
}

/// Regression: a shape placed and made dynamic at run time, followed by a scene query
/// before the next step (a sensor, a vision render), stayed frozen in mid-air: rapier's
/// collision pipeline took the body's changes without filing it in an island.
#[test]
fn a_shape_made_dynamic_before_a_scene_query_still_falls() {
    let mut w = world();
    let b = ok(&mut w, "createPrimitiveShape", vec![i(3), v3(0.1, 0.1, 0.1)])[0].clone();
    let h = int(&b);
    ok(&mut w, "setObjectPosition", vec![b.clone(), v3(0.5, 0.5, 1.0), i(-1)]);
    ok(&mut w, "setObjectInt32Param", vec![b.clone(), i(3003), i(0)]);
    w.world.refresh_queries();
    for _ in 0..4 {
        w.step();
    }
    let z = position(&mut w, h)[2];
    // Free fall for 0.2 s: 0.196 m.
    assert!((1.0 - z - 0.5 * 9.81 * 0.2 * 0.2).abs() < 0.02, "z = {z}");
}

/// `sim.setShapeBB` (the youBot scene's table customization script sizes its table top
/// and legs this way) and `sim.scaleObject`: the box becomes the size asked for, keeps
/// its density, and lands on the floor at its new half height.
#[test]
fn set_shape_bb_and_scale_object_resize_a_shape() {
    let mut w = world();
    let h = dynamic_cube(&mut w, [0.0, 0.0, 1.0]);
    ok(&mut w, "sim.setShapeBB", vec![i(h), v3(0.4, 0.2, 0.06)]);
    let bb = floats(&ok(&mut w, "sim.getShapeBB", vec![i(h)])[0]);
    for (got, want) in bb.iter().zip([0.4, 0.2, 0.06]) {
        assert!((got - want).abs() < 1e-9, "{bb:?}");
    }
    let mass = ok(&mut w, "sim.getShapeMass", vec![i(h)])[0].as_f64().expect("mass");
    assert!(
        (mass - 1000.0 * 0.4 * 0.2 * 0.06).abs() < 1e-6,
        "the density stays: {mass} kg"
    );
    step(&mut w, 40);
    let z = position(&mut w, h)[2];
    assert!((z - 0.03).abs() < 2e-3, "rests on its new half height: {z}");

    ok(&mut w, "sim.scaleObject", vec![i(h), f(0.5), f(1.0), f(2.0)]);
    let bb = floats(&ok(&mut w, "sim.getShapeBB", vec![i(h)])[0]);
    for (got, want) in bb.iter().zip([0.2, 0.2, 0.12]) {
        assert!((got - want).abs() < 1e-9, "{bb:?}");
    }

    // What cannot be scaled is refused, and the shape stays as it was.
    let e = err(&mut w, "sim.setShapeBB", vec![i(h), v3(0.4, 0.0, 0.06)]);
    assert!(e.contains("finite and > 0"), "{e}");
    let ball = int(&ok(&mut w, "sim.createPrimitiveShape", vec![i(4), v3(0.1, 0.1, 0.1)])[0]);
    let e = err(&mut w, "sim.scaleObject", vec![i(ball), f(1.0), f(2.0), f(1.0)]);
    assert!(e.contains("only be scaled uniformly"), "{e}");
    ok(&mut w, "sim.scaleObject", vec![i(ball), f(2.0), f(2.0), f(2.0)]);
    let bb = floats(&ok(&mut w, "sim.getShapeBB", vec![i(ball)])[0]);
    assert!((bb[0] - 0.2).abs() < 1e-9, "{bb:?}");
    let base = find(&w, "/base");
    let e = err(&mut w, "sim.scaleObject", vec![i(base), f(2.0), f(2.0), f(2.0)]);
    assert!(e.contains("shape"), "{e}");
}

/// A vision sensor sees a scaled shape at its new size (its tessellation is redone).
#[test]
fn vision_sensors_see_a_scaled_shape_at_its_new_size() {
    let mut w = world();
    let cam = find(&w, "/camera");
    // The camera at (0, -2, 1) looks up (+Z); a 10 cm cube 0.5 m above it.
    let cube = int(&ok(&mut w, "sim.createPrimitiveShape", vec![i(CUBOID), v3(0.1, 0.1, 0.1)])[0]);
    ok(&mut w, "sim.setObjectPosition", vec![i(cube), v3(0.0, -2.0, 1.5)]);
    let covered = |w: &mut Sim| {
        ok(w, "sim.handleVisionSensor", vec![i(cam)]);
        let img = ok(w, "sim.getVisionSensorImg", vec![i(cam)]);
        let Value::Bytes(px) = &img[0] else { panic!("{img:?}") };
        let background = [px[0], px[1], px[2]];
        px.chunks(3).filter(|p| *p != background).count()
    };
    let small = covered(&mut w);
    ok(&mut w, "sim.setShapeBB", vec![i(cube), v3(0.3, 0.3, 0.1)]);
    let large = covered(&mut w);
    assert!(small > 0 && large > 5 * small, "{small} then {large} pixels");
}
