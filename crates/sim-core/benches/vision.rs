//! `cargo bench -p gantry-sim-core --bench vision`: milliseconds per render of
//! BubbleRob's 256 x 256 vision sensor (the CPU rasteriser of `gantry_sim_core::vision`)
//! and of the tutorial's `sysCall_vision` edge-detection flow.
//!
//! Prints one Markdown table. Figures are medians over a few hundred frames on this
//! machine, after a warm-up frame that fills the tessellation cache.

use std::path::Path;
use std::time::Instant;

use gantry_sim_core::api::{self, CallContext};
use gantry_sim_core::math::Pose;
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene};
use gantry_sim_core::{Handle, Sim, Value, vision};

fn bubble_rob() -> (Sim, Handle) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/scenes/bubble_rob.toml");
    let model = load_scene(&DiskFiles, &path, &LoadOptions::default()).expect("scene loads");
    let w = Sim::new(&model);
    let sensor = w.world.find("/bubbleRob/visionSensor", None, 0).expect("sensor");
    (w, sensor)
}

/// Median and minimum milliseconds of `f` over `n` runs, as "median (min)": on a busy
/// machine the minimum is the steadier figure for comparing two versions.
fn median_ms(n: usize, mut f: impl FnMut()) -> String {
    let mut times: Vec<f64> = (0..n)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    format!("{:.3} ({:.3})", times[n / 2], times[0])
}

fn main() {
    println!("| vision, 256 x 256 | ms per frame, median (min) |");
    println!("|---|---|");

    // The scene as loaded: floor, walls and obstacle 0 within the 1 m far plane.
    let (mut w, sensor) = bubble_rob();
    vision::handle_vision_sensor(&w.world, &mut w.vision, sensor).expect("render");
    let ms = median_ms(300, || {
        vision::handle_vision_sensor(&w.world, &mut w.vision, sensor).expect("render")
    });
    println!("| render, scene as loaded | {ms} |");

    // An obstacle filling the middle of the view (more pixels drawn twice).
    let o0 = w.world.find("/obstacle", None, 0).expect("obstacle");
    w.world
        .set_world_pose(o0, Pose::translation(0.35, 0.0, 0.1))
        .expect("pose");
    let ms = median_ms(300, || {
        vision::handle_vision_sensor(&w.world, &mut w.vision, sensor).expect("render")
    });
    println!("| render, obstacle 0.2 m ahead | {ms} |");

    // The tutorial's sysCall_vision on top of a render.
    let ctx = CallContext {
        script_object: Some(sensor),
        source: "bench",
    };
    let h = [Value::Int(sensor)];
    let edge = [Value::Int(sensor), Value::Float(0.2)];
    let ms = median_ms(300, || {
        vision::handle_vision_sensor(&w.world, &mut w.vision, sensor).expect("render");
        api::call(&mut w, &ctx, "simVision.sensorImgToWorkImg", &h).expect("to work");
        api::call(&mut w, &ctx, "simVision.edgeDetectionOnWorkImg", &edge).expect("edges");
        api::call(&mut w, &ctx, "simVision.workImgToSensorImg", &h).expect("to sensor");
    });
    println!("| render + edge detection (sysCall_vision) | {ms} |");

    // What a remote client pays to fetch the image.
    let ms = median_ms(300, || {
        api::call(&mut w, &ctx, "sim.getVisionSensorImg", &h).expect("image");
    });
    println!("| sim.getVisionSensorImg (no render) | {ms} |");
}
