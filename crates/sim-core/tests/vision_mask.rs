//! Segmentation masks (`sim.getVisionSensorMask`, gantry's own), CoppeliaSim's
//! colour-coded render mode (`sim.visionintparam_render_mode`), and the sensors that
//! ignore RGB or depth (`sim.visionintparam_rgbignored` / `_depthignored`, and the
//! scene keys `render_mode`, `ignore_rgb`, `ignore_depth`).
//!
//! The scene is seen straight down by an orthographic sensor, so which shape each
//! pixel sees follows from the geometry exactly.

use crate::util;

use std::path::Path;

use gantry_sim_core::scene::{DiskFiles, LoadOptions, RenderMode, load_scene_text};
use gantry_sim_core::{Handle, Sim, Value};
use util::{call, find, image_reply as reply_bytes};

// CoppeliaSim's parameter numbers and render modes.
const RENDER_MODE: i64 = 1017;
const RGB_IGNORED: i64 = 1020;
const DEPTH_IGNORED: i64 = 1021;
const RENDERMODE_COLORCODED: i64 = 2;

fn load(text: &str) -> Sim {
    util::text_scene("inline.toml", text)
}

fn words<T>(bytes: &[u8], f: fn([u8; 4]) -> T) -> Vec<T> {
    bytes.chunks_exact(4).map(|c| f([c[0], c[1], c[2], c[3]])).collect()
}

fn handle(w: &mut Sim, h: Handle) {
    call(w, "sim.handleVisionSensor", &[Value::Int(h)]).expect("handled");
}

fn rgb(w: &mut Sim, h: Handle) -> Vec<u8> {
    reply_bytes(&call(w, "sim.getVisionSensorImg", &[Value::Int(h)]).expect("image")).0
}

fn depth(w: &mut Sim, h: Handle) -> Vec<f32> {
    let (bytes, _) = reply_bytes(&call(w, "sim.getVisionSensorDepth", &[Value::Int(h)]).expect("depth"));
    words(&bytes, f32::from_le_bytes)
}

/// The mask as handles (`i32`s on the wire).
fn mask(w: &mut Sim, h: Handle) -> (Vec<Handle>, [usize; 2]) {
    let (bytes, res) = reply_bytes(&call(w, "sim.getVisionSensorMask", &[Value::Int(h)]).expect("mask"));
    (words(&bytes, |b| Handle::from(i32::from_le_bytes(b))), res)
}

fn set_int(w: &mut Sim, h: Handle, id: i64, v: i64) -> Result<Vec<Value>, String> {
    call(
        w,
        "sim.setObjectInt32Param",
        &[Value::Int(h), Value::Int(id), Value::Int(v)],
    )
}

/// A 200 x 100 orthographic sensor 1 m above a 0.3 x 0.3 m floor, looking straight
/// down, 0.4 x 0.2 m of view (2 mm a pixel; image right is the world's -X, image up
/// the world's -Y). A red cube and a green cylinder stand on the floor; beyond
/// |x| = 0.15 m the sensor sees nothing.
const SCENE: &str = r#"
[floor]
size = [0.3, 0.3]

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
position = [0.0503, 0, 0.05]
color = [1, 0, 0]

[[object]]
name = "can"
kind = "shape"
shape = "cylinder"
radius = 0.03
length = 0.2
position = [-0.0797, 0.0, 0.1]
color = [0, 1, 0]
"#;

/// The world x (m) under column `u` (from the left) of the sensor: image right is the
/// world's -X, 2 mm a pixel, the view centred on x = 0.
fn column_x(u: usize) -> f64 {
    0.2 - 0.002 * (u as f64 + 0.5)
}

#[test]
fn the_mask_names_the_shape_each_pixel_sees() {
    let mut w = load(SCENE);
    let cam = find(&w, "/cam");
    let (cube, can) = (find(&w, "/cube"), find(&w, "/can"));
    let floor = w
        .world
        .handles()
        .iter()
        .copied()
        .find(|&h| w.world.object(h).is_ok_and(|o| o.alias == "Floor"))
        .expect("the floor is an object");
    handle(&mut w, cam);
    let (m, res) = mask(&mut w, cam);
    assert_eq!(res, [200, 100]);
    assert_eq!(m.len(), 200 * 100);
    // Row 50 runs through the middle (y = 0): floor, can, floor, cube, floor, then
    // nothing beyond the floor's edges, each where the geometry puts it.
    let row = &m[50 * 200..51 * 200];
    for (u, &got) in row.iter().enumerate() {
        let x = column_x(u);
        let want = if (x - 0.0503).abs() < 0.05 {
            cube
        } else if (x + 0.0797).abs() < 0.03 {
            can
        } else if x.abs() < 0.15 {
            floor
        } else {
            -1
        };
        assert_eq!(got, want, "column {u} (x = {x:.4} m)");
    }
    // Every pixel's mask agrees with its colour and depth: red is the cube, green the
    // can, grey the floor, and -1 exactly where nothing is seen (depth 1).
    let (img, d) = (rgb(&mut w, cam), depth(&mut w, cam));
    for (i, &id) in m.iter().enumerate() {
        let [r, g, b] = [img[3 * i], img[3 * i + 1], img[3 * i + 2]];
        let want = match (r > 0, g > 0, b > 0) {
            (true, false, false) => cube,
            (false, true, false) => can,
            (true, true, true) => floor,
            _ => -1,
        };
        assert_eq!(id, want, "pixel {i}: rgb {r} {g} {b}");
        assert_eq!(id == -1, d[i] == 1.0, "pixel {i}: depth {}", d[i]);
    }
    // A portion: the 3 x 2 pixels at column 48, row 49 (from the bottom).
    let reply = call(
        &mut w,
        "sim.getVisionSensorMask",
        &[
            Value::Int(cam),
            Value::Array(vec![Value::Int(48), Value::Int(49)]),
            Value::Array(vec![Value::Int(3), Value::Int(2)]),
        ],
    )
    .expect("portion");
    let (bytes, size) = reply_bytes(&reply);
    assert_eq!(size, [3, 2]);
    let want: Vec<Handle> = [49 * 200 + 48, 50 * 200 + 48]
        .iter()
        .flat_map(|&i| m[i..i + 3].to_vec())
        .collect();
    assert_eq!(words(&bytes, |b| Handle::from(i32::from_le_bytes(b))), want);
}

#[test]
fn drawing_the_mask_changes_no_bit_of_the_image_or_the_depth() {
    let mut plain = load(SCENE);
    let mut masked = load(SCENE);
    let cam = find(&plain, "/cam");
    // Turn masks on in one of the two, then render both from a new pose.
    mask(&mut masked, cam);
    let renders = masked.vision.render_count(cam);
    for w in [&mut plain, &mut masked] {
        let pose = gantry_sim_core::math::pose_from_euler([0.03, -0.02, 0.8], [3.0, 0.2, 0.4]);
        w.world.set_world_pose(cam, pose).unwrap();
        handle(w, cam);
    }
    assert_eq!(
        masked.vision.render_count(cam),
        renders + 1,
        "one render draws image and mask"
    );
    let depth_bits = |w: &mut Sim| depth(w, cam).iter().map(|d| d.to_bits()).collect::<Vec<_>>();
    assert_eq!(rgb(&mut plain, cam), rgb(&mut masked, cam));
    assert_eq!(depth_bits(&mut plain), depth_bits(&mut masked));
    assert!(plain.vision.image(cam).unwrap().mask().is_none());
    assert!(masked.vision.image(cam).unwrap().mask().is_some());
    // Perspective too: the same comparison through a 60-degree view.
    for w in [&mut plain, &mut masked] {
        call(
            w,
            "sim.setObjectInt32Param",
            &[Value::Int(cam), Value::Int(1018), Value::Int(1)],
        )
        .unwrap();
        handle(w, cam);
    }
    assert_eq!(rgb(&mut plain, cam), rgb(&mut masked, cam));
    assert_eq!(depth_bits(&mut plain), depth_bits(&mut masked));
}

#[test]
fn an_explicitly_handled_sensor_renders_again_for_its_first_mask() {
    let mut w = load(SCENE);
    let cam = find(&w, "/cam");
    handle(&mut w, cam);
    assert_eq!(w.vision.render_count(cam), 1);
    // The first mask needs a render with one: image, depth and mask of one instant.
    mask(&mut w, cam);
    assert_eq!(w.vision.render_count(cam), 2);
    // Later reads reuse it, and later handlings draw it along.
    mask(&mut w, cam);
    assert_eq!(w.vision.render_count(cam), 2);
    handle(&mut w, cam);
    mask(&mut w, cam);
    assert_eq!(w.vision.render_count(cam), 3);
}

#[test]
fn colour_coded_images_hold_the_handles_as_colours() {
    let mut w = load(SCENE);
    let cam = find(&w, "/cam");
    let get =
        |w: &mut Sim, id: i64| call(w, "sim.getObjectInt32Param", &[Value::Int(cam), Value::Int(id)]).expect("param");
    assert_eq!(get(&mut w, RENDER_MODE), vec![Value::Int(0)]);
    let (shaded_depth, (m, _)) = {
        handle(&mut w, cam);
        (depth(&mut w, cam), mask(&mut w, cam))
    };
    set_int(&mut w, cam, RENDER_MODE, RENDERMODE_COLORCODED).expect("colour-coded");
    assert_eq!(get(&mut w, RENDER_MODE), vec![Value::Int(RENDERMODE_COLORCODED)]);
    handle(&mut w, cam);
    let img = rgb(&mut w, cam);
    // As PyRep and RLBench decode it: r + 256 g + 65536 b, white where nothing is.
    for (i, &id) in m.iter().enumerate() {
        let px = &img[3 * i..3 * i + 3];
        if id == -1 {
            assert_eq!(px, [255, 255, 255], "pixel {i}");
        } else {
            let coded = Handle::from(px[0]) + 256 * Handle::from(px[1]) + 65536 * Handle::from(px[2]);
            assert_eq!(coded, id, "pixel {i}");
        }
    }
    // Depth is the same as in the shaded image; the mask comes along for free.
    assert_eq!(depth(&mut w, cam), shaded_depth);
    let kept: Vec<Handle> = w
        .vision
        .image(cam)
        .unwrap()
        .mask()
        .expect("a mask")
        .iter()
        .map(|&id| Handle::from(id))
        .collect();
    assert_eq!(kept, m);
    // Back to the visible colours.
    set_int(&mut w, cam, RENDER_MODE, 0).unwrap();
    handle(&mut w, cam);
    assert!(
        rgb(&mut w, cam)
            .chunks_exact(3)
            .any(|p| p == [255, 0, 0] || p[0] > 0 && p[1] == 0)
    );
    // Modes gantry does not render are refused, naming what it does render.
    let err = set_int(&mut w, cam, RENDER_MODE, 3).unwrap_err();
    assert!(
        err.contains("render mode 3") && err.contains("sim.rendermode_colorcoded"),
        "{err}"
    );
}

#[test]
fn a_sensor_ignoring_rgb_or_depth_leaves_that_image_alone() {
    let mut w = load(SCENE);
    let cam = find(&w, "/cam");
    handle(&mut w, cam);
    let (full_rgb, full_depth) = (rgb(&mut w, cam), depth(&mut w, cam));
    assert!(full_rgb.iter().any(|&c| c != 0));

    // RGB ignored: depth as before, the image unchanged from the last render that made
    // it (CoppeliaSim keeps its buffer), and packet 1's colour values 0.
    set_int(&mut w, cam, RGB_IGNORED, 1).unwrap();
    let mut fresh = load(SCENE);
    set_int(&mut fresh, cam, RGB_IGNORED, 1).unwrap();
    for w in [&mut w, &mut fresh] {
        let reply = call(w, "sim.handleVisionSensor", &[Value::Int(cam)]).unwrap();
        let Some(Value::Array(packet1)) = reply.get(1) else {
            panic!("packet 1: {reply:?}");
        };
        let p: Vec<f64> = packet1.iter().map(|v| v.as_f64().unwrap()).collect();
        assert!(
            p[..4].iter().chain(&p[5..9]).chain(&p[10..14]).all(|&v| v == 0.0),
            "{p:?}"
        );
        assert!(p[14] > 0.0, "depth average {}", p[14]);
        assert_eq!(depth(w, cam), full_depth);
    }
    assert_eq!(rgb(&mut w, cam), full_rgb);
    assert!(
        rgb(&mut fresh, cam).iter().all(|&c| c == 0),
        "never rendered in colour: black"
    );
    // The mask still works without colour.
    assert!(mask(&mut fresh, cam).0.contains(&find(&fresh, "/cube")));

    // Depth ignored: colour as before, depth left as it was.
    let mut w = load(SCENE);
    set_int(&mut w, cam, DEPTH_IGNORED, 1).unwrap();
    let get =
        |w: &mut Sim, id: i64| call(w, "sim.getObjectInt32Param", &[Value::Int(cam), Value::Int(id)]).expect("param");
    assert_eq!(get(&mut w, DEPTH_IGNORED), vec![Value::Int(1)]);
    assert_eq!(get(&mut w, RGB_IGNORED), vec![Value::Int(0)]);
    handle(&mut w, cam);
    assert_eq!(rgb(&mut w, cam), full_rgb);
    assert!(depth(&mut w, cam).iter().all(|&d| d == 1.0));
}

#[test]
fn the_scene_sets_the_render_mode_and_what_to_ignore() {
    let text = SCENE.replace(
        "far = 2.0\n",
        "far = 2.0\nrender_mode = \"color_coded\"\nignore_depth = true\n",
    );
    let model = load_scene_text(&DiskFiles, &text, Path::new("inline.toml"), &LoadOptions::default()).expect("scene");
    assert!(model.warnings.is_empty(), "the keys are known: {:?}", model.warnings);
    let mut w = Sim::new(&model);
    let cam = find(&w, "/cam");
    let gantry_sim_core::world::ObjectKind::VisionSensor(m) = &w.world.object(cam).unwrap().kind else {
        panic!("a vision sensor");
    };
    assert_eq!(
        (m.render_mode, m.ignore_rgb, m.ignore_depth),
        (RenderMode::ColorCoded, false, true)
    );
    handle(&mut w, cam);
    let img = rgb(&mut w, cam);
    let cube = find(&w, "/cube");
    let coded = [cube as u8, (cube >> 8) as u8, (cube >> 16) as u8];
    assert!(img.chunks_exact(3).any(|p| p == coded), "the cube's handle as a colour");

    // A mode the scene format does not know is refused, naming the two it does.
    let bad = SCENE.replace("far = 2.0\n", "far = 2.0\nrender_mode = \"povray\"\n");
    let err = load_scene_text(&DiskFiles, &bad, Path::new("inline.toml"), &LoadOptions::default())
        .expect_err("refused")
        .to_string();
    assert!(err.contains("povray") && err.contains("color_coded"), "{err}");

    // The ROS 2 image rate: read, and refused when negative or not a number.
    let rated = SCENE.replace("far = 2.0\n", "far = 2.0\nros2_rate = 12.5\n");
    let model = load_scene_text(&DiskFiles, &rated, Path::new("inline.toml"), &LoadOptions::default()).expect("scene");
    let rate = model.objects.iter().find_map(|o| match &o.kind {
        gantry_sim_core::scene::ObjectModelKind::VisionSensor(v) => v.ros2_rate,
        _ => None,
    });
    assert_eq!(rate, Some(12.5));
    for bad in ["-1.0", "nan"] {
        let text = SCENE.replace("far = 2.0\n", &format!("far = 2.0\nros2_rate = {bad}\n"));
        let err = load_scene_text(&DiskFiles, &text, Path::new("inline.toml"), &LoadOptions::default())
            .expect_err("refused")
            .to_string();
        assert!(err.contains("ros2_rate"), "{err}");
    }
}

#[test]
fn masks_of_what_is_not_a_sensor_or_outside_the_image_are_refused() {
    let mut w = load(SCENE);
    let (cam, cube) = (find(&w, "/cam"), find(&w, "/cube"));
    let err = call(&mut w, "sim.getVisionSensorMask", &[Value::Int(cube)]).unwrap_err();
    assert!(err.contains("vision sensor"), "{err}");
    let err = call(&mut w, "sim.getVisionSensorMask", &[Value::Int(9999)]).unwrap_err();
    assert!(err.contains("does not exist"), "{err}");
    let err = call(
        &mut w,
        "sim.getVisionSensorMask",
        &[
            Value::Int(cam),
            Value::Array(vec![Value::Int(199), Value::Int(0)]),
            Value::Array(vec![Value::Int(2), Value::Int(1)]),
        ],
    )
    .unwrap_err();
    assert!(err.contains("exceeds the 200x100 image"), "{err}");
    // Nothing rendered for a refused call.
    assert_eq!(w.vision.render_count(cam), 0);
}

#[test]
fn bad_sensor_settings_and_poses_are_refused_and_the_sensor_still_renders() {
    let mut w = load(SCENE);
    let cam = find(&w, "/cam");
    let before = {
        handle(&mut w, cam);
        mask(&mut w, cam).0
    };
    // Clipping planes: zero, inverted, not a number (CoppeliaSim's parameter numbers).
    let (near, far) = (1000, 1001);
    for (id, v) in [
        (near, 0.0),
        (near, 3.0),
        (far, 0.001),
        (far, f64::NAN),
        (near, f64::INFINITY),
    ] {
        let err = call(
            &mut w,
            "sim.setObjectFloatParam",
            &[Value::Int(cam), Value::Int(id), Value::Float(v)],
        )
        .unwrap_err();
        assert!(err.contains("0 < near < far"), "parameter {id} = {v}: {err}");
    }
    // Poses with a NaN position or orientation.
    let err = call(
        &mut w,
        "sim.setObjectPosition",
        &[Value::Int(cam), Value::floats(&[f64::NAN, 0.0, 1.0])],
    )
    .unwrap_err();
    assert!(err.contains("finite"), "{err}");
    let err = call(
        &mut w,
        "sim.setObjectOrientation",
        &[Value::Int(cam), Value::floats(&[f64::NAN, 0.0, 0.0])],
    )
    .unwrap_err();
    assert!(err.contains("finite"), "{err}");
    let err = call(
        &mut w,
        "sim.setObjectQuaternion",
        &[Value::Int(cam), Value::floats(&[f64::NAN, 0.0, 0.0, 1.0])],
    )
    .unwrap_err();
    assert!(err.contains("finite"), "{err}");
    // And through the world itself, which the API's argument checks stand in front of.
    let mut nan_turn = w.world.object(cam).unwrap().world;
    nan_turn.rotation = nalgebra::Unit::new_unchecked(nalgebra::Quaternion::new(f64::NAN, 0.0, 0.0, 0.0));
    let err = w.world.set_world_pose(cam, nan_turn).unwrap_err().to_string();
    assert!(err.contains("finite"), "{err}");
    // Absurd resolutions, at run time.
    for side in [0, -5, 1 << 20] {
        assert!(set_int(&mut w, cam, 1002, side).is_err(), "resolution {side}");
    }
    // Nothing changed: the same view, the same mask.
    handle(&mut w, cam);
    assert_eq!(mask(&mut w, cam).0, before);
}
