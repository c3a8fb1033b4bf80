//! simVision's buffers 1 and 2 (`simVision.workImgToBuffer1`, `buffer1ToWorkImg`,
//! `swapBuffers`, the arithmetic with buffer 1), `selectiveColorOnWorkImg`'s
//! `removedPartToBuffer1`, and the scanner functions' `returnRgb`, which reads point
//! colours from buffer 1, as CoppeliaSim's point-cloud scripts do.

use crate::util;

use gantry_sim_core::{Handle, Sim, Value};
use util::{err, find, image_reply, ok};

/// A 64 x 64 perspective sensor 1 m above a grey floor, looking straight down at a red
/// cube.
const SCENE: &str = r#"
[floor]
size = [3, 3]
color = [0.5, 0.5, 0.5]

[[object]]
name = "cam"
kind = "vision_sensor"
position = [0, 0, 1]
orientation_deg = [180, 0, 0]
resolution = [64, 64]
fov_deg = 60
near = 0.01
far = 2.0

[[object]]
name = "cube"
kind = "shape"
shape = "box"
size = [0.3, 0.3, 0.2]
position = [0.05, 0, 0.1]
color = [1, 0, 0]
"#;

fn scene() -> (Sim, Handle) {
    let w = util::text_scene("buffers.toml", SCENE);
    let cam = find(&w, "/cam");
    (w, cam)
}

/// `simVision.<name>(cam, args...)`.
fn vision(w: &mut Sim, name: &str, cam: Handle, args: &[Value]) -> Vec<Value> {
    let mut all = vec![Value::Int(cam)];
    all.extend_from_slice(args);
    ok(w, &format!("simVision.{name}"), &all)
}

fn work(w: &Sim, cam: Handle) -> Vec<f32> {
    w.vision.image(cam).and_then(|s| s.work_image()).expect("a work image")
}

fn colour(c: [f64; 3]) -> Value {
    Value::Array(c.iter().map(|&v| Value::Float(v)).collect())
}

fn uniform(w: &mut Sim, cam: Handle, c: [f64; 3]) {
    vision(w, "uniformImgToWorkImg", cam, &[colour(c)]);
}

/// Every pixel of `work` is `c` (within f32 rounding).
fn assert_uniform(work: &[f32], c: [f32; 3], what: &str) {
    for (i, px) in work.chunks_exact(3).enumerate() {
        for k in 0..3 {
            assert!((px[k] - c[k]).abs() < 1e-6, "{what}: pixel {i} is {px:?}, not {c:?}");
        }
    }
}

/// The camera image as the work image (rendered first).
fn camera_to_work(w: &mut Sim, cam: Handle) -> Vec<f32> {
    ok(w, "sim.handleVisionSensor", &[Value::Int(cam)]);
    vision(w, "sensorImgToWorkImg", cam, &[]);
    work(w, cam)
}

/// `selectiveColorOnWorkImg` keeping the cube's red (the floor turns black), the removed
/// part to buffer 1 or not.
fn keep_red(w: &mut Sim, cam: Handle, to_buffer1: bool) {
    let args = [
        colour([1.0, 0.0, 0.0]),
        colour([0.1, 0.1, 0.1]),
        Value::Bool(true),
        Value::Bool(true),
        Value::Bool(to_buffer1),
    ];
    vision(w, "selectiveColorOnWorkImg", cam, &args);
}

#[test]
fn buffer_1_keeps_the_camera_image_while_the_work_image_is_filtered() {
    let (mut w, cam) = scene();
    let original = camera_to_work(&mut w, cam);
    vision(&mut w, "workImgToBuffer1", cam, &[]);
    keep_red(&mut w, cam, false);
    let filtered = work(&w, cam);
    assert_ne!(filtered, original);
    let red = filtered.chunks_exact(3).filter(|p| p[0] > 0.9).count();
    assert!(red > 100 && red < 64 * 64 - 100, "{red} red pixels");
    // The camera image back from buffer 1, value for value.
    vision(&mut w, "buffer1ToWorkImg", cam, &[]);
    assert_eq!(work(&w, cam), original);
}

#[test]
fn removed_parts_go_to_buffer_1() {
    let (mut w, cam) = scene();
    let original = camera_to_work(&mut w, cam);
    keep_red(&mut w, cam, true);
    let kept = work(&w, cam);
    vision(&mut w, "buffer1ToWorkImg", cam, &[]);
    let removed = work(&w, cam);
    // Each pixel is in exactly one of the two, and the two add up to the original.
    for ((o, k), r) in original
        .chunks_exact(3)
        .zip(kept.chunks_exact(3))
        .zip(removed.chunks_exact(3))
    {
        let black = |p: &[f32]| p.iter().all(|&v| v == 0.0);
        assert!(black(k) || black(r), "kept {k:?} and removed {r:?}");
        let sum: Vec<f32> = k.iter().zip(r).map(|(a, b)| a + b).collect();
        assert_eq!(sum, o);
    }
    assert!(
        removed.chunks_exact(3).any(|p| p[1] > 0.1),
        "the grey floor was removed"
    );
}

#[test]
fn arithmetic_with_buffer_1_clamps_as_the_plugin_does() {
    let (mut w, cam) = scene();
    uniform(&mut w, cam, [0.6, 0.2, 0.5]);
    vision(&mut w, "workImgToBuffer1", cam, &[]);
    uniform(&mut w, cam, [0.7, 0.1, 0.0]);
    vision(&mut w, "addBuffer1ToWorkImg", cam, &[]);
    assert_uniform(&work(&w, cam), [1.0, 0.3, 0.5], "work + buffer 1, at most 1");
    vision(&mut w, "subtractBuffer1FromWorkImg", cam, &[]);
    assert_uniform(&work(&w, cam), [0.4, 0.1, 0.0], "work - buffer 1, at least 0");
    vision(&mut w, "multiplyWorkImgWithBuffer1", cam, &[]);
    assert_uniform(&work(&w, cam), [0.24, 0.02, 0.0], "work * buffer 1");
    vision(&mut w, "addWorkImgToBuffer1", cam, &[]);
    vision(&mut w, "subtractWorkImgFromBuffer1", cam, &[]);
    vision(&mut w, "subtractWorkImgFromBuffer1", cam, &[]);
    vision(&mut w, "buffer1ToWorkImg", cam, &[]);
    assert_uniform(&work(&w, cam), [0.36, 0.18, 0.5], "buffer 1 + work - work - work");
}

#[test]
fn buffers_copy_and_swap_and_start_black() {
    let (mut w, cam) = scene();
    uniform(&mut w, cam, [0.1, 0.2, 0.3]);
    // Never written: black.
    vision(&mut w, "buffer2ToWorkImg", cam, &[]);
    assert_uniform(&work(&w, cam), [0.0; 3], "a buffer never written");
    uniform(&mut w, cam, [0.1, 0.2, 0.3]);
    vision(&mut w, "workImgToBuffer1", cam, &[]);
    uniform(&mut w, cam, [0.4, 0.5, 0.6]);
    vision(&mut w, "workImgToBuffer2", cam, &[]);
    vision(&mut w, "swapBuffers", cam, &[]);
    vision(&mut w, "buffer1ToWorkImg", cam, &[]);
    assert_uniform(&work(&w, cam), [0.4, 0.5, 0.6], "buffer 1 after the swap");
    vision(&mut w, "buffer2ToWorkImg", cam, &[]);
    assert_uniform(&work(&w, cam), [0.1, 0.2, 0.3], "buffer 2 after the swap");
    uniform(&mut w, cam, [0.7, 0.8, 0.9]);
    vision(&mut w, "swapWorkImgWithBuffer1", cam, &[]);
    assert_uniform(
        &work(&w, cam),
        [0.4, 0.5, 0.6],
        "the work image after swapping with buffer 1",
    );
    vision(&mut w, "buffer1ToWorkImg", cam, &[]);
    assert_uniform(
        &work(&w, cam),
        [0.7, 0.8, 0.9],
        "buffer 1 after swapping with the work image",
    );
}

#[test]
fn buffers_need_a_work_image() {
    let (mut w, cam) = scene();
    let e = err(&mut w, "simVision.workImgToBuffer1", &[Value::Int(cam)]);
    assert!(e.contains("work image"), "{e}");
    let e = err(&mut w, "simVision.buffer1ToWorkImg", &[Value::Int(9999)]);
    assert!(e.contains("9999"), "{e}");
}

#[test]
fn scans_return_the_colours_of_buffer_1() {
    let (mut w, cam) = scene();
    ok(&mut w, "sim.handleVisionSensor", &[Value::Int(cam)]);
    let (rgb, [width, height]) = image_reply(&ok(&mut w, "sim.getVisionSensorImg", &[Value::Int(cam)]));
    let counts = Value::Array(vec![Value::Int(width as i64), Value::Int(height as i64)]);
    let scan = |w: &mut Sim| {
        vision(w, "sensorDepthMapToWorkImg", cam, &[]);
        vision(
            w,
            "coordinatesFromWorkImg",
            cam,
            &[counts.clone(), Value::Bool(false), Value::Bool(true)],
        )
    };
    // No buffer 1 yet: no colours, as the plugin.
    assert_eq!(scan(&mut w).len(), 2);
    // CoppeliaSim's point-cloud scripts: the colour image to buffer 1, then the depth.
    vision(&mut w, "sensorImgToWorkImg", cam, &[]);
    vision(&mut w, "workImgToBuffer1", cam, &[]);
    let reply = scan(&mut w);
    let Some(Value::Bytes(colours)) = reply.get(2) else {
        panic!("expected colours, got {reply:?}");
    };
    assert_eq!(colours.len(), 3 * width * height);
    // As many points as pixels: point (i, j) reads the pixel centre of column W-1-i
    // (points run from image right to left) and row j, and its colour is that pixel's.
    let mut red = 0;
    for j in 0..height {
        for i in 0..width {
            let point = &colours[3 * (i + j * width)..3 * (i + j * width) + 3];
            let p = 3 * ((width - 1 - i) + j * width);
            assert_eq!(point, &rgb[p..p + 3], "point ({i}, {j})");
            red += usize::from(point[0] > 200 && point[1] < 50);
        }
    }
    assert!(red > 100, "{red} red points");
    // The lidar form too.
    let reply = vision(
        &mut w,
        "velodyneDataFromWorkImg",
        cam,
        &[
            Value::Array(vec![Value::Int(16), Value::Int(4)]),
            Value::Float(0.5),
            Value::Bool(true),
        ],
    );
    let Some(Value::Bytes(colours)) = reply.get(2) else {
        panic!("expected colours, got {reply:?}");
    };
    assert_eq!(colours.len(), 3 * 16 * 4);
}
