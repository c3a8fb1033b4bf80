//! How accurate are the physics settings? Runs the same three experiments under several
//! ways of splitting a 50 ms step, against a reference of 200 rapier steps of 0.25 ms:
//!
//! - BubbleRob (no script) driving straight with both wheels at 3.054 rad/s: its speed
//!   (ideal ω·r = 0.12216 m/s) and how far it drifts sideways in 7 s;
//! - a 10 cm box dropped from 1 m and a 5 cm ball from 3 m (7.7 m/s at impact): the lowest
//!   centre height reached (0.05 m means no penetration) and where the box comes to rest;
//! - arm6 in position mode, every joint stepped to 0.5 rad: the largest joint error after
//!   1 s and 3 s (gravity against the position gain leaves a small steady error).
//!
//! `cargo run --release -p gantry-sim-core --example substep_accuracy`; the figures are in
//! docs/performance.md.

use std::path::{Path, PathBuf};

use gantry_sim_core::Sim;
use gantry_sim_core::scene::{DiskFiles, LoadOptions, SceneModel, load_scene_text};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn scene(text: &str) -> SceneModel {
    let path = root().join("assets/scenes/experiment.toml");
    load_scene_text(&DiskFiles, text, &path, &LoadOptions::default()).expect("scene loads")
}

fn step(w: &mut Sim, n: usize) {
    for _ in 0..n {
        w.step();
    }
}

/// (speed m/s, sideways drift m) of BubbleRob driving straight.
fn rover(settings: &str) -> (f64, f64) {
    let text = std::fs::read_to_string(root().join("assets/scenes/bubble_rob.toml")).expect("scene");
    let mut m = scene(&text.replace("substeps = 10", settings));
    m.scripts.clear();
    let mut w = Sim::new(&m);
    let find = |w: &Sim, p: &str| w.world.find(p, None, 0).expect(p);
    let (l, r, b) = (find(&w, "/leftMotor"), find(&w, "/rightMotor"), find(&w, "/bubbleRob"));
    step(&mut w, 20);
    let p0 = w.world.object(b).expect("rover").world.translation.vector;
    w.world.set_joint_target_velocity(l, 3.054).expect("left");
    w.world.set_joint_target_velocity(r, 3.054).expect("right");
    step(&mut w, 20);
    let p1 = w.world.object(b).expect("rover").world.translation.vector;
    step(&mut w, 100);
    let p2 = w.world.object(b).expect("rover").world.translation.vector;
    ((p2 - p1).norm() / 5.0, (p2 - p0).y)
}

/// (box lowest z, box resting z, ball lowest z), m.
fn drop_test(settings: &str) -> (f64, f64, f64) {
    let text = format!(
        "[simulation]\ndt = 0.05\n{settings}\n[floor]\n\
         [[object]]\nname = \"box\"\nkind = \"shape\"\nshape = \"box\"\nsize = [0.1, 0.1, 0.1]\nposition = [0, 0, 1.0]\ndynamic = true\nmass = 1.0\n\
         [[object]]\nname = \"ball\"\nkind = \"shape\"\nshape = \"sphere\"\nradius = 0.05\nposition = [0.5, 0, 3.0]\ndynamic = true\nmass = 1.0\n"
    );
    let mut w = Sim::new(&scene(&text));
    let (bx, bl) = (
        w.world.find("/box", None, 0).expect("box"),
        w.world.find("/ball", None, 0).expect("ball"),
    );
    let z = |w: &Sim, h| w.world.object(h).expect("object").world.translation.z;
    let (mut box_min, mut ball_min) = (f64::MAX, f64::MAX);
    for _ in 0..60 {
        step(&mut w, 1);
        box_min = box_min.min(z(&w, bx));
        ball_min = ball_min.min(z(&w, bl));
    }
    (box_min, z(&w, bx), ball_min)
}

/// Largest joint error (rad) of arm6 after 1 s and 3 s of a 0.5 rad step on every joint.
fn arm(settings: &str) -> (f64, f64) {
    let text = std::fs::read_to_string(root().join("assets/scenes/fk_arm.toml"))
        .expect("scene")
        .replace("substeps = 10", settings)
        .replace("joint_mode = \"kinematic\"", "joint_mode = \"position\"")
        .replace("script = \"../../scripts/fk_server.lua\"", "");
    let mut w = Sim::new(&scene(&text));
    let joints: Vec<_> = (1..=6)
        .map(|i| w.world.find(&format!("/arm6/joint{i}"), None, 0).expect("joint"))
        .collect();
    for &j in &joints {
        w.world.set_joint_target_position(j, 0.5).expect("target");
    }
    let err = |w: &Sim| {
        joints
            .iter()
            .map(|&j| (w.world.joint(j).expect("joint").position - 0.5).abs())
            .fold(0.0, f64::max)
    };
    step(&mut w, 20);
    let at_1s = err(&w);
    step(&mut w, 40);
    (at_1s, err(&w))
}

fn main() {
    println!(
        "| 50 ms step as | rover m/s (ideal 0.12216) | sideways drift m | box lowest / rest z m | ball lowest z m | arm error 1 s / 3 s rad |"
    );
    println!("|---|---|---|---|---|---|");
    for (label, n, every) in [
        ("reference: 200 rapier steps", 200, true),
        ("10 rapier steps (collisions every substep)", 10, true),
        ("1 rapier step of 10 solver substeps (default)", 10, false),
        ("1 rapier step of 4 solver substeps", 4, false),
        ("1 rapier step of 20 solver substeps", 20, false),
    ] {
        let settings = format!("substeps = {n}\ncollisions_every_substep = {every}");
        let (v, drift) = rover(&settings);
        let (box_min, box_rest, ball_min) = drop_test(&settings);
        let (e1, e3) = arm(&settings);
        println!(
            "| {label} | {v:.5} | {drift:+.5} | {box_min:.4} / {box_rest:.4} | {ball_min:.4} | {e1:.2e} / {e3:.2e} |"
        );
    }
}
