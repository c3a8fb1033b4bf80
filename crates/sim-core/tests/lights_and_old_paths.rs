//! Light objects and old path objects through the API, in a TOML scene and as imported
//! from PyRep's `test_scene.ttt` (CoppeliaSim 4.1; `$GANTRY_PYREP_TEST_SCENE`, else the
//! first `shared/pyrep/tests/assets/test_scene.ttt` beside an ancestor of this crate;
//! where it is absent that test prints a note and passes): `sim.getObjectType`,
//! `sim.getLightParameters`/`sim.setLightParameters`, the light object parameters
//! PyRep's `Light` reads and writes, and the old-path functions PyRep's `CartesianPath`
//! calls.

use crate::util;

use std::path::PathBuf;

use gantry_sim_core::scene::DiskFiles;
use gantry_sim_core::scene::load_coppelia_file;
use gantry_sim_core::{Sim, Value};
use gantry_test_support::{assert_close, floats, num};
use util::{err, find, ok, text_scene};

const SCENE: &str = r#"
[[object]]
name = "spot"
kind = "light"
light = "spot"
on = false
diffuse = [0.25, 0.5, 0.75]
specular = [0.1, 0.2, 0.3]
spot_exponent = 9
spot_cutoff_deg = 45
attenuation = [0.5, 0.125, 0.25]
casts_shadows = true
position = [0, 0, 2]

[[object]]
name = "sun"
kind = "light"
light = "directional"

[[object]]
name = "track"
kind = "path"
position = [1, 2, 3]
ctrl_points = [[0, 0, 0, 0, 0, 0, 1], [2, 0, 0, 0, 0, 0, 1], [2, 2, 0, 0, 0, 0, 1]]

[[object]]
name = "box"
kind = "dummy"
"#;

fn scene() -> Sim {
    text_scene("scene.toml", SCENE)
}

// CoppeliaSim's parameter ids (checked against its published constants).
const CASTS_SHADOWS: i64 = 8000;
const SPOT_EXPONENT: i64 = 8001;
const SPOT_CUTOFF: i64 = 8002;
const CONST_ATTENUATION: i64 = 8003;
const QUAD_ATTENUATION: i64 = 8005;

fn int_param(w: &mut Sim, h: &Value, id: i64) -> Vec<Value> {
    ok(w, "sim.getObjectInt32Param", &[h.clone(), Value::Int(id)])
}

fn float_param(w: &mut Sim, h: &Value, id: i64) -> f64 {
    num(&ok(w, "sim.getObjectFloatParam", &[h.clone(), Value::Int(id)])[0])
}

#[test]
fn lights_are_objects_with_parameters() {
    let mut w = scene();
    let spot = Value::Int(find(&w, "/spot"));
    let sun = Value::Int(find(&w, "/sun"));
    assert_eq!(
        num(&ok(&mut w, "sim.getObjectType", std::slice::from_ref(&spot))[0]),
        13.0
    );

    // 4.1's reply: state, the reserved zero, diffuse, specular.
    let p = ok(&mut w, "sim.getLightParameters", std::slice::from_ref(&spot));
    assert_eq!(num(&p[0]), 0.0);
    assert_eq!(floats(&p[1]), [0.0; 3]);
    assert_eq!(floats(&p[2]), [0.25, 0.5, 0.75]);
    assert_eq!(floats(&p[3]), [0.1, 0.2, 0.3]);
    // A new light's defaults: on, grey.
    let p = ok(&mut w, "sim.getLightParameters", std::slice::from_ref(&sun));
    assert_eq!((num(&p[0]), floats(&p[2])), (1.0, vec![0.5; 3]));

    // On, a new diffuse, the specular left as it is (nil); the reserved part ignored.
    ok(
        &mut w,
        "sim.setLightParameters",
        &[
            spot.clone(),
            Value::Int(1),
            Value::Nil,
            Value::floats(&[0.2, 0.5, 0.9]),
            Value::Nil,
        ],
    );
    let p = ok(&mut w, "sim.getLightParameters", std::slice::from_ref(&spot));
    assert_eq!(
        (num(&p[0]), floats(&p[2]), floats(&p[3])),
        (1.0, vec![0.2, 0.5, 0.9], vec![0.1, 0.2, 0.3])
    );
    // A boolean state, as Python clients pass it.
    ok(
        &mut w,
        "sim.setLightParameters",
        &[
            spot.clone(),
            Value::Bool(false),
            Value::Nil,
            Value::Nil,
            Value::floats(&[1.0, 1.0, 1.0]),
        ],
    );
    let p = ok(&mut w, "sim.getLightParameters", std::slice::from_ref(&spot));
    assert_eq!((num(&p[0]), floats(&p[3])), (0.0, vec![1.0; 3]));

    // Bad input: a colour out of range, an object that is no light.
    let e = err(
        &mut w,
        "sim.setLightParameters",
        &[
            spot.clone(),
            Value::Int(1),
            Value::Nil,
            Value::floats(&[2.0, 0.0, 0.0]),
            Value::Nil,
        ],
    );
    assert!(e.contains("from 0 to 1"), "{e}");
    let bx = Value::Int(find(&w, "/box"));
    let e = err(&mut w, "sim.getLightParameters", &[bx]);
    assert!(e.contains("not a light"), "{e}");

    // The object parameters PyRep's Light uses.
    assert_eq!(num(&int_param(&mut w, &spot, CASTS_SHADOWS)[0]), 1.0);
    ok(
        &mut w,
        "sim.setObjectInt32Param",
        &[spot.clone(), Value::Int(CASTS_SHADOWS), Value::Int(0)],
    );
    assert_eq!(num(&int_param(&mut w, &spot, CASTS_SHADOWS)[0]), 0.0);
    assert_eq!(float_param(&mut w, &spot, SPOT_EXPONENT), 9.0);
    ok(
        &mut w,
        "sim.setObjectFloatParam",
        &[spot.clone(), Value::Int(SPOT_EXPONENT), Value::Float(11.4)],
    );
    assert_eq!(
        float_param(&mut w, &spot, SPOT_EXPONENT),
        11.0,
        "rounded, as CoppeliaSim keeps an integer"
    );
    ok(
        &mut w,
        "sim.setObjectFloatParam",
        &[spot.clone(), Value::Int(SPOT_EXPONENT), Value::Float(500.0)],
    );
    assert_eq!(float_param(&mut w, &spot, SPOT_EXPONENT), 128.0);
    assert_close(
        &[float_param(&mut w, &spot, SPOT_CUTOFF)],
        &[std::f64::consts::FRAC_PI_4],
        1e-12,
    );
    ok(
        &mut w,
        "sim.setObjectFloatParam",
        &[spot.clone(), Value::Int(SPOT_CUTOFF), Value::Float(0.3)],
    );
    assert_eq!(float_param(&mut w, &spot, SPOT_CUTOFF), 0.3);
    ok(
        &mut w,
        "sim.setObjectFloatParam",
        &[spot.clone(), Value::Int(SPOT_CUTOFF), Value::Float(3.0)],
    );
    assert!((float_param(&mut w, &spot, SPOT_CUTOFF) - std::f64::consts::FRAC_PI_2).abs() < 1e-6);
    let att: Vec<f64> = (CONST_ATTENUATION..=QUAD_ATTENUATION)
        .map(|id| float_param(&mut w, &spot, id))
        .collect();
    assert_eq!(att, [0.5, 0.125, 0.25]);
    // Attenuation is read-only, as in CoppeliaSim.
    ok(
        &mut w,
        "sim.setObjectFloatParam",
        &[spot.clone(), Value::Int(CONST_ATTENUATION), Value::Float(3.0)],
    );
    assert_eq!(float_param(&mut w, &spot, CONST_ATTENUATION), 0.5);
    // A light parameter of another object is "not retrieved": nothing.
    let track = Value::Int(find(&w, "/track"));
    assert!(int_param(&mut w, &track, CASTS_SHADOWS).is_empty());
}

#[test]
fn scene_paths_are_old_path_objects() {
    let mut w = scene();
    let track = Value::Int(find(&w, "/track"));
    assert_eq!(
        num(&ok(&mut w, "sim.getObjectType", std::slice::from_ref(&track))[0]),
        8.0
    );
    assert_eq!(
        num(&ok(&mut w, "sim.getPathLength", std::slice::from_ref(&track))[0]),
        4.0
    );
    // Half way along the 4 m polyline: its corner, in the world (the path sits at 1, 2, 3).
    let pos = floats(&ok(&mut w, "sim.getPositionOnPath", &[track.clone(), Value::Float(0.5)])[0]);
    assert_close(&pos, &[3.0, 2.0, 3.0], 1e-9);
    let ori = floats(&ok(&mut w, "sim.getOrientationOnPath", &[track.clone(), Value::Float(0.5)])[0]);
    assert_close(&ori, &[0.0, 0.0, 0.0], 1e-9);
    // One control point at the end, 11 values, as PyRep's add-on inserts them: the path
    // grows by 2 m.
    let pt = [2.0, 4.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.5, 0.5];
    ok(
        &mut w,
        "sim.insertPathCtrlPoints",
        &[
            track.clone(),
            Value::Int(0),
            Value::Int(3),
            Value::Int(1),
            Value::floats(&pt),
        ],
    );
    assert_eq!(
        num(&ok(&mut w, "sim.getPathLength", std::slice::from_ref(&track))[0]),
        6.0
    );

    // V-REP 3's createPath makes an old path object; 4.3+'s a dummy.
    let h = ok(
        &mut w,
        "sim.createPath",
        &[Value::Int(-1), Value::Nil, Value::Nil, Value::Nil],
    )[0]
    .clone();
    assert_eq!(num(&ok(&mut w, "sim.getObjectType", &[h])[0]), 8.0);
}

/// PyRep's test scene, or `None` (with a note).
fn pyrep_test_scene() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("GANTRY_PYREP_TEST_SCENE") {
        return Some(PathBuf::from(p));
    }
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let found = here
        .ancestors()
        .map(|a| a.join("shared/pyrep/tests/assets/test_scene.ttt"))
        .find(|p| p.is_file());
    if found.is_none() {
        println!("PyRep's test_scene.ttt not found; skipped (set GANTRY_PYREP_TEST_SCENE)");
    }
    found
}

#[test]
fn pyrep_test_scene_lights_and_cartesian_path_work() {
    let Some(path) = pyrep_test_scene() else { return };
    let model = load_coppelia_file(&DiskFiles, &path).expect("test_scene.ttt imports");
    let mut w = Sim::new(&model);
    for name in ["spot_light", "omni_light", "directed_light"] {
        let h = Value::Int(find(&w, &format!("/{name}")));
        assert_eq!(
            num(&ok(&mut w, "sim.getObjectType", std::slice::from_ref(&h))[0]),
            13.0,
            "{name}"
        );
        let p = ok(&mut w, "sim.getLightParameters", std::slice::from_ref(&h));
        assert_eq!(
            (num(&p[0]), floats(&p[2]), floats(&p[3])),
            (0.0, vec![0.5; 3], vec![0.5; 3]),
            "{name}"
        );
        assert_eq!(num(&int_param(&mut w, &h, CASTS_SHADOWS)[0]), 1.0, "{name}");
        assert_eq!(float_param(&mut w, &h, SPOT_EXPONENT), 5.0);
        // PyRep's round trip: the cutoff read from the file is set back unchanged.
        let cutoff = float_param(&mut w, &h, SPOT_CUTOFF);
        ok(
            &mut w,
            "sim.setObjectFloatParam",
            &[h.clone(), Value::Int(SPOT_CUTOFF), Value::Float(cutoff - 0.5)],
        );
        assert_eq!(float_param(&mut w, &h, SPOT_CUTOFF), cutoff - 0.5);
        ok(
            &mut w,
            "sim.setObjectFloatParam",
            &[h.clone(), Value::Int(SPOT_CUTOFF), Value::Float(cutoff)],
        );
        assert_eq!(float_param(&mut w, &h, SPOT_CUTOFF), cutoff, "{name}");
    }

    let cp = Value::Int(find(&w, "/cartesian_path"));
    assert_eq!(num(&ok(&mut w, "sim.getObjectType", std::slice::from_ref(&cp))[0]), 8.0);
    // The arc of radius 0.051 m about the path's origin (0.52, 0.05, 0.55), 0 to 45
    // degrees; half way along it is near 22.5 degrees.
    let pos = floats(&ok(&mut w, "sim.getPositionOnPath", &[cp.clone(), Value::Float(0.5)])[0]);
    let (dx, dy) = (pos[0] - 0.52, pos[1] - 0.05);
    assert!((dx.hypot(dy) - 0.051).abs() < 0.003, "{pos:?}");
    assert!((dy.atan2(dx).to_degrees() - 22.5).abs() < 3.0, "{pos:?}");
    assert!((pos[2] - 0.55).abs() < 1e-6);
    let ori = floats(&ok(&mut w, "sim.getOrientationOnPath", &[cp.clone(), Value::Float(0.5)])[0]);
    assert_eq!(ori.len(), 3);
    // PyRep's insert_control_points: one pose of 6 values padded to 11.
    let mut pt = vec![0.1; 6];
    pt.extend([1.0, 0.0, 15.0, 0.5, 0.5]);
    ok(
        &mut w,
        "sim.insertPathCtrlPoints",
        &[
            cp.clone(),
            Value::Int(0),
            Value::Int(0),
            Value::Int(1),
            Value::floats(&pt),
        ],
    );
    let start = floats(&ok(&mut w, "sim.getPositionOnPath", &[cp, Value::Float(0.0)])[0]);
    assert_close(&start, &[0.62, 0.15, 0.65], 1e-6);
}
