//! CoppeliaSim 4.1's built-in IK groups (`IKO`) imported from PyRep's files, and the 4.1
//! functions PyRep's `Arm` calls on them: `sim.getIkGroupHandle`, `sim.handleIkGroup`,
//! `sim.checkIkGroup`, `sim.getIkGroupMatrix` and `sim.generateIkPath`. Reads PyRep's
//! test scene (`../shared/pyrep/tests/assets/test_scene.ttt`) and the shared arm models
//! (`PyRep__*.ttm`); where they are absent the tests print a note and pass.

use std::path::{Path, PathBuf};

use gantry_sim_core::api::{self, CallContext};
use gantry_sim_core::scene::{DiskFiles, LoadOptions, SceneModel, load_scene};
use gantry_sim_core::{Sim, Value};
use gantry_test_support::{coppelia_files, repo};

/// `sim.primitiveshape_cuboid`.
const CUBOID: i64 = 3;

/// PyRep's test scene (a Panda with its `Panda_ik`), if present.
fn test_scene() -> Option<PathBuf> {
    let path = repo("../shared/pyrep/tests/assets/test_scene.ttt");
    if path.is_file() {
        Some(path)
    } else {
        println!("{} not found; skipped", path.display());
        None
    }
}

/// The shared PyRep models, sorted, if the folder is present.
fn pyrep_models() -> Vec<PathBuf> {
    let dir = coppelia_files();
    let Ok(entries) = std::fs::read_dir(&dir) else {
        println!("coppelia-files not found at {}; skipped", dir.display());
        return Vec::new();
    };
    let mut out: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("PyRep__") && n.ends_with(".ttm"))
        })
        .collect();
    out.sort();
    out
}

fn load(path: &Path) -> SceneModel {
    load_scene(&DiskFiles, path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn call(sim: &mut Sim, name: &str, args: &[Value]) -> Result<Vec<Value>, String> {
    api::call(sim, &CallContext::default(), name, args).map_err(|e| e.to_string())
}

fn group_handle(sim: &mut Sim, name: &str) -> i64 {
    let got = call(sim, "sim.getIkGroupHandle", &[Value::Str(name.into())]).unwrap_or_else(|e| panic!("{name}: {e}"));
    let Value::Int(h) = got[0] else { panic!("{got:?}") };
    h
}

fn floats(v: &Value) -> Vec<f64> {
    let Value::Array(items) = v else {
        panic!("not an array: {v:?}")
    };
    items.iter().map(|x| x.as_f64().expect("a number")).collect()
}

/// World position of an object.
fn position(sim: &Sim, h: i64) -> nalgebra::Vector3<f64> {
    sim.world.object(h).expect("object").world.translation.vector
}

/// Distance (m) and angle (rad) from the tip to the target.
fn tip_error(sim: &Sim, tip: i64, target: i64) -> (f64, f64) {
    let a = sim.world.object(tip).expect("tip").world;
    let b = sim.world.object(target).expect("target").world;
    (
        (a.translation.vector - b.translation.vector).norm(),
        a.rotation.angle_to(&b.rotation),
    )
}

/// Puts the target on the tip, as PyRep's `get_jacobian` does (the Panda's is saved
/// tilted 14° about the tip's y axis).
fn align(sim: &mut Sim, target: i64, tip: i64) {
    let pose = sim.world.object(tip).expect("tip").world;
    sim.world.set_world_pose(target, pose).expect("aligned");
}

/// Moves an object by `d` in the world frame.
fn shift(sim: &mut Sim, h: i64, d: [f64; 3]) {
    let mut pose = sim.world.object(h).expect("object").world;
    pose.translation.vector += nalgebra::Vector3::from(d);
    sim.world.set_world_pose(h, pose).expect("moved");
}

/// Handles the group up to ten times (CoppeliaSim's arms need a few handlings for
/// centimetres: each does the group's few iterations) until the tip is within 1 mm (and,
/// for a full-pose group, 0.01 rad) of the target.
fn handle_until_reached(sim: &mut Sim, group: i64, tip: i64, target: i64, orientation: bool, what: &str) {
    let mut error = tip_error(sim, tip, target);
    for _ in 0..10 {
        call(sim, "sim.handleIkGroup", &[Value::Int(group)]).unwrap_or_else(|e| panic!("{what}: {e}"));
        error = tip_error(sim, tip, target);
        if error.0 < 1e-3 && (!orientation || error.1 < 1e-2) {
            return;
        }
    }
    panic!(
        "{what}: the tip stays {:.4} m, {:.4} rad from its target",
        error.0, error.1
    );
}

/// The Panda of PyRep's test scene: its group is imported as the file has it, and
/// `sim.getIkGroupHandle('Panda_ik')` finds it.
#[test]
fn the_test_scene_panda_has_its_ik_group() {
    let Some(path) = test_scene() else { return };
    let model = load(&path);
    let names: Vec<&str> = model.ik_groups.iter().map(|g| g.name.as_str()).collect();
    assert_eq!(names, ["Panda_ik"]);
    let g = &model.ik_groups[0];
    let alias = |i: usize| model.objects[i].alias.as_str();
    assert_eq!(g.elements.len(), 1);
    let e = &g.elements[0];
    assert_eq!(
        (alias(e.tip), alias(e.target), e.base.map(alias)),
        ("Panda_tip", "Panda_target", Some("Panda"))
    );
    assert_eq!(e.constraints, 31, "x, y, z, alpha-beta and gamma");
    // PyRep handles its arms' groups itself.
    assert!(g.explicit);
    assert_eq!(g.max_iterations, 6);
    assert_eq!(g.damping, 0.1, "the f32 0.1 as written in CoppeliaSim's dialog");
    let mut sim = Sim::new(&model);
    assert!(group_handle(&mut sim, "Panda_ik") >= 0);
    let missing = call(&mut sim, "sim.getIkGroupHandle", &[Value::Str("Dobot_ik".into())]).unwrap_err();
    assert!(missing.contains("'Dobot_ik' does not exist"), "{missing}");
}

/// Every arm group of PyRep's models (and the test scene's Panda): after the target moves
/// a few centimetres, handling the group brings the tip onto it; the group's handle is
/// found by name.
#[test]
fn handling_pyrep_arm_groups_brings_the_tip_to_the_moved_target() {
    let mut files = pyrep_models();
    files.extend(test_scene());
    let mut handled = Vec::new();
    for path in &files {
        let model = load(path);
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or_default().to_owned();
        for g in &model.ik_groups {
            let e = &g.elements[0];
            // Arms only: the Robotiq's finger loops are solved by the main script, and the
            // Dobot's tip has no target.
            if !g.name.ends_with("_ik") || e.tip == e.target {
                continue;
            }
            // Baxter's arms are saved stretched straight out (every joint at 0), a
            // singular pose for their full-pose groups: gantry's solver does not get them
            // out of it towards a target a few centimetres away (not asserted; PyRep's
            // tests do not use Baxter's IK).
            if g.name.starts_with("Baxter_") {
                continue;
            }
            let what = format!("{name}: {}", g.name);
            let mut sim = Sim::new(&model);
            let h = group_handle(&mut sim, &g.name);
            let (tip, target) = (e.tip as i64, e.target as i64);
            // The file's target sits on its tip, as saved.
            assert!(tip_error(&sim, tip, target).0 < 2e-3, "{what}: saved apart");
            align(&mut sim, target, tip);
            // 4 cm towards the arm's base: reachable from every saved pose (outwards or
            // upwards, the Panda's and others' saved poses are near the end of their
            // reach with the tip's orientation kept).
            let base = e.base.expect("arm groups have a base") as i64;
            let towards = (position(&sim, base) - position(&sim, tip)).normalize() * 0.04;
            shift(&mut sim, target, towards.into());
            let before = position(&sim, tip);
            handle_until_reached(&mut sim, h, tip, target, e.constraints == 31, &what);
            assert!((position(&sim, tip) - before).norm() > 0.03, "{what}: the tip moved");
            handled.push(g.name.clone());
        }
    }
    if files.is_empty() {
        return;
    }
    handled.sort();
    handled.dedup();
    println!("handled: {handled:?}");
    for want in [
        "Jaco_ik",
        "LBR_iiwa_14_R820_ik",
        "LBR_iiwa_7_R800_ik",
        "Mico_ik",
        "Panda_ik",
        "Sawyer_ik",
        "UR10_ik",
        "UR3_ik",
        "UR5_ik",
        "xarm_ik",
        "youBot_ik",
    ] {
        assert!(handled.iter().any(|h| h == want), "{want} not handled: {handled:?}");
    }
}

/// `sim.checkIkGroup` computes the joint values that put the tip on the target without
/// moving the arm; applying them does.
#[test]
fn check_ik_group_solves_without_applying() {
    let Some(path) = test_scene() else { return };
    let model = load(&path);
    let mut sim = Sim::new(&model);
    let h = group_handle(&mut sim, "Panda_ik");
    let e = &model.ik_groups[0].elements[0];
    let (tip, target) = (e.tip as i64, e.target as i64);
    let joints: Vec<i64> = (1..=7)
        .map(|k| sim.world.find(&format!("/Panda_joint{k}"), None, 0).expect("joint"))
        .collect();
    let handles = Value::Array(joints.iter().map(|&j| Value::Int(j)).collect());
    align(&mut sim, target, tip);
    shift(&mut sim, target, [0.0, 0.0, -0.005]);
    let before: Vec<f64> = joints
        .iter()
        .map(|&j| sim.world.joint(j).expect("joint").position)
        .collect();
    let tip_before = position(&sim, tip);
    let got = call(&mut sim, "sim.checkIkGroup", &[Value::Int(h), handles.clone()]).expect("checked");
    assert_eq!(got[0], Value::Int(1), "sim.ikresult_success");
    let values = floats(&got[1]);
    assert_eq!(values.len(), 7);
    let now: Vec<f64> = joints
        .iter()
        .map(|&j| sim.world.joint(j).expect("joint").position)
        .collect();
    assert_eq!(now, before, "the scene's joints did not move");
    assert_eq!(position(&sim, tip), tip_before);
    assert!(
        values.iter().zip(&before).any(|(a, b)| (a - b).abs() > 1e-4),
        "a solution that moves"
    );
    for (&j, &q) in joints.iter().zip(&values) {
        sim.world.set_joint_position(j, q).expect("set");
    }
    assert!(
        tip_error(&sim, tip, target).0 < 1e-3,
        "{:?}",
        tip_error(&sim, tip, target)
    );

    // A joint outside the chain keeps its value; a non-joint is refused.
    let finger = sim.world.find("/Panda_gripper_joint1", None, 0).expect("finger joint");
    let q = sim.world.joint(finger).expect("joint").position;
    let got = call(
        &mut sim,
        "sim.checkIkGroup",
        &[Value::Int(h), Value::Array(vec![Value::Int(finger)])],
    )
    .expect("checked");
    assert_eq!(floats(&got[1]), [q]);
    let err = call(
        &mut sim,
        "sim.checkIkGroup",
        &[Value::Int(h), Value::Array(vec![Value::Int(tip)])],
    )
    .unwrap_err();
    assert!(err.contains("is not a joint"), "{err}");
    let err = call(&mut sim, "sim.checkIkGroup", &[Value::Int(12), handles]).unwrap_err();
    assert!(err.contains("IK group 12 does not exist"), "{err}");
}

/// `sim.getIkGroupMatrix(h, 0)`: the Panda's Jacobian, 6 rows (full pose) by 7 joints,
/// reported as {columns, rows} as CoppeliaSim does; PyRep reshapes it to 7 × 6.
#[test]
fn the_panda_jacobian_has_six_rows_and_seven_columns() {
    let Some(path) = test_scene() else { return };
    let model = load(&path);
    let mut sim = Sim::new(&model);
    let h = group_handle(&mut sim, "Panda_ik");
    let got = call(&mut sim, "sim.getIkGroupMatrix", &[Value::Int(h), Value::Int(0)]).expect("matrix");
    assert_eq!(got[1], Value::Array(vec![Value::Int(7), Value::Int(6)]));
    let j = floats(&got[0]);
    assert_eq!(j.len(), 42);
    assert!(
        j.iter().all(|v| v.is_finite()) && j.iter().any(|v| v.abs() > 0.1),
        "{j:?}"
    );
}

/// `sim.generateIkPath`: configurations moving the Panda's tip in a straight line to its
/// moved target, the first being the current one; nil out of reach; the scene unchanged.
#[test]
fn generate_ik_path_moves_the_tip_in_a_straight_line() {
    let Some(path) = test_scene() else { return };
    let model = load(&path);
    let mut sim = Sim::new(&model);
    let h = group_handle(&mut sim, "Panda_ik");
    let e = &model.ik_groups[0].elements[0];
    let (tip, target) = (e.tip as i64, e.target as i64);
    let joints: Vec<i64> = (1..=7)
        .map(|k| sim.world.find(&format!("/Panda_joint{k}"), None, 0).expect("joint"))
        .collect();
    let handles = Value::Array(joints.iter().map(|&j| Value::Int(j)).collect());
    let start_tip = position(&sim, tip);
    align(&mut sim, target, tip);
    shift(&mut sim, target, [0.05, 0.05, -0.05]);
    let goal = position(&sim, target);
    let before: Vec<f64> = joints
        .iter()
        .map(|&j| sim.world.joint(j).expect("joint").position)
        .collect();
    let got = call(
        &mut sim,
        "sim.generateIkPath",
        &[Value::Int(h), handles.clone(), Value::Int(20)],
    )
    .expect("path");
    let values = floats(&got[0]);
    assert_eq!(values.len(), 20 * 7);
    let now: Vec<f64> = joints
        .iter()
        .map(|&j| sim.world.joint(j).expect("joint").position)
        .collect();
    assert_eq!(now, before, "the scene's joints did not move");
    assert_eq!(
        &values[..7],
        before.as_slice(),
        "the first point is the current configuration"
    );
    // Each configuration puts the tip on the line from its start to the target.
    let line = goal - start_tip;
    for (k, config) in values.chunks(7).enumerate() {
        for (&j, &q) in joints.iter().zip(config) {
            sim.world.set_joint_position(j, q).expect("set");
        }
        let p = position(&sim, tip) - start_tip;
        let off_line = (p - line * (p.dot(&line) / line.norm_squared())).norm();
        assert!(off_line < 2e-3, "point {k}: {off_line} m off the line");
        let s = k as f64 / 19.0;
        assert!((p - line * s).norm() < 2e-3, "point {k} not evenly spaced");
    }
    assert!(tip_error(&sim, tip, target).0 < 1e-3);

    for (&j, &q) in joints.iter().zip(&before) {
        sim.world.set_joint_position(j, q).expect("set back");
    }

    // A collision pair: the arm's collection against a box. Away from the path, the
    // path stands; across the target, no path; the arm is put back either way.
    let got = call(&mut sim, "sim.getCollectionHandle", &[Value::Str("Panda_arm".into())]).expect("collection");
    let arm = got[0].clone();
    let got = call(
        &mut sim,
        "sim.createPrimitiveShape",
        &[Value::Int(CUBOID), Value::floats(&[0.1, 0.1, 0.1])],
    )
    .expect("box");
    let Value::Int(obstacle) = got[0] else {
        panic!("{got:?}")
    };
    let mut away = sim.world.object(obstacle).expect("box").world;
    away.translation.vector = nalgebra::Vector3::new(5.0, 5.0, 0.5);
    sim.world.set_world_pose(obstacle, away).expect("moved");
    let pairs = Value::Array(vec![arm, Value::Int(obstacle)]);
    let args = [Value::Int(h), handles.clone(), Value::Int(10), pairs];
    let got = call(&mut sim, "sim.generateIkPath", &args).expect("path");
    assert_eq!(floats(&got[0]).len(), 70, "{got:?}");
    let mut across = away;
    across.translation.vector = goal;
    sim.world.set_world_pose(obstacle, across).expect("moved");
    let got = call(&mut sim, "sim.generateIkPath", &args).expect("call");
    assert_eq!(got, [Value::Nil]);
    let now: Vec<f64> = joints
        .iter()
        .map(|&j| sim.world.joint(j).expect("joint").position)
        .collect();
    assert_eq!(now, before, "the joints are put back after the collision checks");

    // Out of reach: nil.
    let mut far = sim.world.object(target).expect("target").world;
    far.translation.vector = nalgebra::Vector3::new(99.0, 99.0, 99.0);
    sim.world.set_world_pose(target, far).expect("moved");
    let got = call(
        &mut sim,
        "sim.generateIkPath",
        &[Value::Int(h), handles.clone(), Value::Int(50)],
    )
    .expect("call");
    assert_eq!(got, [Value::Nil]);

    for (args, want) in [
        (vec![Value::Int(h), handles.clone(), Value::Int(1)], "ptCnt must be 2"),
        (
            vec![
                Value::Int(h),
                handles.clone(),
                Value::Int(5),
                Value::Array(vec![Value::Int(tip)]),
            ],
            "come in twos",
        ),
        (
            vec![Value::Int(h), Value::Array(vec![Value::Int(tip)]), Value::Int(5)],
            "is not a joint",
        ),
    ] {
        let err = call(&mut sim, "sim.generateIkPath", &args).unwrap_err();
        assert!(err.contains(want), "{err}");
    }
}
