//! Vision sensors: the CPU renderer seen through the API (`sim.getVisionSensorImg`,
//! `sim.getVisionSensorDepth`, `sim.handleVisionSensor`, ...) and the `simVision`
//! work-image flow of the BubbleRob tutorial's edge-detection script.

use crate::util;

use std::path::Path;
use std::time::Instant;

use gantry_sim_core::api::{self, CallContext};
use gantry_sim_core::math::Pose;
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene_text};
use gantry_sim_core::{Handle, Sim, Value, vision};

fn bubble_rob() -> Sim {
    util::asset_scene("scenes/bubble_rob.toml")
}

fn find(w: &Sim, path: &str, index: usize) -> Handle {
    w.world.find(path, None, index).expect(path)
}

fn call(w: &mut Sim, name: &str, args: &[Value]) -> Result<Vec<Value>, String> {
    api::call(w, &CallContext::default(), name, args).map_err(|e| e.to_string())
}

/// The sensor 0.12 m above the floor at (0.1, 0, 0.12), looking along +X, with
/// obstacle 0 (a grey cylinder, radius 0.05, height 0.2) centred 0.4 m ahead: its
/// front face is 0.35 m away. Obstacle 1 is moved out of sight.
fn scene_with_obstacle() -> (Sim, Handle) {
    let mut w = bubble_rob();
    let sensor = find(&w, "/bubbleRob/visionSensor", 0);
    let o0 = find(&w, "/obstacle", 0);
    w.world
        .set_world_pose(o0, Pose::translation(0.5, 0.0, 0.1))
        .expect("pose");
    (w, sensor)
}

/// An image and its `{width, height}` from a `getVisionSensorImg`-shaped reply.
fn image(reply: &[Value]) -> (Vec<u8>, [usize; 2]) {
    let Some(Value::Bytes(bytes)) = reply.first() else {
        panic!("expected bytes, got {reply:?}");
    };
    let Some(Value::Array(res)) = reply.get(1) else {
        panic!("expected a resolution, got {reply:?}");
    };
    let dim = |k: usize| res[k].as_i64().expect("integer") as usize;
    (bytes.clone(), [dim(0), dim(1)])
}

fn rgb(w: &mut Sim, h: Handle) -> (Vec<u8>, [usize; 2]) {
    image(&call(w, "sim.getVisionSensorImg", &[Value::Int(h)]).expect("image"))
}

/// Pixel at column `x` (from the left) and row `y` (from the bottom).
fn pixel(img: &[u8], res: [usize; 2], x: usize, y: usize) -> [u8; 3] {
    let i = 3 * (y * res[0] + x);
    [img[i], img[i + 1], img[i + 2]]
}

fn depth_floats(reply: &[Value]) -> (Vec<f32>, [usize; 2]) {
    let (bytes, res) = image(reply);
    let floats = bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    (floats, res)
}

fn near(actual: u8, expected: f64, tol: f64, what: &str) {
    assert!(
        (f64::from(actual) - expected).abs() <= tol,
        "{what}: {actual}, expected {expected:.1} ± {tol}"
    );
}

#[test]
fn obstacle_ahead_shows_its_colour_and_distance() {
    let (mut w, sensor) = scene_with_obstacle();
    let (img, res) = rgb(&mut w, sensor);
    assert_eq!(res, [256, 256]);
    assert_eq!(img.len(), 256 * 256 * 3);

    // Centre: the cylinder's face, normal along the view axis, so ambient 0.3 +
    // headlight 0.45 of its colour 0.85.
    let c = pixel(&img, res, 128, 128);
    for ch in c {
        near(ch, 0.85 * 0.75 * 255.0, 4.0, "obstacle centre");
    }
    // Bottom rows: the floor (0.55, 0.55, 0.5) lit by ambient + the top light.
    let f = pixel(&img, res, 20, 5);
    near(f[0], 0.55 * 0.65 * 255.0, 2.0, "floor red");
    near(f[2], 0.5 * 0.65 * 255.0, 2.0, "floor blue");
    // Top corners look above the floor at nothing within the 1 m far plane: background.
    assert_eq!(pixel(&img, res, 0, 255), [0, 0, 0]);
    assert_eq!(pixel(&img, res, 255, 255), [0, 0, 0]);

    // Depth at the centre: 0.35 m, planar, to within a pixel's worth (the cylinder
    // is a 32-gon whose chord is at most 0.25 mm inside the true surface).
    let (d, dres) =
        depth_floats(&call(&mut w, "sim.getVisionSensorDepth", &[Value::Int(sensor), Value::Int(1)]).unwrap());
    assert_eq!(dres, [256, 256]);
    let centre = d[128 * 256 + 128];
    assert!((centre - 0.35).abs() < 2e-3, "depth at centre {centre} m");
    // Normalised by default: (z - near) / (far - near), and 1 for the background.
    let (n, _) = depth_floats(&call(&mut w, "sim.getVisionSensorDepth", &[Value::Int(sensor)]).unwrap());
    assert!((n[128 * 256 + 128] - (0.35 - 0.01) / 0.99).abs() < 2e-3);
    assert_eq!(n[255 * 256], 1.0);
    assert!(
        (d[255 * 256] - 1.0).abs() < 1e-6,
        "background at the far plane in metres"
    );
}

#[test]
fn image_left_is_the_sensor_x_axis_and_row_zero_the_bottom() {
    let (mut w, sensor) = scene_with_obstacle();
    // The sensor's +X is the world's +Y (its left when looking along +X); an obstacle
    // there must appear in the left half of the image.
    let o1 = find(&w, "/obstacle", 1);
    w.world
        .set_world_pose(o1, Pose::translation(0.7, 0.15, 0.1))
        .expect("pose");
    let (img, res) = rgb(&mut w, sensor);
    assert_ne!(pixel(&img, res, 70, 140), [0, 0, 0], "obstacle 1 on the left");
    assert_eq!(pixel(&img, res, 186, 140), [0, 0, 0], "nothing on the right");
    // Row 0 is the bottom: the floor is there, the top row sees nothing.
    assert_ne!(pixel(&img, res, 40, 0), [0, 0, 0]);
    assert_eq!(pixel(&img, res, 40, 255), [0, 0, 0]);
}

#[test]
fn field_of_view_spans_the_larger_side() {
    // A 128 x 64 sensor with a 90° view angle (horizontal, the larger side), at
    // z = 0.5 looking along +X, and a small red cube 1 m ahead, 0.5 m to the left
    // (sensor +X) and 0.25 m up: tan = 0.5 of the 45° half-angle horizontally and of
    // the 26.6° half-angle vertically, so column 32 and row 48.
    let text = r#"
[[object]]
name = "cam"
kind = "vision_sensor"
position = [0, 0, 0.5]
orientation_deg = [0, 90, 90]
resolution = [128, 64]
fov_deg = 90
near = 0.01
far = 3.0

[[object]]
name = "cube"
kind = "shape"
shape = "box"
size = [0.04, 0.04, 0.04]
position = [1, 0.5, 0.75]
color = [1, 0, 0]
"#;
    let model = load_scene_text(&DiskFiles, text, Path::new("inline.toml"), &LoadOptions::default()).expect("scene");
    let mut w = Sim::new(&model);
    let cam = find(&w, "/cam", 0);
    let (img, res) = rgb(&mut w, cam);
    assert_eq!(res, [128, 64]);
    let p = pixel(&img, res, 32, 48);
    assert!(p[0] > 100 && p[1] == 0 && p[2] == 0, "red cube at (32, 48), got {p:?}");
    // Only a few pixels around it are red.
    let red = img.chunks_exact(3).filter(|px| px[0] > 0).count();
    assert!((2..=25).contains(&red), "{red} red pixels");
    let res_reply = call(&mut w, "sim.getVisionSensorRes", &[Value::Int(cam)]).unwrap();
    assert_eq!(res_reply, vec![Value::Array(vec![Value::Int(128), Value::Int(64)])]);
}

#[test]
fn edge_detection_outlines_the_obstacle() {
    let (mut w, sensor) = scene_with_obstacle();
    let (raw, res) = rgb(&mut w, sensor);
    // The obstacle's silhouette on row 150 (above the floor, whose far edge is near
    // row 101): the first and last non-background columns.
    let row = 150;
    let lit: Vec<usize> = (0..256).filter(|&x| pixel(&raw, res, x, row) != [0, 0, 0]).collect();
    let (left, right) = (lit[0], lit[lit.len() - 1]);
    assert!(
        left > 90 && right < 166 && right - left > 40,
        "silhouette {left}..{right}"
    );

    // The tutorial's sysCall_vision, called as a script attached to the sensor would.
    let ctx = CallContext {
        script_object: Some(sensor),
        source: "edge_detect.lua",
    };
    let me = Value::Int(-4); // sim.handle_self
    api::call(&mut w, &ctx, "simVision.sensorImgToWorkImg", std::slice::from_ref(&me)).unwrap();
    api::call(
        &mut w,
        &ctx,
        "simVision.edgeDetectionOnWorkImg",
        &[me.clone(), Value::Float(0.2)],
    )
    .unwrap();
    api::call(&mut w, &ctx, "simVision.workImgToSensorImg", &[me]).unwrap();
    let (edges, _) = rgb(&mut w, sensor);
    assert_eq!(
        w.vision.render_count(sensor),
        1,
        "reading the edge image does not render again"
    );

    let white = [255, 255, 255];
    let black = [0, 0, 0];
    assert_eq!(pixel(&edges, res, left, row), white, "left silhouette");
    assert_eq!(pixel(&edges, res, right, row), white, "right silhouette");
    assert_eq!(
        pixel(&edges, res, (left + right) / 2, row),
        black,
        "inside the obstacle"
    );
    assert_eq!(pixel(&edges, res, 20, row), black, "background");
    assert_eq!(pixel(&edges, res, 20, 30), black, "uniform floor");
    assert_eq!(pixel(&edges, res, 128, 30), black, "floor below the obstacle");
    // Every pixel is black or white.
    assert!(edges.chunks_exact(3).all(|p| p == white || p == black));
    // The floor's far edge (the far clipping plane) is a horizontal edge.
    assert!((95..110).any(|y| pixel(&edges, res, 20, y) == white), "floor horizon");
    // Only the obstacle's outline, the horizon and the image frame are white.
    let count = edges.chunks_exact(3).filter(|p| *p == white).count();
    assert!((400..3000).contains(&count), "{count} white pixels");
}

#[test]
fn images_render_only_when_handled() {
    let (mut w, sensor) = scene_with_obstacle();
    assert_eq!(
        w.vision.render_count(sensor),
        0,
        "nothing renders until read or handled"
    );
    rgb(&mut w, sensor);
    rgb(&mut w, sensor);
    call(&mut w, "sim.getVisionSensorDepth", &[Value::Int(sensor)]).unwrap();
    call(&mut w, "sim.readVisionSensor", &[Value::Int(sensor)]).unwrap();
    assert_eq!(w.vision.render_count(sensor), 1, "one render per step for readers");
    w.finish_step();
    rgb(&mut w, sensor);
    assert_eq!(w.vision.render_count(sensor), 2, "a new step makes the image stale");
    let stamp = w.vision.image(sensor).and_then(|s| s.rendered()).expect("stamp");
    assert_eq!(stamp.step, 1);

    // Explicit handling renders every time, and from then on readers get the image
    // of the last handling.
    call(&mut w, "sim.handleVisionSensor", &[Value::Int(sensor)]).unwrap();
    call(&mut w, "sim.handleVisionSensor", &[Value::Int(sensor)]).unwrap();
    assert_eq!(w.vision.render_count(sensor), 4);
    w.finish_step();
    rgb(&mut w, sensor);
    assert_eq!(w.vision.render_count(sensor), 4);
    vision::handle_vision_sensor(&w.world, &mut w.vision, sensor).unwrap();
    assert_eq!(w.vision.render_count(sensor), 5);
}

#[test]
fn handle_and_read_return_the_default_packet() {
    let (mut w, sensor) = scene_with_obstacle();
    let reply = call(&mut w, "sim.handleVisionSensor", &[Value::Int(sensor)]).unwrap();
    assert_eq!(reply.len(), 2, "{reply:?}");
    assert_eq!(reply[0], Value::Int(0));
    let Value::Array(p) = &reply[1] else {
        panic!("packet 1 is a table: {reply:?}");
    };
    let p: Vec<f64> = p.iter().map(|v| v.as_f64().unwrap()).collect();
    assert_eq!(p.len(), 15);
    for k in 0..5 {
        assert!(
            p[k] <= p[10 + k] && p[10 + k] <= p[5 + k],
            "min <= avg <= max for value {k}: {p:?}"
        );
    }
    assert_eq!(p[0], 0.0, "the background is black");
    assert_eq!(p[9], 1.0, "and at the far plane");
    assert_eq!(
        call(&mut w, "sim.readVisionSensor", &[Value::Int(sensor)]).unwrap(),
        reply
    );

    // A sysCall_vision callback's trigger and packets, as the host records them.
    w.vision
        .set_callback_result(sensor, true, vec![vision::unpack_floats(&2.5f32.to_le_bytes())])
        .unwrap();
    let read = call(&mut w, "sim.readVisionSensor", &[Value::Int(sensor)]).unwrap();
    assert_eq!(read[0], Value::Int(1));
    assert_eq!(read[2], Value::floats(&[2.5]));
    // sim.handle_all renders every sensor.
    assert_eq!(
        call(&mut w, "sim.handleVisionSensor", &[Value::Int(-2)]).unwrap(),
        vec![Value::Int(0)]
    );
    assert_eq!(w.vision.render_count(sensor), 2);
}

#[test]
fn set_image_and_work_image_round_trip() {
    let (mut w, sensor) = scene_with_obstacle();
    // Written images are what readers get, bottom row first.
    let grey: Vec<u8> = (0..256 * 256).map(|i| (i % 256) as u8).collect();
    call(
        &mut w,
        "sim.setVisionSensorImg",
        &[Value::Int(sensor), Value::Bytes(grey), Value::Int(1)],
    )
    .unwrap();
    assert_eq!(
        call(&mut w, "sim.readVisionSensor", &[Value::Int(sensor)]).unwrap(),
        vec![Value::Int(-1)],
        "never handled: -1 alone"
    );
    let (img, res) = rgb(&mut w, sensor);
    assert_eq!(w.vision.render_count(sensor), 0);
    assert_eq!(pixel(&img, res, 7, 3), [7, 7, 7]);

    // A portion, greyscale.
    let reply = call(
        &mut w,
        "sim.getVisionSensorImg",
        &[
            Value::Int(sensor),
            Value::Int(1),
            Value::Float(0.0),
            Value::floats(&[100.0, 10.0]),
            Value::floats(&[4.0, 2.0]),
        ],
    )
    .unwrap();
    let (part, pres) = image(&reply);
    assert_eq!(pres, [4, 2]);
    assert_eq!(part, vec![100, 101, 102, 103, 100, 101, 102, 103]);

    // Through the work image, flipped left to right.
    let h = Value::Int(sensor);
    call(&mut w, "simVision.sensorImgToWorkImg", std::slice::from_ref(&h)).unwrap();
    call(&mut w, "simVision.horizontalFlipWorkImg", std::slice::from_ref(&h)).unwrap();
    call(&mut w, "simVision.workImgToSensorImg", &[h.clone(), Value::Bool(false)]).unwrap();
    assert!(
        w.vision.image(sensor).unwrap().work_image().is_some(),
        "kept: removeBuffer = false"
    );
    let (img, res) = rgb(&mut w, sensor);
    assert_eq!(pixel(&img, res, 7, 3), [248, 248, 248]);
    call(&mut w, "simVision.workImgToSensorImg", std::slice::from_ref(&h)).unwrap();
    let err = call(
        &mut w,
        "simVision.edgeDetectionOnWorkImg",
        &[h.clone(), Value::Float(0.2)],
    )
    .unwrap_err();
    assert!(
        err.contains("no work image") && err.contains("simVision.edgeDetectionOnWorkImg"),
        "{err}"
    );

    // Depth as a work image, and a uniform one.
    call(&mut w, "simVision.sensorDepthMapToWorkImg", std::slice::from_ref(&h)).unwrap();
    call(
        &mut w,
        "simVision.uniformImgToWorkImg",
        &[h.clone(), Value::floats(&[1.0, 0.5, 0.0])],
    )
    .unwrap();
    call(&mut w, "simVision.workImgToSensorImg", std::slice::from_ref(&h)).unwrap();
    let (img, res) = rgb(&mut w, sensor);
    assert_eq!(pixel(&img, res, 200, 200), [255, 128, 0]);
}

#[test]
fn portions_are_the_same_pixels_as_the_whole_image() {
    let (mut w, sensor) = scene_with_obstacle();
    let h = Value::Int(sensor);
    // Around the obstacle's edge, so the portion holds different pixels.
    let (x0, y0, pw, ph) = (90usize, 100usize, 7usize, 5usize);
    let pos = Value::floats(&[x0 as f64, y0 as f64]);
    let size = Value::floats(&[pw as f64, ph as f64]);
    let (full, res) = rgb(&mut w, sensor);
    let (full_depth, _) = depth_floats(&call(&mut w, "sim.getVisionSensorDepth", std::slice::from_ref(&h)).unwrap());
    let portion = |opts: i64, cutoff: f64, w: &mut Sim| {
        let args = [
            h.clone(),
            Value::Int(opts),
            Value::Float(cutoff),
            pos.clone(),
            size.clone(),
        ];
        image(&call(w, "sim.getVisionSensorImg", &args).unwrap())
    };
    let (part, pres) = portion(0, 0.0, &mut w);
    let (grey, _) = portion(1, 0.0, &mut w);
    let (rgba, _) = portion(0, 0.5, &mut w);
    let depth_args = [h.clone(), Value::Int(0), pos.clone(), size.clone()];
    let (depth, dres) = depth_floats(&call(&mut w, "sim.getVisionSensorDepth", &depth_args).unwrap());
    assert_eq!((pres, dres), ([pw, ph], [pw, ph]));
    let mut distinct = std::collections::BTreeSet::new();
    for y in 0..ph {
        for x in 0..pw {
            let (i, whole) = (y * pw + x, (y0 + y) * res[0] + x0 + x);
            let px = pixel(&full, res, x0 + x, y0 + y);
            distinct.insert(px);
            assert_eq!(part[3 * i..3 * i + 3], px, "RGB ({x}, {y})");
            let mean = (px.iter().map(|&c| u16::from(c)).sum::<u16>() + 1) / 3;
            assert_eq!(u16::from(grey[i]), mean, "grey ({x}, {y})");
            assert_eq!(rgba[4 * i..4 * i + 3], px, "RGBA ({x}, {y})");
            let alpha = if f64::from(full_depth[whole]) < 0.5 { 255 } else { 0 };
            assert_eq!(rgba[4 * i + 3], alpha, "alpha ({x}, {y})");
            assert_eq!(depth[i], full_depth[whole], "depth ({x}, {y})");
        }
    }
    assert!(distinct.len() > 1, "the portion shows an edge");

    // Writing a portion changes those pixels and no others.
    let block: Vec<u8> = (0..3 * pw * ph).map(|i| (i * 7 % 256) as u8).collect();
    call(
        &mut w,
        "sim.setVisionSensorImg",
        &[
            h.clone(),
            Value::Bytes(block.clone()),
            Value::Int(0),
            pos.clone(),
            size.clone(),
        ],
    )
    .unwrap();
    let (after, _) = rgb(&mut w, sensor);
    for y in 0..res[1] {
        for x in 0..res[0] {
            let inside = (x0..x0 + pw).contains(&x) && (y0..y0 + ph).contains(&y);
            let want = if inside {
                let i = 3 * ((y - y0) * pw + x - x0);
                [block[i], block[i + 1], block[i + 2]]
            } else {
                pixel(&full, res, x, y)
            };
            assert_eq!(pixel(&after, res, x, y), want, "({x}, {y}) after writing");
        }
    }
}

#[test]
fn rgba_cut_off_and_options() {
    let (mut w, sensor) = scene_with_obstacle();
    let reply = call(
        &mut w,
        "sim.getVisionSensorImg",
        &[Value::Int(sensor), Value::Int(0), Value::Float(0.5)],
    )
    .unwrap();
    let (img, res) = image(&reply);
    assert_eq!(img.len(), 4 * res[0] * res[1]);
    let alpha = |x: usize, y: usize| img[4 * (y * res[0] + x) + 3];
    assert_eq!(alpha(128, 128), 255, "obstacle nearer than the cut-off");
    assert_eq!(alpha(0, 255), 0, "background beyond it");
    let (grey, _) = image(&call(&mut w, "sim.getVisionSensorImg", &[Value::Int(sensor), Value::Int(1)]).unwrap());
    assert_eq!(grey.len(), 256 * 256);
}

/// Options bit 1, as CoppeliaSim documents it for `sim.setVisionSensorImg` (the same
/// layout both ways): one more byte per pixel, alpha, after RGB or after the grey byte.
/// Without a cut-off the sensor's image is opaque; with one, alpha follows the depth.
#[test]
fn alpha_option_adds_a_byte_per_pixel_both_ways() {
    let (mut w, sensor) = scene_with_obstacle();
    let get = |w: &mut Sim, options: i64, cutoff: f64| {
        image(
            &call(
                w,
                "sim.getVisionSensorImg",
                &[Value::Int(sensor), Value::Int(options), Value::Float(cutoff)],
            )
            .unwrap(),
        )
        .0
    };
    let rgb = get(&mut w, 0, 0.0);
    let rgba = get(&mut w, 2, 0.0);
    assert_eq!(rgba.len(), 4 * 256 * 256);
    for (px, c) in rgba.chunks_exact(4).zip(rgb.chunks_exact(3)) {
        assert_eq!(&px[..3], c);
        assert_eq!(px[3], 255, "opaque without a cut-off");
    }
    let grey = get(&mut w, 1, 0.0);
    let grey_alpha = get(&mut w, 3, 0.5);
    assert_eq!(grey_alpha.len(), 2 * 256 * 256);
    let at = |x: usize, y: usize| 2 * (y * 256 + x);
    assert_eq!(grey_alpha[at(128, 128)], grey[128 * 256 + 128]);
    assert_eq!(grey_alpha[at(128, 128) + 1], 255, "obstacle nearer than the cut-off");
    assert_eq!(grey_alpha[at(0, 255) + 1], 0, "background beyond it");
    // Bit 1 and a cut-off together are the same RGBA image as the cut-off alone.
    assert_eq!(get(&mut w, 2, 0.5), get(&mut w, 0, 0.5));

    // Written back with the alpha byte (which the opaque image drops), the same pixels.
    let mut inverted = rgba.clone();
    for px in inverted.chunks_exact_mut(4) {
        for c in &mut px[..3] {
            *c = 255 - *c;
        }
    }
    call(
        &mut w,
        "sim.setVisionSensorImg",
        &[Value::Int(sensor), Value::Bytes(inverted.clone()), Value::Int(2)],
    )
    .unwrap();
    let back = get(&mut w, 2, 0.0);
    assert_eq!(back, inverted);
    let short = call(
        &mut w,
        "sim.setVisionSensorImg",
        &[Value::Int(sensor), Value::Bytes(rgb), Value::Int(2)],
    )
    .unwrap_err();
    assert!(short.contains("4 per pixel"), "{short}");
}

#[test]
fn bad_arguments_name_the_function() {
    let (mut w, sensor) = scene_with_obstacle();
    let floor = find(&w, "/Floor", 0);
    let cases: Vec<(&str, Vec<Value>, &str)> = vec![
        ("sim.getVisionSensorImg", vec![Value::Int(floor)], "not a vision sensor"),
        ("sim.getVisionSensorDepth", vec![Value::Int(9999)], "does not exist"),
        ("sim.handleVisionSensor", vec![Value::Str("cam".into())], "argument 1"),
        ("sim.getVisionSensorRes", vec![Value::Int(floor)], "not a vision sensor"),
        (
            "sim.getVisionSensorImg",
            vec![
                Value::Int(sensor),
                Value::Int(0),
                Value::Float(0.0),
                Value::floats(&[256.0, 0.0]),
            ],
            "exceeds the 256x256 image",
        ),
        (
            "sim.getVisionSensorDepth",
            vec![
                Value::Int(sensor),
                Value::Int(0),
                Value::floats(&[10.0, 10.0]),
                Value::floats(&[0.0, 250.0]),
            ],
            "exceeds",
        ),
        (
            "sim.getVisionSensorImg",
            vec![
                Value::Int(sensor),
                Value::Int(0),
                Value::Float(0.0),
                Value::floats(&[-1.0, 0.0]),
            ],
            "non-negative integers",
        ),
        (
            "sim.getVisionSensorImg",
            vec![Value::Int(sensor), Value::Int(0), Value::Float(f64::NAN)],
            "rgbaCutOff",
        ),
        (
            "sim.setVisionSensorImg",
            vec![Value::Int(sensor), Value::Bytes(vec![0; 10])],
            "expected 196608 bytes",
        ),
        ("sim.setVisionSensorImg", vec![Value::Int(sensor)], "argument 2"),
        (
            "simVision.edgeDetectionOnWorkImg",
            vec![Value::Int(sensor), Value::Str("x".into())],
            "argument 2",
        ),
        ("simVision.sensorImgToWorkImg", vec![Value::Int(-4)], "handle_self"),
        (
            "simVision.workImgToSensorImg",
            vec![Value::Int(sensor)],
            "no work image",
        ),
        (
            "simVision.uniformImgToWorkImg",
            vec![Value::Int(sensor), Value::floats(&[1.0])],
            "argument 2",
        ),
    ];
    for (name, args, needle) in cases {
        let err = call(&mut w, name, &args).expect_err(name);
        assert!(
            err.contains(needle) && err.contains(&format!("(in function '{name}')")),
            "{name}: {err}"
        );
    }
    assert_eq!(w.vision.render_count(sensor), 0, "failed calls render nothing");
}

/// A rough figure in the test profile; `cargo bench -p gantry-sim-core --bench vision`
/// measures release builds.
#[test]
fn render_time_in_the_test_profile() {
    let (mut w, sensor) = scene_with_obstacle();
    vision::handle_vision_sensor(&w.world, &mut w.vision, sensor).unwrap();
    let n = 10;
    let t = Instant::now();
    for _ in 0..n {
        vision::handle_vision_sensor(&w.world, &mut w.vision, sensor).unwrap();
    }
    let ms = t.elapsed().as_secs_f64() * 1e3 / f64::from(n);
    eprintln!("vision: 256x256 BubbleRob render {ms:.2} ms (test profile)");
}

/// A 256 x 256 black sensor image with a red 20 x 20 square at columns 30..50, rows
/// 40..60 and a green 10 x 30 rectangle at columns 150..160, rows 100..130, loaded as
/// the work image.
fn two_squares() -> (Sim, Handle) {
    let mut w = bubble_rob();
    let sensor = find(&w, "/bubbleRob/visionSensor", 0);
    let mut img = vec![0u8; 256 * 256 * 3];
    let mut fill = |xs: std::ops::Range<usize>, ys: std::ops::Range<usize>, c: [u8; 3]| {
        for y in ys {
            for x in xs.clone() {
                let i = 3 * (y * 256 + x);
                img[i..i + 3].copy_from_slice(&c);
            }
        }
    };
    fill(30..50, 40..60, [255, 0, 0]);
    fill(150..160, 100..130, [0, 255, 0]);
    call(
        &mut w,
        "sim.setVisionSensorImg",
        &[Value::Int(sensor), Value::Bytes(img)],
    )
    .unwrap();
    call(&mut w, "simVision.sensorImgToWorkImg", &[Value::Int(sensor)]).unwrap();
    (w, sensor)
}

/// The work image written back to the sensor, as bytes.
fn work_bytes(w: &mut Sim, sensor: Handle) -> (Vec<u8>, [usize; 2]) {
    call(
        w,
        "simVision.workImgToSensorImg",
        &[Value::Int(sensor), Value::Bool(false)],
    )
    .unwrap();
    rgb(w, sensor)
}

/// `blobDetectionOnWorkImg`'s reply: trigger, then the packet's floats.
fn blobs(w: &mut Sim, sensor: Handle, args: &[Value]) -> (bool, Vec<f64>) {
    let mut all = vec![Value::Int(sensor)];
    all.extend_from_slice(args);
    let reply = call(w, "simVision.blobDetectionOnWorkImg", &all).unwrap();
    let Some(Value::Bool(trigger)) = reply.first() else {
        panic!("expected a trigger, got {reply:?}");
    };
    let Some(Value::Bytes(packet)) = reply.get(1) else {
        panic!("expected a packed packet, got {reply:?}");
    };
    (*trigger, vision::unpack_floats(packet))
}

fn close(actual: f64, expected: f64, what: &str) {
    assert!((actual - expected).abs() < 1e-4, "{what}: {actual} != {expected}");
}

#[test]
fn blob_detection_finds_two_squares_where_they_are() {
    let (mut w, sensor) = two_squares();
    let (trigger, p) = blobs(
        &mut w,
        sensor,
        &[Value::Float(0.2), Value::Float(0.0), Value::Bool(false)],
    );
    assert!(!trigger);
    assert_eq!(p.len(), 2 + 2 * 6, "{p:?}");
    assert_eq!((p[0], p[1]), (2.0, 6.0));
    let n = 256.0;
    // First pixel first: the red square (row 40) before the green one (row 100).
    let red = &p[2..8];
    close(red[0], 400.0 / (n * n), "red size");
    close(red[1], 0.0, "red orientation");
    close(red[2], 40.0 / n, "red x");
    close(red[3], 50.0 / n, "red y");
    close(red[4], 20.0 / n, "red width");
    close(red[5], 20.0 / n, "red height");
    let green = &p[8..14];
    close(green[0], 300.0 / (n * n), "green size");
    close(green[1], 0.0, "green orientation");
    close(green[2], 155.0 / n, "green x");
    close(green[3], 115.0 / n, "green y");
    close(green[4], 10.0 / n, "green width");
    close(green[5], 30.0 / n, "green height");

    // The image is untouched without modifyWorkImage or overlay.
    let (img, res) = work_bytes(&mut w, sensor);
    assert_eq!(pixel(&img, res, 35, 45), [255, 0, 0]);
    assert_eq!(pixel(&img, res, 155, 115), [0, 255, 0]);

    // The packet unpacks with sim.unpackFloatTable, as scripts read it.
    let (mut w2, sensor2) = two_squares();
    let reply = call(
        &mut w2,
        "simVision.blobDetectionOnWorkImg",
        &[
            Value::Int(sensor2),
            Value::Float(0.2),
            Value::Float(0.0),
            Value::Bool(false),
        ],
    )
    .unwrap();
    let unpacked = call(&mut w2, "sim.unpackFloatTable", &reply[1..2]).unwrap();
    let Some(Value::Array(values)) = unpacked.first() else {
        panic!("expected a table, got {unpacked:?}");
    };
    assert_eq!(values.first().and_then(Value::as_f64), Some(2.0));
}

#[test]
fn small_blobs_are_dropped_and_blacked_out() {
    let (mut w, sensor) = two_squares();
    // Red covers 400 / 65536 = 0.0061 of the image, green 0.0046.
    let (_, p) = blobs(
        &mut w,
        sensor,
        &[Value::Float(0.2), Value::Float(0.005), Value::Bool(false)],
    );
    assert_eq!(p[0], 1.0);
    close(p[4], 40.0 / 256.0, "the red square is left");
    let (img, res) = work_bytes(&mut w, sensor);
    assert_eq!(
        pixel(&img, res, 155, 115),
        [0, 0, 0],
        "simVision blacks out small blobs"
    );
    assert_eq!(pixel(&img, res, 35, 45), [255, 0, 0]);
    // A threshold above both squares' intensity (1/3) finds nothing.
    let (mut w, sensor) = two_squares();
    let (_, p) = blobs(
        &mut w,
        sensor,
        &[Value::Float(0.5), Value::Float(0.0), Value::Bool(false)],
    );
    assert_eq!(p, vec![0.0, 6.0]);
}

#[test]
fn blob_detection_recolours_and_draws_overlays() {
    let (mut w, sensor) = two_squares();
    blobs(
        &mut w,
        sensor,
        &[Value::Float(0.2), Value::Float(0.0), Value::Bool(true)],
    );
    let (img, res) = work_bytes(&mut w, sensor);
    // First blob red, second green, both at 0.8.
    assert_eq!(pixel(&img, res, 35, 45), [204, 0, 0]);
    assert_eq!(pixel(&img, res, 155, 115), [0, 204, 0]);
    assert_eq!(pixel(&img, res, 100, 100), [0, 0, 0], "the background stays black");

    let (mut w, sensor) = two_squares();
    blobs(
        &mut w,
        sensor,
        &[
            Value::Float(0.2),
            Value::Float(0.0),
            Value::Bool(false),
            Value::floats(&[0.0, 0.0, 1.0]),
        ],
    );
    let (img, res) = work_bytes(&mut w, sensor);
    // The outline runs along the squares' outer pixels; the inside is untouched.
    for (x, y) in [
        (30, 40),
        (49, 40),
        (49, 59),
        (30, 59),
        (40, 40),
        (30, 50),
        (150, 100),
        (159, 129),
    ] {
        assert_eq!(pixel(&img, res, x, y), [0, 0, 255], "outline at {x}, {y}");
    }
    assert_eq!(pixel(&img, res, 40, 50), [255, 0, 0]);
    assert_eq!(pixel(&img, res, 29, 50), [0, 0, 0], "nothing outside");
}

#[test]
fn selective_colour_keeps_or_removes_the_matching_pixels() {
    let red = (35, 45);
    let green = (155, 115);
    let run = |args: &[Value]| {
        let (mut w, sensor) = two_squares();
        let mut all = vec![Value::Int(sensor)];
        all.extend_from_slice(args);
        let reply = call(&mut w, "simVision.selectiveColorOnWorkImg", &all).unwrap();
        assert!(reply.is_empty());
        let (img, res) = work_bytes(&mut w, sensor);
        (pixel(&img, res, red.0, red.1), pixel(&img, res, green.0, green.1))
    };
    let red_rgb = [
        Value::floats(&[1.0, 0.0, 0.0]),
        Value::floats(&[0.1, 0.1, 0.1]),
        Value::Bool(true),
    ];
    // keep: only red is left.
    let mut args = red_rgb.to_vec();
    args.extend([Value::Bool(true), Value::Bool(false)]);
    assert_eq!(run(&args), ([255, 0, 0], [0, 0, 0]));
    // not keep: red is removed, the rest stays.
    let mut args = red_rgb.to_vec();
    args.extend([Value::Bool(false), Value::Bool(false)]);
    assert_eq!(run(&args), ([0, 0, 0], [0, 255, 0]));
    // In HSL: green has hue 1/3, saturation 1, lightness 0.5.
    let args = [
        Value::floats(&[1.0 / 3.0, 1.0, 0.5]),
        Value::floats(&[0.05, 0.1, 0.1]),
        Value::Bool(false),
        Value::Bool(true),
        Value::Bool(false),
    ];
    assert_eq!(run(&args), ([0, 0, 0], [0, 255, 0]));
    // A tolerance spanning 0..1 in every component matches every pixel.
    let args = [
        Value::floats(&[0.5, 0.5, 0.5]),
        Value::floats(&[0.5, 0.5, 0.5]),
        Value::Bool(true),
        Value::Bool(true),
        Value::Bool(false),
    ];
    assert_eq!(
        run(&args),
        ([255, 0, 0], [0, 255, 0]),
        "a tolerance covering everything keeps all"
    );
}

#[test]
fn blob_and_colour_arguments_are_checked() {
    let (mut w, sensor) = two_squares();
    let h = Value::Int(sensor);
    // (`removedPartToBuffer1` is served: tests/vision_buffers.rs.)
    let e = call(
        &mut w,
        "simVision.selectiveColorOnWorkImg",
        &[h.clone(), Value::floats(&[1.0, 0.0]), Value::floats(&[0.1, 0.1, 0.1])],
    )
    .unwrap_err();
    assert!(e.contains("argument 2"), "{e}");
    let e = call(
        &mut w,
        "simVision.blobDetectionOnWorkImg",
        &[
            h.clone(),
            Value::Float(0.2),
            Value::Float(0.0),
            Value::Bool(false),
            Value::Int(1),
        ],
    )
    .unwrap_err();
    assert!(e.contains("argument 5"), "{e}");
    call(&mut w, "simVision.workImgToSensorImg", std::slice::from_ref(&h)).unwrap();
    let e = call(
        &mut w,
        "simVision.blobDetectionOnWorkImg",
        &[h, Value::Float(0.2), Value::Float(0.0), Value::Bool(false)],
    )
    .unwrap_err();
    assert!(
        e.contains("no work image") && e.ends_with("(in function 'simVision.blobDetectionOnWorkImg')"),
        "{e}"
    );
}
