//! What PyRep asks of the scene besides poses: configuration trees, objects created at
//! run time (vision, force and proximity sensors, joints), joint intervals, double
//! signals, engine parameters and a few object queries, through the `sim.*` registry with
//! CoppeliaSim 4.1's argument forms.

mod util;

use gantry_sim_core::{Sim, Value};
use gantry_test_support::{assert_contains, floats, int, num};
use util::{err, find, ok, step};

/// A floor, a dynamic cube that falls and tumbles, and a kinematic hinge on a stand with
/// a dynamic link.
const SCENE: &str = r#"
[simulation]
dt = 0.05
substeps = 10

[floor]

[[object]]
name = "cube"
kind = "shape"
shape = "box"
size = [0.1, 0.1, 0.1]
position = [0.3, 0.2, 0.6]
orientation_deg = [20, 10, 0]
dynamic = true
mass = 0.5

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
limits = [-90, 90]

[[object]]
name = "link"
kind = "shape"
shape = "box"
size = [0.3, 0.05, 0.05]
parent = "hinge"
position = [0.3, 0, 0.1]
"#;

fn sim() -> Sim {
    util::text_scene("tests/pyrep_objects.toml", SCENE)
}

fn h(v: i64) -> Value {
    Value::Int(v)
}

fn position(s: &mut Sim, handle: i64) -> Vec<f64> {
    floats(&ok(s, "getObjectPosition", &[h(handle), h(-1)])[0])
}

fn bytes(v: &Value) -> Vec<u8> {
    match v {
        Value::Bytes(b) => b.clone(),
        other => panic!("expected bytes, got {other:?}"),
    }
}

#[test]
fn configuration_tree_puts_a_fallen_cube_back_at_rest() {
    let mut s = sim();
    let cube = find(&s, "/cube");
    let before = position(&mut s, cube);
    let tree = ok(&mut s, "getConfigurationTree", &[h(cube)]);
    step(&mut s, 10);
    let moved = position(&mut s, cube);
    assert!((moved[2] - before[2]).abs() > 0.05, "the cube fell: {moved:?}");
    ok(&mut s, "setConfigurationTree", &tree);
    let after = position(&mut s, cube);
    gantry_test_support::assert_close(&after, &before, 1e-9);
    // Dynamics restarted at rest: no velocity carried over from the fall.
    let v = ok(&mut s, "getObjectVelocity", &[h(cube)]);
    assert!(floats(&v[0]).iter().all(|x| x.abs() < 1e-9), "{v:?}");
    // And it falls again from there, as a reset task does.
    step(&mut s, 2);
    assert!(position(&mut s, cube)[2] < before[2]);
}

#[test]
fn configuration_tree_of_the_scene_restores_joints_and_what_hangs_from_them() {
    let mut s = sim();
    let (hinge, link, cube) = (
        find(&s, "/stand/hinge"),
        find(&s, "/stand/hinge/link"),
        find(&s, "/cube"),
    );
    let link_before = position(&mut s, link);
    let tree = ok(&mut s, "getConfigurationTree", &[h(-12)]);
    ok(&mut s, "setJointPosition", &[h(hinge), Value::Float(1.0)]);
    ok(
        &mut s,
        "setObjectPosition",
        &[h(cube), h(-1), Value::floats(&[2.0, 2.0, 2.0])],
    );
    assert!((position(&mut s, link)[0] - link_before[0]).abs() > 0.1);
    ok(&mut s, "setConfigurationTree", &tree);
    assert_eq!(num(&ok(&mut s, "getJointPosition", &[h(hinge)])[0]), 0.0);
    gantry_test_support::assert_close(&position(&mut s, link), &link_before, 1e-9);
    gantry_test_support::assert_close(&position(&mut s, cube), &[0.3, 0.2, 0.6], 1e-9);
}

#[test]
fn configuration_tree_refuses_foreign_or_damaged_bytes_and_changes_nothing() {
    let mut s = sim();
    let cube = find(&s, "/cube");
    let tree = bytes(&ok(&mut s, "getConfigurationTree", &[h(cube)])[0]);
    ok(
        &mut s,
        "setObjectPosition",
        &[h(cube), h(-1), Value::floats(&[1.0, 1.0, 1.0])],
    );
    let mut flipped = tree.clone();
    flipped[20] ^= 1;
    for bad in [
        Vec::new(),
        b"not a tree at all, just text".to_vec(),
        tree[..tree.len() - 3].to_vec(),
        flipped,
    ] {
        let e = err(&mut s, "setConfigurationTree", &[Value::Bytes(bad)]);
        assert_contains(&e, &["not a configuration tree", "sim.setConfigurationTree"]);
    }
    assert_eq!(position(&mut s, cube), vec![1.0, 1.0, 1.0]);
    // A tree naming an object removed since is refused too.
    let link = find(&s, "/stand/hinge/link");
    let link_tree = ok(&mut s, "getConfigurationTree", &[h(link)]);
    ok(&mut s, "removeObjects", &[Value::Array(vec![h(link)])]);
    let e = err(&mut s, "setConfigurationTree", &link_tree);
    assert_contains(&e, &[&format!("object {link} does not exist")]);
    assert_contains(err(&mut s, "getConfigurationTree", &[h(999)]), &["999"]);
}
