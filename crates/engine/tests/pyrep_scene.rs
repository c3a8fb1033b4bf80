//! What PyRep's own test scene (`test_scene.ttt`, CoppeliaSim 4.1) asks of the API
//! beyond loading: CoppeliaSim 4.1's joint switches, the objects' collidable and
//! measurable flags from the file, dummies as points to distance queries, vision
//! parameters that only read back, and a V-REP 3.5 model whose header names no file
//! type. Each was a failure of PyRep's suite on gantry (issue 50).

use crate::util;
use util::Drive;

use gantry_engine::Engine;
use gantry_lua::ScriptLimits;
use gantry_sim_core::Value;
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene};
use gantry_test_support::pyrep_assets;

fn test_scene() -> Engine {
    let path = pyrep_assets().join("test_scene.ttt");
    let model = load_scene(&DiskFiles, &path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let mut sim = util::engine(model, ScriptLimits::default()).unwrap_or_else(|e| panic!("{e}"));
    sim.start();
    sim
}

fn handle(sim: &mut Engine, name: &str) -> Value {
    let ret = sim
        .call("getObjectHandle", &[Value::Str(name.into())])
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    ret[0].clone()
}

fn int_param(sim: &mut Engine, h: &Value, id: i64) -> i64 {
    let ret = sim
        .call("getObjectInt32Param", &[h.clone(), Value::Int(id)])
        .expect("getObjectInt32Param");
    match ret.first() {
        Some(Value::Int(v)) => *v,
        other => panic!("parameter {id}: {other:?}"),
    }
}

fn set_int_param(sim: &mut Engine, h: &Value, id: i64, v: i64) {
    sim.call("setObjectInt32Param", &[h.clone(), Value::Int(id), Value::Int(v)])
        .unwrap_or_else(|e| panic!("parameter {id} = {v}: {e}"));
}

#[test]
fn joint_modes_and_motor_switches_of_4_1_read_back() {
    let mut sim = test_scene();
    let j = handle(&mut sim, "prismatic_joint");
    // The file's joint: motor on, position control off, not locked.
    assert_eq!(int_param(&mut sim, &j, 2000), 1, "motor enabled");
    assert_eq!(int_param(&mut sim, &j, 2001), 0, "control loop enabled");
    assert_eq!(int_param(&mut sim, &j, 2030), 0, "locked at zero velocity");
    set_int_param(&mut sim, &j, 2001, 1);
    assert_eq!(int_param(&mut sim, &j, 2001), 1);
    set_int_param(&mut sim, &j, 2030, 1);
    assert_eq!(int_param(&mut sim, &j, 2030), 1);
    set_int_param(&mut sim, &j, 2000, 0);
    assert_eq!(int_param(&mut sim, &j, 2000), 0);
    sim.step();

    // CoppeliaSim 4.1's IK mode is kinematic, and reads back as 2.
    sim.call("setJointMode", &[j.clone(), Value::Int(2), Value::Int(0)])
        .expect("IK mode");
    let mode = sim
        .call("getJointMode", std::slice::from_ref(&j))
        .expect("getJointMode");
    assert_eq!(mode[0], Value::Int(2));
    sim.call("setJointMode", &[j.clone(), Value::Int(0), Value::Int(0)])
        .expect("kinematic mode");
    let mode = sim.call("getJointMode", &[j]).expect("getJointMode");
    assert_eq!(mode[0], Value::Int(0));
}

#[test]
fn collision_with_everything_uses_the_files_collidable_flag() {
    let mut sim = test_scene();
    // Both cubes are collidable but not measurable in the file: a collision check
    // against everything finds the pair, a distance query against everything not.
    let a = handle(&mut sim, "colliding_cube0");
    let b = handle(&mut sim, "colliding_cube1");
    let hit = sim
        .call("checkCollision", &[a.clone(), Value::Int(-2)])
        .expect("checkCollision");
    assert_eq!(hit[0], Value::Int(1));
    assert_eq!(hit[1], Value::Array(vec![a.clone(), b.clone()]));
    let special = sim
        .call("getObjectSpecialProperty", &[a])
        .expect("getObjectSpecialProperty");
    let Value::Int(bits) = special[0] else {
        panic!("{special:?}")
    };
    assert_eq!(bits & 1, 1, "collidable");
    assert_eq!(bits & 2, 0, "not measurable");
}

#[test]
fn a_dummy_is_a_point_to_distance_queries() {
    let mut sim = test_scene();
    let d = handle(&mut sim, "dummy");
    let cube = handle(&mut sim, "cube0");
    let ret = sim
        .call("checkDistance", &[d.clone(), cube.clone(), Value::Float(-1.0)])
        .expect("checkDistance");
    assert_eq!(ret[0], Value::Int(1), "{ret:?}");
    let Value::Array(data) = &ret[1] else { panic!("{ret:?}") };
    let Value::Float(distance) = data[6] else {
        panic!("{data:?}")
    };
    // The distance PyRep's own test expects in CoppeliaSim 4.1.
    assert!((distance - 1.4629).abs() < 1e-3, "{distance}");
    // The dummy's end of the segment is the dummy itself.
    let pos = sim
        .call("getObjectPosition", &[d.clone(), Value::Int(-1)])
        .expect("position");
    let Value::Array(p) = &pos[0] else { panic!("{pos:?}") };
    for k in 0..3 {
        let (Value::Float(a), Value::Float(b)) = (&data[k], &p[k]) else {
            panic!()
        };
        assert!((a - b).abs() < 1e-6);
    }
    assert_eq!(ret[2], Value::Array(vec![d, cube]));
}

#[test]
fn vision_parameters_that_change_nothing_read_back_and_others_are_refused() {
    let mut sim = test_scene();
    let cam = handle(&mut sim, "cam0");
    set_int_param(&mut sim, &cam, 1017, 6);
    assert_eq!(int_param(&mut sim, &cam, 1017), 6, "OpenGL 3 render mode");
    set_int_param(&mut sim, &cam, 1017, 0);
    assert_eq!(int_param(&mut sim, &cam, 1017), 0);
    set_int_param(&mut sim, &cam, 1009, 640);
    set_int_param(&mut sim, &cam, 1010, 480);
    assert_eq!(
        (int_param(&mut sim, &cam, 1009), int_param(&mut sim, &cam, 1010)),
        (640, 480)
    );
    assert_eq!(int_param(&mut sim, &cam, 1008), -1, "renders everything");
    set_int_param(&mut sim, &cam, 1008, -1);
    let err = sim
        .call("setObjectInt32Param", &[cam.clone(), Value::Int(1008), Value::Int(5)])
        .expect_err("only -1 is supported");
    assert!(err.to_string().contains("every renderable object"), "{err}");
    let err = sim
        .call("setObjectInt32Param", &[cam, Value::Int(1017), Value::Int(3)])
        .expect_err("POV-Ray is not a renderer gantry has");
    assert!(err.to_string().contains("not render mode 3"), "{err}");
}

#[test]
fn a_v_rep_3_5_model_without_a_file_type_loads_as_a_model() {
    let mut sim = test_scene();
    let path = pyrep_assets().join("loadable_model.ttm");
    let ret = sim
        .call("loadModel", &[Value::Str(path.to_str().expect("UTF-8 path").into())])
        .unwrap_or_else(|e| panic!("{e}"));
    let kind = sim.call("getObjectType", &[ret[0].clone()]).expect("getObjectType");
    assert_eq!(kind[0], Value::Int(0), "the model's base is a shape");
}

#[test]
fn an_imported_arm_brings_its_ik_group_and_a_second_copy_is_suffixed() {
    let mut sim = test_scene();
    let panda = gantry_test_support::coppelia_files().join("PyRep__Panda.ttm");
    assert!(panda.is_file(), "{} is missing", panda.display());
    let path = Value::Str(panda.to_str().expect("UTF-8 path").into());
    // test_scene.ttt has a Panda of its own: the imported one's group is the first copy.
    sim.call("loadModel", std::slice::from_ref(&path))
        .unwrap_or_else(|e| panic!("{e}"));
    sim.call("loadModel", &[path]).unwrap_or_else(|e| panic!("{e}"));
    let mut groups = Vec::new();
    for name in ["Panda_ik", "Panda_ik#0", "Panda_ik#1"] {
        let h = sim
            .call("getIkGroupHandle", &[Value::Str(name.into())])
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        groups.push(h[0].clone());
    }
    groups.dedup();
    assert_eq!(groups.len(), 3, "three distinct groups: {groups:?}");
    // The copy's group solves the copy's arm: handling it changes none of the scene's own
    // joints.
    let own = handle(&mut sim, "Panda_joint1");
    let before = sim
        .call("getJointPosition", std::slice::from_ref(&own))
        .expect("position");
    let h = groups[2].clone();
    sim.call("handleIkGroup", &[h]).expect("handleIkGroup");
    assert_eq!(sim.call("getJointPosition", &[own]).expect("position"), before);
}

#[test]
fn the_spherical_sensor_script_reads_its_user_parameters_and_composes_the_panorama() {
    let mut sim = test_scene();
    let base = handle(&mut sim, "sphericalVisionRGBAndDepth");
    let param = |sim: &mut Engine, name: &str, force: bool| {
        sim.call(
            "getScriptSimulationParameter",
            &[base.clone(), Value::Str(name.into()), Value::Bool(force)],
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"))[0]
            .clone()
    };
    // The file's values (its `Lsp` chunk), as numbers unless text is asked for.
    assert_eq!(param(&mut sim, "sensorResolutionX", false), Value::Int(512));
    assert_eq!(param(&mut sim, "horizontalAngle", true), Value::Str("360".into()));
    assert_eq!(param(&mut sim, "noSuchParameter", false), Value::Nil);

    for _ in 0..3 {
        sim.step();
    }
    // The model's own script read them in `sysCall_init` and composes the panorama
    // every step (PyRep's `test_capture_rgb` reads it without handling the sensor).
    let scripts = sim.scripts();
    let spherical: Vec<_> = scripts.iter().filter(|(_, h, _)| Value::Int(*h) == base).collect();
    assert_eq!(spherical.len(), 1, "the model's script: {scripts:?}");
    assert_eq!(spherical[0].2, gantry_lua::ScriptState::Running, "{:?}", spherical[0]);
    let rgb = handle(&mut sim, "sphericalVisionRGBAndDepth_sensorRGB");
    let img = sim.call("getVisionSensorImg", &[rgb]).expect("getVisionSensorImg");
    let Some(Value::Bytes(bytes)) = img.first() else {
        panic!("an image: {img:?}");
    };
    assert_eq!(bytes.len(), 512 * 256 * 3);
    assert!(bytes.iter().any(|&b| b != 0), "the panorama is not blank");
}
