//! `simVision.handleSpherical` on the spherical vision sensor model of PyRep's
//! `test_scene.ttt`: the panorama is assembled from the six faces, looks where they
//! look, and its depth image is the distance along each ray.

use crate::util;

use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene};
use gantry_sim_core::{Sim, Value};
use gantry_test_support::pyrep_assets;
use util::{call, find, image_reply, ok};

const FACES: [&str; 6] = ["front", "top", "back", "bottom", "left", "right"];

fn scene() -> Sim {
    let path = pyrep_assets().join("test_scene.ttt");
    Sim::new(&load_scene(&DiskFiles, &path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}")))
}

fn handles(sim: &Sim) -> (Value, Vec<Value>, Value) {
    let name = |s: &str| Value::Int(find(sim, &format!("/sphericalVisionRGBAndDepth_{s}")));
    (
        name("sensorRGB"),
        FACES.iter().map(|f| name(f)).collect(),
        name("sensorDepth"),
    )
}

fn image(sim: &mut Sim, h: &Value) -> (Vec<u8>, [usize; 2]) {
    image_reply(&ok(sim, "getVisionSensorImg", std::slice::from_ref(h)))
}

#[test]
fn the_panorama_is_the_six_faces_seen_along_each_ray() {
    let mut sim = scene();
    let (rgb, faces, depth) = handles(&sim);
    let args = [
        rgb.clone(),
        Value::Array(faces.clone()),
        Value::Float(std::f64::consts::TAU),
        Value::Float(std::f64::consts::PI),
        depth.clone(),
    ];
    assert_eq!(
        ok(&mut sim, "simVision.handleSpherical", &args),
        vec![Value::Bool(true)]
    );
    let (pano, [w, h]) = image(&mut sim, &rgb);
    assert!(pano.iter().any(|&b| b != 0), "the panorama is not black");
    // The centre of the panorama looks where the front face looks: the front face's
    // centre pixel.
    let (front, [fw, fh]) = image(&mut sim, &faces[0]);
    let centre = |img: &[u8], w: usize, h: usize| {
        let at = 3 * ((h / 2) * w + w / 2);
        img[at..at + 3].to_vec()
    };
    assert_eq!(centre(&pano, w, h), centre(&front, fw, fh));
    // Depth: grey, one value per pixel in all three channels.
    let (grey, size) = image(&mut sim, &depth);
    assert_eq!(size, [w, h]);
    assert!(grey.chunks_exact(3).all(|p| p[0] == p[1] && p[1] == p[2]));
}

#[test]
fn bad_arguments_are_refused() {
    let mut sim = scene();
    let (rgb, faces, _) = handles(&sim);
    let e = call(
        &mut sim,
        "simVision.handleSpherical",
        &[
            rgb.clone(),
            Value::Array(faces[..5].to_vec()),
            Value::Float(6.0),
            Value::Float(3.0),
        ],
    )
    .expect_err("five faces");
    assert!(e.contains("six vision sensors"), "{e}");
    let e = call(
        &mut sim,
        "simVision.handleSpherical",
        &[rgb, Value::Array(faces), Value::Float(7.0), Value::Float(3.0)],
    )
    .expect_err("more than a turn");
    assert!(e.contains("horizontal sweep"), "{e}");
}
