//! CoppeliaSim vision sensors and cameras through the importer, on the shared files
//! (`../shared/coppelia-files/` from the repository root, or `$GANTRY_COPPELIA_FILES`;
//! where a file is absent the test prints a note and passes, as `coppelia_import.rs`).

use std::path::Path;

use gantry_sim_core::api::{self, CallContext};
use gantry_sim_core::scene::{
    DiskFiles, ImportReport, LoadOptions, ObjectModelKind, Projection, SceneModel, VisionModel, load_coppelia,
    load_scene,
};
use gantry_sim_core::{Sim, Value};
use gantry_test_support::coppelia_files;

/// The file's import, or `None` (with a note) when the shared folder lacks it.
fn import(name: &str) -> Option<(SceneModel, ImportReport)> {
    let dir = coppelia_files();
    let Ok(bytes) = std::fs::read(dir.join(name)) else {
        println!(
            "{name} not found in {}; skipped (set GANTRY_COPPELIA_FILES)",
            dir.display()
        );
        return None;
    };
    Some(load_coppelia(&bytes, Path::new(name)).expect("imports"))
}

fn vision_sensors(model: &SceneModel) -> Vec<(&str, VisionModel)> {
    model
        .objects
        .iter()
        .filter_map(|o| match &o.kind {
            ObjectModelKind::VisionSensor(v) => Some((o.alias.as_str(), *v)),
            _ => None,
        })
        .collect()
}

#[test]
fn line_tracer_keeps_its_three_orthographic_sensors() {
    let Some((model, report)) = import("PyRep__LineTracer.ttm") else {
        return;
    };
    let sensors = vision_sensors(&model);
    let names: Vec<&str> = sensors.iter().map(|(n, _)| *n).collect();
    assert_eq!(names, ["LeftSensor", "RightSensor", "MiddleSensor"]);
    for (name, v) in &sensors {
        // The file's values (saved as f32 by CoppeliaSim 3.6): 16 x 16 pixels, a 1 cm
        // orthographic view, clipping at 1 and 6 cm.
        assert_eq!(v.projection, Projection::Orthographic, "{name}");
        assert_eq!(v.resolution, [16, 16], "{name}");
        assert_eq!(v.ortho_size, f64::from(0.01f32), "{name}");
        assert_eq!((v.near, v.far), (f64::from(0.01f32), f64::from(0.06f32)), "{name}");
    }
    assert!(
        report.as_dummies.iter().all(|(n, _)| !n.ends_with("Sensor")),
        "{:?}",
        report.as_dummies
    );

    // On gantry's floor, each sensor looks down at it: a uniform floor image at one
    // depth, as an orthographic sensor above a flat floor sees it.
    let model = load_scene(
        &DiskFiles,
        &coppelia_files().join("PyRep__LineTracer.ttm"),
        &LoadOptions::default(),
    )
    .expect("loads");
    let mut sim = Sim::new(&model);
    for name in names {
        let h = sim.world.find(&format!("/LineTracer/{name}"), None, 0).expect(name);
        let reply = api::call(
            &mut sim,
            &CallContext::default(),
            "sim.getVisionSensorDepth",
            &[Value::Int(h), Value::Int(1)],
        )
        .expect("depth");
        let Some(Value::Bytes(bytes)) = reply.first() else {
            panic!("{reply:?}")
        };
        let d: Vec<f32> = bytes
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        assert_eq!(d.len(), 256);
        assert!(
            d[0] > 0.01 && d[0] < 0.06,
            "{name} sees the floor within its clipping planes: {} m",
            d[0]
        );
        assert!(d.iter().all(|&z| (z - d[0]).abs() < 1e-6), "{name}: {d:?}");
    }
}

#[test]
fn thymio_ground_sensors_are_orthographic() {
    let Some((model, _)) = import("coppeliasi__thymio.ttm") else {
        return;
    };
    let sensors = vision_sensors(&model);
    assert_eq!(sensors.len(), 2);
    for (name, v) in sensors {
        assert_eq!(
            (v.projection, v.resolution),
            (Projection::Orthographic, [1, 1]),
            "{name}"
        );
        assert_eq!(v.ortho_size, f64::from(0.01f32), "{name}");
    }
}

#[test]
fn baxter_and_sawyer_keep_their_640_pixel_cameras() {
    for (name, want) in [
        ("PyRep__Baxter.ttm", vec![[640, 480]; 3]),
        ("PyRep__Sawyer.ttm", vec![[640, 360], [640, 480]]),
    ] {
        let Some((model, report)) = import(name) else {
            return;
        };
        let got: Vec<[u32; 2]> = vision_sensors(&model).iter().map(|(_, v)| v.resolution).collect();
        assert_eq!(got, want, "{name}");
        assert!(
            vision_sensors(&model)
                .iter()
                .all(|(_, v)| v.projection == Projection::Perspective),
            "{name}"
        );
        assert!(
            report.as_dummies.iter().all(|(_, why)| !why.contains("vision")),
            "{name}: {:?}",
            report.as_dummies
        );
    }
    // Baxter's head camera renders its 640 x 480 image.
    let model = load_scene(
        &DiskFiles,
        &coppelia_files().join("PyRep__Baxter.ttm"),
        &LoadOptions::default(),
    )
    .expect("loads");
    let mut sim = Sim::new(&model);
    let h = sim.world.find("/Baxter_camera", None, 0).expect("camera");
    let reply = api::call(
        &mut sim,
        &CallContext::default(),
        "sim.getVisionSensorImg",
        &[Value::Int(h)],
    )
    .expect("image");
    let (Some(Value::Bytes(img)), Some(res)) = (reply.first(), reply.get(1)) else {
        panic!("{reply:?}")
    };
    assert_eq!(img.len(), 640 * 480 * 3);
    assert_eq!(*res, Value::Array(vec![Value::Int(640), Value::Int(480)]));
}

#[test]
fn cameras_become_viewpoints_and_lights_lights() {
    let Some((model, report)) = import("modulabs_c__vision_sensor.ttt") else {
        return;
    };
    let cameras: Vec<(&str, f64)> = model
        .objects
        .iter()
        .filter_map(|o| match &o.kind {
            ObjectModelKind::Camera(c) => Some((o.alias.as_str(), c.fov)),
            _ => None,
        })
        .collect();
    // CoppeliaSim's default scene: the perspective camera and the six axis views, all
    // with its 60 degree default view angle (stored as f32).
    assert_eq!(cameras.len(), 7, "{cameras:?}");
    assert!(cameras.iter().any(|(n, _)| *n == "DefaultCamera"));
    for (name, fov) in &cameras {
        assert!((fov - 60f64.to_radians()).abs() < 1e-6, "{name}: {fov}");
    }
    assert!(report.as_dummies.iter().all(|(_, why)| !why.contains("camera")));
    // The default scene's lights are lights, with no warning.
    let lights = model
        .objects
        .iter()
        .filter(|o| matches!(o.kind, ObjectModelKind::Light(_)))
        .count();
    assert!(lights > 0);
    assert!(report.as_dummies.iter().all(|(_, why)| !why.contains("light")));
    assert!(
        report.warnings.iter().all(|w| !w.contains("light")),
        "{:?}",
        report.warnings
    );
    // A world built from it has them as cameras (CoppeliaSim's type 3).
    let sim = Sim::new(&model);
    let k = model.objects.iter().position(|o| o.alias == "DefaultCamera").unwrap();
    assert_eq!(sim.world.object(k as _).unwrap().kind.type_code(), 3);
}

#[test]
fn imported_scenes_take_the_environment_colour_their_sensors_show() {
    // CoppeliaSim's sensors clear to the environment's fog colour, black in every
    // public scene (not the grey-blue gradient its views draw); models carry none.
    let Some((scene, _)) = import("modulabs_c__vision_sensor.ttt") else {
        return;
    };
    assert_eq!(scene.settings.background, Some([0.0; 3]));
    let Some((model, _)) = import("PyRep__LineTracer.ttm") else {
        return;
    };
    assert_eq!(model.settings.background, None);
}

/// CoppeliaSim keeps a model's respondable shapes on hidden layers (9-16), under the
/// visual meshes: a colour-coded view of PyRep's Panda sees the visual meshes, never
/// a `_respondable` one (RLBench's masks are handles of what the camera shows).
#[test]
fn shapes_on_hidden_layers_are_not_drawn() {
    let path = coppelia_files().join("PyRep__scene_panda_reach_target.ttt");
    let model = load_scene(&DiskFiles, &path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let respondable = model
        .objects
        .iter()
        .filter(|o| o.alias.ends_with("_respondable"))
        .map(|o| o.layer)
        .collect::<Vec<_>>();
    assert!(
        !respondable.is_empty() && respondable.iter().all(|&l| l == 0x0100),
        "{respondable:?}"
    );
    let mut sim = Sim::new(&model);
    let call = |sim: &mut Sim, f: &str, args: &[Value]| {
        let ctx = CallContext::default();
        api::call(sim, &ctx, f, args).unwrap_or_else(|e| panic!("{f}: {e}"))
    };
    // 128 x 128, 60 degrees, looking down at the Panda from 1.2 m above its base.
    let cam = call(
        &mut sim,
        "createVisionSensor",
        &[
            Value::Int(0),
            Value::Array(vec![Value::Int(128), Value::Int(128), Value::Int(0), Value::Int(0)]),
            Value::floats(&[0.01, 4.0, 60f64.to_radians(), 0.1, 0.1, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0]),
        ],
    )[0]
    .clone();
    // sim.visionintparam_render_mode = sim.rendermode_colorcoded.
    call(
        &mut sim,
        "setObjectInt32Param",
        &[cam.clone(), Value::Int(1017), Value::Int(2)],
    );
    call(
        &mut sim,
        "setObjectPosition",
        &[cam.clone(), Value::Int(-1), Value::floats(&[0.7, 0.0, 2.3])],
    );
    call(
        &mut sim,
        "setObjectOrientation",
        &[
            cam.clone(),
            Value::Int(-1),
            Value::floats(&[std::f64::consts::PI, 0.0, 0.0]),
        ],
    );
    call(&mut sim, "handleVisionSensor", std::slice::from_ref(&cam));
    let img = call(&mut sim, "getVisionSensorImg", std::slice::from_ref(&cam));
    let Some(Value::Bytes(rgb)) = img.first() else {
        panic!("{img:?}")
    };
    let mut seen = std::collections::BTreeSet::new();
    for p in rgb.chunks_exact(3) {
        let h = i64::from(p[0]) + 256 * i64::from(p[1]) + 65536 * i64::from(p[2]);
        if h != 0xff_ffff {
            seen.insert(h);
        }
    }
    let names: Vec<String> = seen
        .iter()
        .map(|&h| match call(&mut sim, "getObjectAlias", &[Value::Int(h)]).first() {
            Some(Value::Str(s)) => s.clone(),
            other => format!("{other:?}"),
        })
        .collect();
    assert!(names.iter().any(|n| n.contains("visual")), "{names:?}");
    assert!(!names.iter().any(|n| n.contains("respondable")), "{names:?}");
    assert!(
        !names.iter().any(|n| n == "diningTable" || n.ends_with("_element")),
        "{names:?}"
    );
}
