//! `cargo bench --bench sim`: steps per second of gantry's scenes against bare rapier
//! (the physics floor), the cost of scripts, and the text channel's latency.
//!
//! Every figure is a ratio or a rate measured in one run on one machine; it prints
//! Markdown tables and writes every figure to `target/bench/gantry.json`, which
//! `tools/bench/report.py` sets beside PyBullet's (`bash tools/bench.sh` runs both). Run a
//! subset with `cargo bench --bench sim -- SECTION...` where a section is `scenes`, `arm`,
//! `rovers` or `text`.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::{Path, PathBuf};
use std::time::Instant;

use gantry_engine::{Engine, EngineConfig, Input, LoopControl};
use gantry_lua::ScriptLimits;
use gantry_server::{ServeConfig, Shutdown, SimConfig};
use gantry_sim_core::World;
use gantry_sim_core::scene::{DiskFiles, LoadOptions, SceneModel, load_scene, load_scene_text};
use gantry_sim_core::sim::Control;
use serde_json::{Value as Json, json};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_owned()
}

fn scene(rel: &str) -> SceneModel {
    load_scene(&DiskFiles, &root().join(rel), &LoadOptions::default()).expect("scene loads")
}

/// The engine of `model`, started: what every front end steps.
fn engine(model: &SceneModel) -> Engine {
    let config = EngineConfig {
        limits: ScriptLimits::default(),
        ..EngineConfig::default()
    };
    let mut e = Engine::new(model.clone(), config, None).expect("simulation");
    e.serve(Input::Control(LoopControl::Control(Control::Start)));
    e
}

/// Steps per second of the full simulation (scripts, sensors, physics).
fn gantry_rate(model: &SceneModel, seconds: f64) -> f64 {
    let mut sim = engine(model);
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

/// `n` BubbleRobs, each with its own script (the lab sheet's, or with `controller` the
/// benchmark's obstacle avoidance alone), in cells of a grid with two obstacles each,
/// walled in so that no rover drives off the floor. tools/bench/pybullet_bench.py builds
/// the same arena.
fn rovers(n: usize, controller: bool) -> SceneModel {
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
            let mut b = b.replace("script = \"../../scripts/edge_detect.lua\"\n", "");
            if controller {
                b = b.replace(
                    "../../scripts/bubble_rob.lua",
                    "../../scripts/bench/rover_controller.lua",
                );
            }
            let b = b
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
    // Walls along the floor's edges, 0.1 m thick and 0.2 m high.
    let h = extent / 2.0;
    for (k, (x, y, sx, sy)) in [
        (0.0, h, extent, 0.1),
        (0.0, -h, extent, 0.1),
        (h, 0.0, 0.1, extent),
        (-h, 0.0, 0.1, extent),
    ]
    .into_iter()
    .enumerate()
    {
        out.push_str(&format!(
            "\n[[object]]\nname = \"wall{k}\"\nkind = \"shape\"\nshape = \"box\"\nsize = [{sx}, {sy}, 0.2]\nposition = [{x}, {y}, 0.1]\n"
        ));
    }
    let path = root().join("assets/scenes/rovers_generated.toml");
    load_scene_text(&DiskFiles, &out, &path, &LoadOptions::default()).expect("generated scene loads")
}

/// The rover fleet's floor: the benchmark controller (scripts/bench/rover_controller.lua)
/// written straight against rapier: a ray from each rover's nose through rapier's query
/// pipeline instead of the proximity cone, motor targets through the multibody API, no
/// object tree, scripts or sensors. The rovers move as they do in gantry, so both worlds
/// have the same contacts to solve.
fn rover_rapier_rate(model: &SceneModel, seconds: f64) -> f64 {
    use gantry_sim_core::rapier3d::prelude::{JointAxis, MultibodyJointHandle, QueryFilter, Ray, RigidBodyHandle};
    let speed = 175f32.to_radians();
    let dt = model.settings.dt;
    let (mut pw, rapier_steps) = World::new(model).into_rapier();
    // Each rover is one multibody: its body is the root, its two wheels the links whose
    // joint sits at +y (left) or -y (right) of the body.
    struct Rover {
        body: RigidBodyHandle,
        left: MultibodyJointHandle,
        right: MultibodyJointHandle,
        back_until: f64,
    }
    let mut wheels: std::collections::HashMap<RigidBodyHandle, [Option<MultibodyJointHandle>; 2]> = Default::default();
    for (h, _, mb, link) in pw.multibody_joints.iter() {
        if link.joint.ndofs() == 1 {
            let side = usize::from(link.joint.data.local_frame1.translation.y < 0.0);
            wheels.entry(mb.root().rigid_body_handle()).or_default()[side] = Some(h);
        }
    }
    let mut fleet: Vec<Rover> = wheels
        .into_iter()
        .map(|(body, [l, r])| Rover {
            body,
            left: l.expect("left wheel"),
            right: r.expect("right wheel"),
            back_until: -1.0,
        })
        .collect();
    fleet.sort_by_key(|r| r.body.into_raw_parts());
    let mut steps = 0u64;
    let t = Instant::now();
    while t.elapsed().as_secs_f64() < seconds {
        let time = steps as f64 * dt;
        for r in &mut fleet {
            let pose = *pw.bodies[r.body].position();
            let ahead = pose.rotation * gantry_sim_core::rapier3d::math::Vector::X;
            let ray = Ray::new(pose.translation + ahead * 0.1, ahead);
            let qp = pw
                .query_pipeline()
                .with_filter(QueryFilter::default().exclude_rigid_body(r.body));
            if qp.cast_ray(&ray, 0.155, true).is_some() {
                r.back_until = time + 4.0;
            }
            let (vl, vr) = if r.back_until < time {
                (speed, speed)
            } else {
                (-speed / 2.0, -speed / 8.0)
            };
            for (joint, v) in [(r.left, vl), (r.right, vr)] {
                if let Some((mb, link)) = pw.multibody_joints.get_mut(joint)
                    && let Some(l) = mb.link_mut(link)
                {
                    let m = l.joint.data.motor(JointAxis::AngX).copied().expect("velocity motor");
                    l.joint.data.set_motor(JointAxis::AngX, 0.0, v, 0.0, m.damping);
                }
            }
        }
        for _ in 0..rapier_steps {
            pw.step();
        }
        steps += 1;
    }
    steps as f64 / t.elapsed().as_secs_f64()
}

fn without_scripts(mut m: SceneModel) -> SceneModel {
    m.scripts.clear();
    m
}

fn scenes(secs: f64) -> Json {
    println!("\n### Scenes, headless, as fast as possible (dt 0.05 s, 10 substeps)\n");
    println!("| scene | gantry steps/s | real-time factor | bare rapier steps/s | gantry / rapier |");
    println!("|---|---|---|---|---|");
    let mut out = Vec::new();
    for (name, model) in [
        ("fk_arm", scene("assets/scenes/fk_arm.toml")),
        ("bubble_rob (with its scripts)", scene("assets/scenes/bubble_rob.toml")),
        (
            "bubble_rob (no script)",
            without_scripts(scene("assets/scenes/bubble_rob.toml")),
        ),
        ("showroom", scene("assets/scenes/showroom.toml")),
    ] {
        let g = gantry_rate(&model, secs);
        let r = rapier_rate(&model, secs);
        let rtf = g * model.settings.dt;
        println!("| {name} | {g:.0} | {rtf:.0} | {r:.0} | {:.2} |", g / r);
        out.push(json!({"scene": name, "steps_per_s": g, "rtf": rtf, "rapier_steps_per_s": r}));
    }
    Json::Array(out)
}

/// The engine's own cost: a scene without scripts stepped through `Engine::step` (what
/// every front end does) against the bare `Sim::step` of the same scene, in
/// alternating rounds so that both see the same host. Issue 47's target: within 3 %.
fn engine_overhead(secs: f64) -> Json {
    println!("\n### The engine's cost without scripts: Engine::step against bare Sim::step\n");
    println!("| scene | Sim::step steps/s | Engine::step steps/s | engine / bare |");
    println!("|---|---|---|---|");
    let rounds = 5;
    let per_round = secs / rounds as f64;
    let mut out = Vec::new();
    for (name, model) in [
        (
            "bubble_rob (no script)",
            without_scripts(scene("assets/scenes/bubble_rob.toml")),
        ),
        (
            "fk_arm (no script)",
            without_scripts(scene("assets/scenes/fk_arm.toml")),
        ),
        ("empty", scene("assets/scenes/bench/empty.toml")),
    ] {
        let mut bare = gantry_sim_core::Sim::new(&model);
        bare.state = gantry_sim_core::sim::SimulationState::Running;
        let mut eng = engine(&model);
        let (mut b, mut e) = (Vec::new(), Vec::new());
        for _ in 0..rounds {
            b.push(rate_for(per_round, || bare.step()));
            e.push(rate_for(per_round, || eng.step()));
        }
        b.sort_by(f64::total_cmp);
        e.sort_by(f64::total_cmp);
        let (b, e) = (b[rounds / 2], e[rounds / 2]);
        println!("| {name} | {b:.0} | {e:.0} | {:.3} |", e / b);
        out.push(json!({"scene": name, "sim_steps_per_s": b, "engine_steps_per_s": e, "ratio": e / b}));
    }
    Json::Array(out)
}

/// Steps per second of `step` called for `secs`, in batches of 10.
fn rate_for(secs: f64, mut step: impl FnMut()) -> f64 {
    let t = Instant::now();
    let mut n = 0u64;
    while t.elapsed().as_secs_f64() < secs {
        for _ in 0..10 {
            step();
        }
        n += 10;
    }
    n as f64 / t.elapsed().as_secs_f64()
}

/// The arm's floor: the same rapier world given the same targets straight through
/// rapier's multibody API (no Lua, no tree, no read-back), so that both move alike.
fn arm_rapier_rate(model: &SceneModel, steps: u64) -> f64 {
    use gantry_sim_core::rapier3d::prelude::JointAxis;
    const A: [f32; 6] = [0.6, 0.5, 0.4, 0.8, 0.6, 1.0];
    const F: [f32; 6] = [0.25, 0.3, 0.35, 0.4, 0.45, 0.5];
    let (mut pw, rapier_steps) = World::new(model).into_rapier();
    // Revolute links in chain order (link ids grow from the base).
    let mut joints: Vec<_> = pw
        .multibody_joints
        .iter()
        .filter(|(_, _, _, link)| link.joint.ndofs() == 1)
        .map(|(h, id, _, _)| (id.id, h))
        .collect();
    joints.sort_by_key(|&(id, _)| id);
    assert_eq!(joints.len(), 6, "arm6 has six moving joints");
    let dt = model.settings.dt as f32;
    let t = Instant::now();
    let mut sum = 0.0f32;
    for k in 0..steps {
        let time = (k + 1) as f32 * dt;
        for (i, &(_, h)) in joints.iter().enumerate() {
            if let Some((mb, link)) = pw.multibody_joints.get_mut(h)
                && let Some(l) = mb.link_mut(link)
            {
                let target = A[i] * (2.0 * std::f32::consts::PI * F[i] * time).sin();
                let m = l.joint.data.motor(JointAxis::AngX).copied().expect("position motor");
                l.joint
                    .data
                    .set_motor(JointAxis::AngX, target, 0.0, m.stiffness, m.damping);
            }
        }
        for _ in 0..rapier_steps {
            pw.step();
        }
        for &(_, h) in &joints {
            if let Some((mb, link)) = pw.multibody_joints.get(h) {
                sum += mb.link(link).map_or(0.0, |l| l.joint.coords()[3]);
            }
        }
    }
    std::hint::black_box(sum);
    steps as f64 / t.elapsed().as_secs_f64()
}

/// The arm benchmark: arm6 at dt 1/240 with one substep, a new position target for every
/// joint every step from scripts/bench/arm_tracking.lua, 10,000 steps.
fn arm(steps: u64) -> Json {
    let model = scene("assets/scenes/bench/arm_tracking.toml");
    let mut sim = engine(&model);
    let t = Instant::now();
    for _ in 0..steps {
        sim.step();
    }
    let rate = steps as f64 / t.elapsed().as_secs_f64();
    let err = sim
        .call_script_function("trackingError", &[])
        .expect("trackingError runs")
        .expect("the benchmark script defines trackingError");
    let num = |i: usize| err.get(i).and_then(gantry_sim_core::Value::as_f64).expect("a number");
    let (rms, max) = (num(0), num(1));
    let bare = arm_rapier_rate(&model, steps);
    println!("\n### Arm: arm6, dt 1/240 s, 1 substep, new position targets every step from Lua\n");
    println!("| steps | gantry steps/s | RMS joint error rad | largest error rad | bare rapier steps/s |");
    println!("|---|---|---|---|---|");
    println!("| {steps} | {rate:.0} | {rms:.2e} | {max:.2e} | {bare:.0} |");
    json!({"steps": steps, "steps_per_s": rate, "rms_error_rad": rms, "max_error_rad": max, "rapier_steps_per_s": bare})
}

fn rover_scaling(secs: f64) -> Json {
    println!("\n### BubbleRobs, each running its own script (dt 0.05 s, 10 substeps)\n");
    println!(
        "| rovers | lab-sheet script steps/s | rtf | controller only steps/s | rtf | no scripts (parked) steps/s | bare rapier, same controller steps/s | controller / rapier |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let mut out = Vec::new();
    for n in [1, 10, 50, 100] {
        let model = rovers(n, false);
        let dt = model.settings.dt;
        let lab = gantry_rate(&model, secs);
        let ctl = gantry_rate(&rovers(n, true), secs);
        let ns = gantry_rate(&without_scripts(model.clone()), secs);
        let r = rover_rapier_rate(&model, secs);
        println!(
            "| {n} | {lab:.1} | {:.1} | {ctl:.1} | {:.1} | {ns:.1} | {r:.1} | {:.2} |",
            lab * dt,
            ctl * dt,
            ctl / r
        );
        out.push(json!({
            "rovers": n,
            "lab_sheet_steps_per_s": lab,
            "controller_steps_per_s": ctl,
            "no_scripts_steps_per_s": ns,
            "rapier_steps_per_s": r,
            "dt": dt,
        }));
    }
    Json::Array(out)
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

fn text_latency() -> Json {
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
    json!({
        "persistent_median_us": percentile(&persistent, 0.5),
        "persistent_p99_us": percentile(&persistent, 0.99),
        "per_connection_median_us": percentile(&per_conn, 0.5),
        "per_connection_p99_us": percentile(&per_conn, 0.99),
        "packets_per_s": rate,
    })
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
    let dir = root().join("target/bench");
    let path = dir.join("gantry.json");
    // A subset run updates its sections and keeps the others' last figures.
    let mut report = std::fs::read_to_string(&path)
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Map<String, Json>>(&t).ok())
        .unwrap_or_default();
    report.insert(
        "cores".into(),
        json!(std::thread::available_parallelism().map_or(1, |n| n.get())),
    );
    if want("scenes") {
        report.insert("scenes".into(), scenes(secs));
    }
    if want("arm") {
        report.insert("arm".into(), arm(10_000));
    }
    if want("engine") {
        report.insert("engine".into(), engine_overhead(secs * 2.0));
    }
    if want("rovers") {
        report.insert("rovers".into(), rover_scaling(secs));
    }
    if want("text") {
        report.insert("text".into(), text_latency());
    }
    std::fs::create_dir_all(&dir).expect("target/bench");
    std::fs::write(
        &path,
        serde_json::to_string_pretty(&Json::Object(report)).expect("json"),
    )
    .expect("write");
    println!("\nfigures written to {}", path.display());
}
