//! `cargo bench -p gantry-sim-core --bench scan`: milliseconds per laser scan in the
//! bundled `assets/scenes/scanners.toml`, through the batch ray cast (`sim.castRays`)
//! and through depth sensors read as CoppeliaSim's scanner models read them (`simVision`).
//!
//! Prints one Markdown table. Figures are medians (and minima) over a few hundred
//! scans, after a warm-up scan; the `sim.castRays` rows go through the registry as a
//! script's or client's call does, arguments and results converted included.

mod timing;

use std::path::Path;

use gantry_sim_core::api::{self, CallContext};
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene};
use gantry_sim_core::sensor::{self, RayCastParams};
use gantry_sim_core::{Handle, Sim, Value};
use timing::median_ms;

fn scanners() -> Sim {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/scenes/scanners.toml");
    let model = load_scene(&DiskFiles, &path, &LoadOptions::default()).expect("scene loads");
    Sim::new(&model)
}

fn call(w: &mut Sim, name: &str, args: &[Value]) -> Vec<Value> {
    api::call(w, &CallContext::default(), name, args).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Unit directions: `azimuths` around the frame's Z axis times `elevations` evenly over
/// `spread` rad, as x, y, z.
fn fan(azimuths: usize, elevations: usize, spread: f64) -> Vec<[f64; 3]> {
    let mut out = Vec::with_capacity(azimuths * elevations);
    for i in 0..azimuths {
        let az = std::f64::consts::TAU * i as f64 / azimuths as f64;
        for j in 0..elevations {
            let el = if elevations > 1 {
                -spread / 2.0 + spread * j as f64 / (elevations - 1) as f64
            } else {
                0.0
            };
            out.push([az.cos() * el.cos(), az.sin() * el.cos(), el.sin()]);
        }
    }
    out
}

fn cast_rays_row(w: &mut Sim, label: &str, frame: Handle, dirs: &[[f64; 3]], max: f64) {
    let table = Value::Array(dirs.iter().flatten().map(|&v| Value::Float(v)).collect());
    let args = [Value::Int(frame), table, Value::Float(max), Value::Int(frame)];
    let tables = median_ms(300, 4, || {
        call(w, "sim.castRays", &args);
    });
    // Packed in and out, as a script passes sim.packFloatTable and reads
    // sim.unpackFloatTable.
    let packed: Vec<u8> = dirs.iter().flatten().flat_map(|&v| (v as f32).to_le_bytes()).collect();
    let args = [
        Value::Int(frame),
        Value::Bytes(packed),
        Value::Float(max),
        Value::Int(frame),
        Value::Int(2),
    ];
    let packed = median_ms(300, 4, || {
        call(w, "sim.castRays", &args);
    });
    let params = RayCastParams {
        max_distance: max,
        ignored_tree: Some(frame),
        detectable_only: false,
    };
    let mut hits = Vec::new();
    let direct = median_ms(300, 4, || {
        sensor::cast_rays(&mut w.world, frame, dirs, &params, &mut hits).expect("cast");
    });
    let n = hits.iter().flatten().count();
    println!("| {label}: sim.castRays, tables ({n} hits) | {tables} |");
    println!("| {label}: sim.castRays, packed (options 2) | {packed} |");
    println!("| {label}: sensor::cast_rays (Rust, no conversions) | {direct} |");
}

/// One scan of a depth-sensor scanner as its filters do it: per sensor, render, depth
/// map to the work image, points.
fn simvision_row(w: &mut Sim, label: &str, sensors: &[Handle], function: &str, args: &[Value]) {
    let ms = median_ms(100, 4, || {
        for &s in sensors {
            call(w, "sim.handleVisionSensor", &[Value::Int(s)]);
            call(w, "simVision.sensorDepthMapToWorkImg", &[Value::Int(s)]);
            let mut a = vec![Value::Int(s)];
            a.extend_from_slice(args);
            call(w, function, &a);
        }
    });
    // The points alone, from the work images left by the last scan.
    let points = median_ms(300, 4, || {
        for &s in sensors {
            let mut a = vec![Value::Int(s)];
            a.extend_from_slice(args);
            call(w, function, &a);
        }
    });
    println!("| {label}: render, work image, points | {ms} |");
    println!("| {label}: points only (coordinatesFromWorkImg etc.) | {points} |");
}

fn main() {
    let mut w = scanners();
    let find = |w: &Sim, p: &str| w.world.find(p, None, 0).expect(p);
    let (hokuyo, velodyne) = (find(&w, "/hokuyo"), find(&w, "/velodyne"));

    println!("| laser scan, scanners.toml | ms per scan, median (min) |");
    println!("|---|---|");
    cast_rays_row(&mut w, "2-D, 360 rays, 5 m", hokuyo, &fan(360, 1, 0.0), 5.0);
    cast_rays_row(
        &mut w,
        "3-D, 16 x 1,800 rays over 30 deg, 10 m",
        velodyne,
        &fan(1800, 16, 30f64.to_radians()),
        10.0,
    );

    let h_sensors = [find(&w, "/hokuyo/sensor1"), find(&w, "/hokuyo/sensor2")];
    simvision_row(
        &mut w,
        "Hokuyo-style, 2 sensors of 342 x 1, coordinatesFromWorkImg",
        &h_sensors,
        "simVision.coordinatesFromWorkImg",
        &[Value::Array(vec![Value::Int(342), Value::Int(1)]), Value::Bool(false)],
    );
    let v_sensors = [1, 2, 3, 4].map(|i| find(&w, &format!("/velodyne/sensor{i}")));
    simvision_row(
        &mut w,
        "Velodyne-style, 4 sensors of 512 x 200, velodyneDataFromWorkImg 16 x 1,800",
        &v_sensors,
        "simVision.velodyneDataFromWorkImg",
        &[
            Value::Array(vec![Value::Int(450), Value::Int(16)]),
            Value::Float(30f64.to_radians()),
        ],
    );
}
