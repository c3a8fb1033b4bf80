//! Orthographic vision sensors, and resolutions up to 2048 a side, through the scene
//! format and the API: exact geometry of what an orthographic sensor sees, its depth,
//! its parameters (`sim.visionfloatparam_ortho_size`,
//! `sim.visionintparam_perspective_operation`), and the memory cap on sensor images.

use std::path::Path;

use crate::util;

use gantry_sim_core::api::{self, CallContext};
use gantry_sim_core::math::{Pose, pose_from_euler};
use gantry_sim_core::scene::{DiskFiles, LoadOptions, Projection, load_scene_text};
use gantry_sim_core::{Handle, Sim, Value};
use util::image_reply as image;

// CoppeliaSim's parameter numbers (`sim.visionfloatparam_ortho_size`, ...).
const ORTHO_SIZE: i64 = 1005;
const PERSPECTIVE_OPERATION: i64 = 1018;
const RESOLUTION_X: i64 = 1002;

fn call(w: &mut Sim, name: &str, args: &[Value]) -> Result<Vec<Value>, String> {
    api::call(w, &CallContext::default(), name, args).map_err(|e| e.to_string())
}

fn load(text: &str) -> Sim {
    let model = load_scene_text(&DiskFiles, text, Path::new("inline.toml"), &LoadOptions::default()).expect("scene");
    Sim::new(&model)
}

fn load_err(text: &str) -> String {
    load_scene_text(&DiskFiles, text, Path::new("inline.toml"), &LoadOptions::default())
        .expect_err("refused")
        .to_string()
}

fn find(w: &Sim, path: &str) -> Handle {
    w.world.find(path, None, 0).expect(path)
}

/// Renders sensor `h` now: a reader alone gets the image of the current step, which
/// an earlier read in the same step already made (as in CoppeliaSim).
fn handle(w: &mut Sim, h: Handle) {
    call(w, "sim.handleVisionSensor", &[Value::Int(h)]).expect("handled");
}

fn rgb(w: &mut Sim, h: Handle) -> (Vec<u8>, [usize; 2]) {
    handle(w, h);
    image(&call(w, "sim.getVisionSensorImg", &[Value::Int(h)]).expect("image"))
}

/// Depth in metres (`options` 1) or normalised (0), bottom row first.
fn depth(w: &mut Sim, h: Handle, options: i64) -> (Vec<f32>, [usize; 2]) {
    handle(w, h);
    let (bytes, res) =
        image(&call(w, "sim.getVisionSensorDepth", &[Value::Int(h), Value::Int(options)]).expect("depth"));
    let d = bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    (d, res)
}

/// Columns of row `y` (from the bottom) whose pixel is pure red.
fn red_columns(img: &[u8], res: [usize; 2], y: usize) -> Vec<usize> {
    (0..res[0])
        .filter(|&x| {
            let i = 3 * (y * res[0] + x);
            img[i] > 50 && img[i + 1] == 0 && img[i + 2] == 0
        })
        .collect()
}

/// A 200 x 100 orthographic sensor 1 m above the floor looking straight down
/// (`orientation_deg = [180, 0, 0]`: its +Z is the world's -Z, its +X the world's +X,
/// its +Y the world's -Y), 0.4 m of view across its 200 columns: 2 mm a pixel. A red
/// 0.1 m cube stands on the floor at x = 0.0203.
const TOP_VIEW: &str = r#"
[floor]
size = [2, 2]

[[object]]
name = "cam"
kind = "vision_sensor"
projection = "orthographic"
ortho_size = 0.4
position = [0, 0, 1]
orientation_deg = [180, 0, 0]
resolution = [200, 100]
near = 0.01
far = 2.0

[[object]]
name = "cube"
kind = "shape"
shape = "box"
size = [0.1, 0.1, 0.1]
position = [0.0203, 0, 0.05]
color = [1, 0, 0]
"#;

#[test]
fn an_orthographic_sensor_sees_edges_where_its_size_puts_them() {
    let mut w = load(TOP_VIEW);
    let cam = find(&w, "/cam");
    // Image right is the sensor's -X (the world's -X here). Column u (continuous, from
    // the left) of world x is 100 (1 - x / 0.2) = 100 - 500 x: the cube's sides at
    // x = -0.0297 and 0.0703 are at u = 114.85 and 64.85, so the pixel centres c + 0.5
    // inside are columns 65 to 114, at any distance.
    let (img, res) = rgb(&mut w, cam);
    assert_eq!(res, [200, 100]);
    let expected: Vec<usize> = (65..=114).collect();
    assert_eq!(red_columns(&img, res, 50), expected);
    // Rows: the sensor's +Y is the world's -Y, v = 50 (1 + y_s / 0.1): the cube's
    // y in [-0.05, 0.05] covers rows 25 to 74.
    let rows: Vec<usize> = (0..100).filter(|&y| !red_columns(&img, res, y).is_empty()).collect();
    assert_eq!(rows, (25..=74).collect::<Vec<_>>());

    // Half the height: the same columns (a perspective sensor would see the cube grow).
    let down = [std::f64::consts::PI, 0.0, 0.0];
    w.world
        .set_world_pose(cam, pose_from_euler([0.0, 0.0, 0.5], down))
        .unwrap();
    let (img, res) = rgb(&mut w, cam);
    assert_eq!(red_columns(&img, res, 50), expected);

    // Half the ortho size: 1 mm a pixel, u = 100 - 1000 x: columns 30 to 129.
    call(
        &mut w,
        "sim.setObjectFloatParam",
        &[Value::Int(cam), Value::Int(ORTHO_SIZE), Value::Float(0.2)],
    )
    .unwrap();
    let got = call(
        &mut w,
        "sim.getObjectFloatParam",
        &[Value::Int(cam), Value::Int(ORTHO_SIZE)],
    )
    .unwrap();
    assert_eq!(got, vec![Value::Float(0.2)]);
    let (img, res) = rgb(&mut w, cam);
    assert_eq!(red_columns(&img, res, 50), (30..=129).collect::<Vec<_>>());
}

#[test]
fn orthographic_depth_is_the_distance_along_the_axis() {
    let mut w = load(TOP_VIEW);
    let cam = find(&w, "/cam");
    // Straight down at the floor: every floor pixel 1 m away, the cube's top 0.9 m.
    let (d, res) = depth(&mut w, cam, 1);
    assert_eq!(res, [200, 100]);
    let (img, _) = rgb(&mut w, cam);
    for (i, &z) in d.iter().enumerate() {
        let red = img[3 * i] > 50 && img[3 * i + 1] == 0;
        let want = if red { 0.9 } else { 1.0 };
        assert!((z - want).abs() < 1e-5, "pixel {i}: {z} m, want {want}");
    }
    // Normalised as CoppeliaSim does: (z - near) / (far - near).
    let (n, _) = depth(&mut w, cam, 0);
    assert!((n[0] - (1.0 - 0.01) / (2.0 - 0.01)).abs() < 1e-6, "{}", n[0]);

    // Tilted by 30 degrees about X, at 1 m: the ray of a row at y_s along the sensor's
    // +Y starts at height 1 + y_s sin 30 and runs down at cos 30, so it meets the floor
    // at depth (1 + y_s sin 30) / cos 30: affine in the row, exactly.
    let tilt = 30f64.to_radians();
    let tilted = [std::f64::consts::PI - tilt, 0.0, 0.0];
    w.world
        .set_world_pose(cam, pose_from_euler([0.0, 0.0, 1.0], tilted))
        .unwrap();
    w.world
        .set_world_pose(find(&w, "/cube"), Pose::translation(0.0, 0.0, -5.0))
        .unwrap();
    let (d, _) = depth(&mut w, cam, 1);
    for row in 0..100 {
        let ys = (row as f64 + 0.5 - 50.0) * 0.002;
        let want = (1.0 + ys * tilt.sin()) / tilt.cos();
        for col in [0, 77, 199] {
            let z = f64::from(d[row * 200 + col]);
            assert!((z - want).abs() < 2e-5, "row {row}, column {col}: {z} m, want {want}");
        }
    }

    // A perspective sensor in the same place sees the same floor with a depth that is
    // not affine in the row (its 1/z is): the middle row is off the chord.
    call(
        &mut w,
        "sim.setObjectInt32Param",
        &[Value::Int(cam), Value::Int(PERSPECTIVE_OPERATION), Value::Int(1)],
    )
    .unwrap();
    let (p, _) = depth(&mut w, cam, 1);
    let at = |row: usize| f64::from(p[row * 200 + 100]);
    let bow = (at(20) + at(78)) / 2.0 - at(49);
    assert!(bow.abs() > 1e-3, "perspective depth bows by {bow} m between rows");
}

#[test]
fn the_projection_is_a_parameter_as_in_coppeliasim() {
    let mut w = load(TOP_VIEW);
    let cam = find(&w, "/cam");
    let get_int =
        |w: &mut Sim, id: i64| call(w, "sim.getObjectInt32Param", &[Value::Int(cam), Value::Int(id)]).unwrap();
    assert_eq!(get_int(&mut w, PERSPECTIVE_OPERATION), vec![Value::Int(0)]);
    let get_float =
        |w: &mut Sim, id: i64| call(w, "sim.getObjectFloatParam", &[Value::Int(cam), Value::Int(id)]).unwrap();
    assert_eq!(get_float(&mut w, ORTHO_SIZE), vec![Value::Float(0.4)]);
    let (ortho_img, _) = rgb(&mut w, cam);

    // Perspective with the default 60 degree view angle over the 200 columns.
    call(
        &mut w,
        "sim.setObjectInt32Param",
        &[Value::Int(cam), Value::Int(PERSPECTIVE_OPERATION), Value::Int(1)],
    )
    .unwrap();
    assert_eq!(get_int(&mut w, PERSPECTIVE_OPERATION), vec![Value::Int(1)]);
    let gantry_sim_core::world::ObjectKind::VisionSensor(m) = w.world.object(cam).unwrap().kind else {
        panic!("vision sensor")
    };
    assert_eq!(m.projection, Projection::Perspective);
    // The ortho size is kept through the switch, as CoppeliaSim keeps it.
    assert_eq!(get_float(&mut w, ORTHO_SIZE), vec![Value::Float(0.4)]);
    let (persp_img, res) = rgb(&mut w, cam);
    assert!(persp_img != ortho_img);
    // u = 100 (1 - x / (0.9 tan 30)): the cube's top edges at x = 0.0703 and -0.0297
    // are at u = 86.47 and 105.72, so columns 86 to 105.
    assert_eq!(red_columns(&persp_img, res, 50), (86..=105).collect::<Vec<_>>());

    // Out of range: refused, the sensor unchanged.
    assert!(
        call(
            &mut w,
            "sim.setObjectFloatParam",
            &[Value::Int(cam), Value::Int(ORTHO_SIZE), Value::Float(0.0)]
        )
        .is_err()
    );
    assert_eq!(get_float(&mut w, ORTHO_SIZE), vec![Value::Float(0.4)]);
}

#[test]
fn the_scene_format_checks_the_projection() {
    let sensor = |extra: &str| format!("[[object]]\nname = \"cam\"\nkind = \"vision_sensor\"\n{extra}\n");
    assert!(load_err(&sensor("projection = \"fisheye\"")).contains("unknown projection 'fisheye'"));
    assert!(load_err(&sensor("projection = \"orthographic\"\northo_size = 0")).contains("ortho_size > 0"));
    // Perspective by default, with a 1 m ortho size kept for a switch.
    let w = load(&sensor(""));
    let gantry_sim_core::world::ObjectKind::VisionSensor(m) = w.world.object(find(&w, "/cam")).unwrap().kind else {
        panic!("vision sensor")
    };
    assert_eq!((m.projection, m.ortho_size), (Projection::Perspective, 1.0));
}

#[test]
fn a_640_by_480_sensor_renders_its_whole_image() {
    let mut w = load(
        r#"
[floor]

[[object]]
name = "cam"
kind = "vision_sensor"
position = [0, 0, 1]
orientation_deg = [180, 0, 0]
resolution = [640, 480]
fov_deg = 60
near = 0.01
far = 2.0
"#,
    );
    let cam = find(&w, "/cam");
    let (img, res) = rgb(&mut w, cam);
    assert_eq!(res, [640, 480]);
    assert_eq!(img.len(), 640 * 480 * 3);
    // The floor fills it: no background pixel.
    assert!(img.chunks_exact(3).all(|p| p != [0, 0, 0]));
    let (d, res) = depth(&mut w, cam, 1);
    assert_eq!((d.len(), res), (640 * 480, [640, 480]));
    assert!(d.iter().all(|&z| (z - 1.0).abs() < 1e-5));
    let got = call(&mut w, "sim.getVisionSensorRes", &[Value::Int(cam)]).unwrap();
    assert_eq!(got, vec![Value::Array(vec![Value::Int(640), Value::Int(480)])]);
}

/// `n` sensors of `side` x `side` pixels.
fn sensors(n: usize, side: u32) -> String {
    (0..n)
        .map(|i| format!("[[object]]\nname = \"cam{i}\"\nkind = \"vision_sensor\"\nresolution = [{side}, {side}]\n"))
        .collect()
}

#[test]
fn sensor_images_are_held_to_2048_a_side_and_1_gib_in_all() {
    // 2048 a side is accepted; 2049 is not.
    let w = load(&sensors(1, 2048));
    assert!(matches!(
        w.world.object(find(&w, "/cam0")).unwrap().kind,
        gantry_sim_core::world::ObjectKind::VisionSensor(_)
    ));
    assert!(load_err(&sensors(1, 2049)).contains("1..=2048"));
    // 36 sensors of 2048 x 2048 hold 36 x 28 MiB = 1008 MiB of RGB and depth; a 37th
    // would pass 1 GiB, and the loader says so (nothing is allocated to find out).
    let _ = load(&sensors(36, 2048));
    let e = load_err(&sensors(37, 2048));
    assert!(
        e.contains("cam36") && e.contains("1036 MiB") && e.contains("1024 MiB cap"),
        "{e}"
    );

    // At run time, the resolution parameters keep to the same cap.
    let mut w =
        load(&(sensors(36, 2048) + "[[object]]\nname = \"small\"\nkind = \"vision_sensor\"\nresolution = [64, 64]\n"));
    let small = find(&w, "/small");
    let set = |w: &mut Sim, v: i64| {
        call(
            w,
            "sim.setObjectInt32Param",
            &[Value::Int(small), Value::Int(RESOLUTION_X), Value::Int(v)],
        )
    };
    assert!(set(&mut w, 2048).is_ok());
    let e = set(&mut w, 2049).unwrap_err();
    assert!(e.contains("1..=2048"), "{e}");
    // 2048 x 2048 would make it the 37th large sensor.
    let e = call(
        &mut w,
        "sim.setObjectInt32Param",
        &[Value::Int(small), Value::Int(RESOLUTION_X + 1), Value::Int(2048)],
    )
    .unwrap_err();
    assert!(e.contains("1036 MiB, over the 1024 MiB cap"), "{e}");
    let got = call(&mut w, "sim.getVisionSensorRes", &[Value::Int(small)]).unwrap();
    assert_eq!(got, vec![Value::Array(vec![Value::Int(2048), Value::Int(64)])]);
}

#[test]
fn a_loaded_model_keeps_to_the_same_cap() {
    use gantry_sim_core::world::ObjectKind;
    let mut w = load(&sensors(36, 2048));
    // sim.loadModel's path: the model's large sensor would be the 37th; a small one fits.
    let model = load_scene_text(
        &DiskFiles,
        "[[object]]\nname = \"big\"\nkind = \"vision_sensor\"\nresolution = [2048, 2048]\n\n[[object]]\nname = \"small\"\nkind = \"vision_sensor\"\nresolution = [64, 64]\n",
        Path::new("model.toml"),
        &LoadOptions::default(),
    )
    .expect("model");
    let (handles, warnings) = w.world.import_model(&model);
    let kind = |w: &Sim, h: Handle| w.world.object(h).expect("object").kind.name();
    assert_eq!(kind(&w, handles[0]), "dummy");
    assert!(matches!(
        w.world.object(handles[1]).unwrap().kind,
        ObjectKind::VisionSensor(_)
    ));
    assert!(
        warnings
            .iter()
            .any(|m| m.contains("big") && m.contains("over 1024 MiB")),
        "{warnings:?}"
    );
}
