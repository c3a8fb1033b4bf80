//! `cargo bench --bench sim`: steps per second of gantry's scenes against bare rapier
//! (the physics floor), the cost of scripts, and the text channel's latency.
//!
//! Every figure is a ratio or a rate measured in one run on one machine; it prints a
//! Markdown table. Run a subset with `cargo bench --bench sim -- SECTION...` where a
//! section is `scenes`, `rovers` or `text`.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::{Path, PathBuf};
use std::time::Instant;

use gantry_script::{ScriptLimits, Simulation};
use gantry_server::{ServeConfig, Shutdown, SimConfig};
use gantry_sim_core::World;
use gantry_sim_core::scene::{DiskFiles, LoadOptions, SceneModel, load_scene, load_scene_text};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_owned()
}

fn scene(rel: &str) -> SceneModel {
    load_scene(&DiskFiles, &root().join(rel), &LoadOptions::default()).expect("scene loads")
}

/// Steps per second of the full simulation (scripts, sensors, physics).
fn gantry_rate(model: &SceneModel, seconds: f64) -> f64 {
    let mut sim = Simulation::new(model.clone(), ScriptLimits::default()).expect("simulation");
    sim.start();
    for _ in 0..10 {
        sim.step();
    }
    let t = Instant::now();
    let mut n = 0u64;
    while t.elapsed().as_secs_f64() < seconds {
        for _ in 0..10 {
            sim.step();
        }
        n += 10;
    }
    n as f64 / t.elapsed().as_secs_f64()
}

/// Steps per second of the same rapier world stepped bare: no tree, no sensors, no scripts.
fn rapier_rate(model: &SceneModel, seconds: f64) -> f64 {
    let (mut pw, rapier_steps) = World::new(model).into_rapier();
    let t = Instant::now();
    let mut n = 0u64;
    while t.elapsed().as_secs_f64() < seconds {
        for _ in 0..rapier_steps {
            pw.step();
        }
        n += 1;
    }
    n as f64 / t.elapsed().as_secs_f64()
}

/// `n` BubbleRobs, each with its own script, in cells of a grid with two obstacles each.
fn rovers(n: usize) -> SceneModel {
    let text = std::fs::read_to_string(root().join("assets/scenes/bubble_rob.toml")).expect("scene text");
    let mut blocks = text.split("\n[[object]]\n");
    let header = blocks.next().expect("header");
    let rover: Vec<&str> = blocks
        .filter(|b| !b.contains("\"obstacle") && !b.contains("\"wall"))
        .collect();
    let side = (n as f64).sqrt().ceil() as usize;
    let cell = 2.0;
    let extent = side as f64 * cell + 1.0;
    let mut out = header.replace("size = [5, 5]", &format!("size = [{extent}, {extent}]"));
    for i in 0..n {
        let (cx, cy) = ((i % side) as f64 * cell, (i / side) as f64 * cell);
        let (cx, cy) = (cx - extent / 2.0 + 1.5, cy - extent / 2.0 + 1.5);
        for b in &rover {
            // Each rover runs its controller; the camera's edge-detection script is left
            // out (it is measured on its own by `cargo bench -p gantry-sim-core --bench vision`).
            let b = b
                .replace("script = \"../../scripts/edge_detect.lua\"\n", "")
                .replace("name = \"", &format!("name = \"r{i}_"))
                .replace("parent = \"", &format!("parent = \"r{i}_"))
                .replace("position = [0, 0, 0.12]", &format!("position = [{cx}, {cy}, 0.12]"));
            out.push_str("\n[[object]]\n");
            out.push_str(&b);
        }
        for (k, (dx, dy)) in [(0.7, 0.1), (-0.2, 0.75)].into_iter().enumerate() {
            out.push_str(&format!(
                "\n[[object]]\nname = \"o{i}_{k}\"\nalias = \"obstacle\"\nkind = \"shape\"\nshape = \"cylinder\"\nradius = 0.05\nlength = 0.2\nposition = [{}, {}, 0.1]\n",
                cx + dx,
                cy + dy
            ));
        }
    }
    let path = root().join("assets/scenes/rovers_generated.toml");
    load_scene_text(&DiskFiles, &out, &path, &LoadOptions::default()).expect("generated scene loads")
}

fn without_scripts(mut m: SceneModel) -> SceneModel {
    m.scripts.clear();
    m
}

fn scenes(secs: f64) {
    println!("\n### Scenes, headless, as fast as possible (dt 0.05 s, 10 substeps)\n");
    println!("| scene | gantry steps/s | real-time factor | bare rapier steps/s | gantry / rapier |");
    println!("|---|---|---|---|---|");
    for (name, model) in [
        ("fk_arm", scene("assets/scenes/fk_arm.toml")),
        ("bubble_rob (with its script)", scene("assets/scenes/bubble_rob.toml")),
        (
            "bubble_rob (no script)",
            without_scripts(scene("assets/scenes/bubble_rob.toml")),
        ),
        ("showroom", scene("assets/scenes/showroom.toml")),
    ] {
        let g = gantry_rate(&model, secs);
        let r = rapier_rate(&model, secs);
        println!(
            "| {name} | {g:.0} | {:.0} | {r:.0} | {:.2} |",
            g * model.settings.dt,
            g / r
        );
    }
}

fn rover_scaling(secs: f64) {
    println!("\n### BubbleRobs, each running its own script (dt 0.05 s, 10 substeps)\n");
    println!(
        "| rovers | gantry steps/s | real-time factor | no scripts steps/s | bare rapier steps/s | gantry / rapier |"
    );
    println!("|---|---|---|---|---|---|");
    for n in [1, 10, 50, 100] {
        let model = rovers(n);
        let g = gantry_rate(&model, secs);
        let ns = gantry_rate(&without_scripts(model.clone()), secs);
        let r = rapier_rate(&model, secs);
        println!(
            "| {n} | {g:.1} | {:.1} | {ns:.1} | {r:.1} | {:.2} |",
            g * model.settings.dt,
            g / r
        );
    }
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

fn text_latency() {
    let model = scene("assets/scenes/fk_arm.toml");
    let (tx, rx) = std::sync::mpsc::channel();
    let shutdown = Shutdown::default();
    let stop = shutdown.clone();
    let server = std::thread::spawn(move || {
        let serve = ServeConfig {
            text_port: Some(0),
            ..ServeConfig::default()
        };
        // Real time, as the paper's GUI sees it: replies must not wait for the 50 ms step.
        let sim = SimConfig {
            steps: None,
            fast: false,
            limits: ScriptLimits::default(),
            autostart: true,
            ..SimConfig::default()
        };
        gantry_server::run(model, sim, serve, stop, |b| {
            tx.send(b.text.expect("text port")).expect("ready")
        })
    });
    let addr: SocketAddr = rx.recv().expect("server ready");
    let packet = "<FK#J1=0.785398163397448,J2=0,J3=-0.5,J4=0,J5=-1.2,J6=0>";

    let mut s = TcpStream::connect(addr).expect("connect");
    s.set_nodelay(true).expect("nodelay");
    let mut r = BufReader::new(s.try_clone().expect("clone"));
    let mut line = String::new();
    let mut persistent = Vec::new();
    for i in 0..5000 {
        let t = Instant::now();
        s.write_all(packet.as_bytes())
            .and_then(|()| s.write_all(b"\n"))
            .expect("write");
        line.clear();
        r.read_line(&mut line).expect("reply");
        if i >= 200 {
            persistent.push(t.elapsed().as_secs_f64() * 1e6);
        }
    }
    let t = Instant::now();
    let n = 20_000;
    for _ in 0..n {
        s.write_all(packet.as_bytes())
            .and_then(|()| s.write_all(b"\n"))
            .expect("write");
        line.clear();
        r.read_line(&mut line).expect("reply");
    }
    let rate = n as f64 / t.elapsed().as_secs_f64();

    let mut per_conn = Vec::new();
    let mut connect = Vec::new();
    for _ in 0..2000 {
        let t0 = Instant::now();
        let mut c = TcpStream::connect(addr).expect("connect");
        connect.push(t0.elapsed().as_secs_f64() * 1e6);
        // Latency counts from the request, as for the persistent client; connection
        // set-up is reported separately.
        let t = Instant::now();
        c.write_all(packet.as_bytes())
            .and_then(|()| c.write_all(b"\r\n"))
            .expect("write");
        let mut buf = [0u8; 100];
        let _ = c.read(&mut buf).expect("reply");
        per_conn.push(t.elapsed().as_secs_f64() * 1e6);
    }
    shutdown.trigger();
    server.join().expect("server thread").expect("server ran");
    persistent.sort_by(f64::total_cmp);
    per_conn.sort_by(f64::total_cmp);
    let within_1ms = persistent.iter().filter(|&&v| v <= 1000.0).count() as f64 / persistent.len() as f64;
    println!("\n### Text channel, fk_arm running in real time (dt 0.05 s)\n");
    println!("| client style | median µs | p99 µs | within 1 ms |");
    println!("|---|---|---|---|");
    println!(
        "| persistent connection | {:.0} | {:.0} | {:.1} % |",
        percentile(&persistent, 0.5),
        percentile(&persistent, 0.99),
        within_1ms * 100.0
    );
    let within = per_conn.iter().filter(|&&v| v <= 1000.0).count() as f64 / per_conn.len() as f64;
    println!(
        "| new connection per command (C# style) | {:.0} | {:.0} | {:.1} % |",
        percentile(&per_conn, 0.5),
        percentile(&per_conn, 0.99),
        within * 100.0
    );
    connect.sort_by(f64::total_cmp);
    println!(
        "\nConnection set-up (C# style, before the request): median {:.0} µs, p99 {:.0} µs",
        percentile(&connect, 0.5),
        percentile(&connect, 0.99)
    );
    println!("One persistent connection, request/reply: {rate:.0} packets/s");
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with("--")).collect();
    let want = |s: &str| args.is_empty() || args.iter().any(|a| a == s);
    let secs = std::env::var("GANTRY_BENCH_SECONDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(3.0);
    println!(
        "gantry benchmark, {} cores, {secs} s per figure",
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );
    if want("scenes") {
        scenes(secs);
    }
    if want("rovers") {
        rover_scaling(secs);
    }
    if want("text") {
        text_latency();
    }
}
