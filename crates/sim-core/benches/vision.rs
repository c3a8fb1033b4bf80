//! `cargo bench -p gantry-sim-core --bench vision`: milliseconds per render of
//! BubbleRob's 256 x 256 vision sensor (the CPU rasteriser of `gantry_sim_core::vision`)
//! and of the tutorial's `sysCall_vision` edge-detection flow.
//!
//! Prints one Markdown table. Figures are medians over a few hundred frames on this
//! machine, after a warm-up frame that fills the tessellation cache.

mod timing;

use std::path::{Path, PathBuf};

use gantry_sim_core::api::{self, CallContext};
use gantry_sim_core::math::Pose;
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene, load_scene_text};
use gantry_sim_core::{Handle, Sim, Value, vision};
use timing::median_ms;

fn bubble_rob() -> (Sim, Handle) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/scenes/bubble_rob.toml");
    let model = load_scene(&DiskFiles, &path, &LoadOptions::default()).expect("scene loads");
    let w = Sim::new(&model);
    let sensor = w.world.find("/bubbleRob/visionSensor", None, 0).expect("sensor");
    (w, sensor)
}

/// `cargo bench --bench vision [-- SECTION...]`: every section, or only those named
/// (`bubble_rob`, `scenes`, `panda`, `pyrep_obs`), e.g. to profile one.
fn main() {
    let named: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with("--")).collect();
    let wanted = |section: &str| named.is_empty() || named.iter().any(|n| n == section);
    if wanted("bubble_rob") {
        bubble_rob_frames();
    }
    if wanted("scenes") {
        scenes();
    }
    if wanted("panda") {
        rlbench_views();
    }
    if wanted("pyrep_obs") {
        pyrep_observation();
    }
}

/// BubbleRob's 256 x 256 sensor: the render alone and with the tutorial's edge detection.
fn bubble_rob_frames() {
    println!("| vision, 256 x 256 | ms per frame, median (min) |");
    println!("|---|---|");

    // The scene as loaded: floor, walls and obstacle 0 within the 1 m far plane.
    let (mut w, sensor) = bubble_rob();
    vision::handle_vision_sensor(&w.world, &mut w.vision, sensor).expect("render");
    let ms = median_ms(300, 3, || {
        vision::handle_vision_sensor(&w.world, &mut w.vision, sensor).expect("render")
    });
    println!("| render, scene as loaded | {ms} |");

    // An obstacle filling the middle of the view (more pixels drawn twice).
    let o0 = w.world.find("/obstacle", None, 0).expect("obstacle");
    w.world
        .set_world_pose(o0, Pose::translation(0.35, 0.0, 0.1))
        .expect("pose");
    let ms = median_ms(300, 3, || {
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
    let ms = median_ms(300, 3, || {
        vision::handle_vision_sensor(&w.world, &mut w.vision, sensor).expect("render");
        api::call(&mut w, &ctx, "simVision.sensorImgToWorkImg", &h).expect("to work");
        api::call(&mut w, &ctx, "simVision.edgeDetectionOnWorkImg", &edge).expect("edges");
        api::call(&mut w, &ctx, "simVision.workImgToSensorImg", &h).expect("to sensor");
    });
    println!("| render + edge detection (sysCall_vision) | {ms} |");

    // What a remote client pays to fetch the image.
    let ms = median_ms(300, 3, || {
        api::call(&mut w, &ctx, "sim.getVisionSensorImg", &h).expect("image");
    });
    println!("| sim.getVisionSensorImg (no render) | {ms} |");
}

/// FNV-1a over an image's RGB bytes and depth bits: the bench prints it so two builds
/// (before and after a renderer change) can be compared for bit-identical output.
fn image_hash(img: &vision::SensorImage) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    let mut eat = |b: u8| {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x100_0000_01b3);
    };
    img.rgb().iter().for_each(|&b| eat(b));
    img.depth()
        .iter()
        .flat_map(|d| d.to_bits().to_le_bytes())
        .for_each(&mut eat);
    h
}

/// A file of a PyPI package installed in the workspace's `.venv` (`rel` under
/// site-packages), or under `$env_var` when set. `Err` says why it is missing, for the
/// skip message.
fn venv_file(env_var: &str, env_rel: &str, rel: &str, package: &str) -> Result<PathBuf, String> {
    if let Ok(dir) = std::env::var(env_var) {
        let p = Path::new(&dir).join(env_rel);
        return if p.is_file() {
            Ok(p)
        } else {
            Err(format!("{} not found ({env_var})", p.display()))
        };
    }
    let lib = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../.venv/lib");
    let found = std::fs::read_dir(&lib).ok().and_then(|dirs| {
        dirs.flatten()
            .map(|d| d.path().join("site-packages").join(rel))
            .find(|p| p.is_file())
    });
    found.ok_or_else(|| {
        format!(
            "no {rel}: `pip install {package}` into {}/.. or set {env_var}",
            lib.display()
        )
    })
}

/// The UR5 of the PyPI package `example-robot-data` (`$GANTRY_ROBOT_DATA`: its `robots` folder).
fn ur5_urdf() -> Result<PathBuf, String> {
    let rel = "ur_description/urdf/ur5_robot.urdf";
    let share = "cmeel.prefix/share/example-robot-data/robots/";
    venv_file("GANTRY_ROBOT_DATA", rel, &format!("{share}{rel}"), "example-robot-data")
}

/// The Panda of the PyPI package `pybullet` (`$GANTRY_PYBULLET_DATA`: its `pybullet_data` folder).
fn panda_urdf() -> Result<PathBuf, String> {
    let rel = "franka_panda/panda.urdf";
    venv_file("GANTRY_PYBULLET_DATA", rel, &format!("pybullet_data/{rel}"), "pybullet")
}

/// A scene text: a 4 x 4 m floor, three boxes, a sphere, a cylinder and a capsule around
/// the origin, the robot `urdf` (if
/// any) at the origin, and vision sensors `(name, [width, height], position)`, each
/// looking along world -X with world +Z up in its image (far plane 3 m, 60 degrees).
fn scene_text(urdf: Option<&Path>, sensors: &[(&str, [u32; 2], [f64; 3])]) -> String {
    let mut s = String::from("[simulation]\ndt = 0.05\n\n[floor]\nsize = [4, 4]\n\n");
    for (k, (x, y)) in [(0.5, 0.5), (-0.4, 0.6), (0.3, -0.7)].iter().enumerate() {
        s += &format!(
            "[[object]]\nname = \"box{k}\"\nkind = \"shape\"\nshape = \"box\"\nsize = [0.2, 0.2, 0.2]\n\
             position = [{x}, {y}, 0.1]\nstatic = true\n\n"
        );
    }
    // Round primitives of more than one chunk (a sphere is 960 triangles), in every
    // view, so the bench's hashes cover their chunking too.
    for (k, (shape, size)) in [
        ("sphere", "radius = 0.12"),
        ("cylinder", "radius = 0.08\nlength = 0.3"),
        ("capsule", "radius = 0.06\nlength = 0.2"),
    ]
    .iter()
    .enumerate()
    {
        let y = -0.6 + 0.3 * k as f64;
        s += &format!(
            "[[object]]\nname = \"{shape}\"\nkind = \"shape\"\nshape = \"{shape}\"\n{size}\n\
             position = [0.6, {y}, 0.2]\nstatic = true\ncolor = [0.2, 0.5, 0.9]\n\n"
        );
    }
    for (name, [w, h], [x, y, z]) in sensors {
        // Rx(0) Ry(-90) Rz(-90): local +Z onto world -X, local +Y onto world +Z.
        s += &format!(
            "[[object]]\nname = \"{name}\"\nkind = \"vision_sensor\"\nresolution = [{w}, {h}]\n\
             position = [{x}, {y}, {z}]\norientation_deg = [0, -90, -90]\nfov_deg = 60\nfar = 3.0\n\n"
        );
    }
    if let Some(urdf) = urdf {
        // The upper arm raised (shoulder lift -90 degrees): the arm stands at the
        // origin, in the middle of every view, its upper arm on the 1 x 1 sensor's ray.
        s += &format!(
            "[[robot]]\nname = \"ur5\"\nurdf = {:?}\njoint_mode = \"kinematic\"\ninitial = {{ shoulder_lift_joint = -90 }}\n",
            urdf.display().to_string()
        );
    }
    s
}

fn load_text(text: &str) -> Sim {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/scenes/bench_vision.toml");
    let model = load_scene_text(&DiskFiles, text, &path, &LoadOptions::default()).expect("bench scene loads");
    Sim::new(&model)
}

/// One sensor of `w` rendered `n` times: median (min) ms, the image's hash and the
/// normalised depth at its centre pixel (below 1: the arm or a box is seen there).
fn time_sensor(w: &mut Sim, name: &str, n: usize) -> (String, u64, f32) {
    let h = w.world.find(&format!("/{name}"), None, 0).expect("sensor");
    vision::handle_vision_sensor(&w.world, &mut w.vision, h).expect("render");
    let ms = median_ms(n, 3, || {
        vision::handle_vision_sensor(&w.world, &mut w.vision, h).expect("render")
    });
    let img = w.vision.image(h).expect("image");
    let [width, height] = img.resolution().map(|v| v as usize);
    // To look at what a case renders: GANTRY_BENCH_DUMP=folder writes NAME.ppm there.
    if let Ok(dir) = std::env::var("GANTRY_BENCH_DUMP") {
        let mut ppm = format!("P6 {width} {height} 255\n").into_bytes();
        for row in (0..height).rev() {
            ppm.extend_from_slice(&img.rgb()[3 * row * width..3 * (row + 1) * width]);
        }
        std::fs::write(format!("{dir}/{name}.ppm"), ppm).expect("GANTRY_BENCH_DUMP is a writable folder");
    }
    (ms, image_hash(img), img.depth()[height / 2 * width + width / 2])
}

/// Turns each sensor `names` (keeping its position) to look at the UR5's upper arm,
/// world +Z up in its image: so the arm is in the middle of every view, and the 1 x 1
/// sensor's one ray hits it.
fn aim_at_arm(w: &mut Sim, names: &[&str]) {
    let elbow = w
        .world
        .handles()
        .iter()
        .copied()
        .find(|&h| w.world.object(h).is_ok_and(|o| o.alias == "forearm_link"))
        .expect("UR5 forearm link");
    // 0.2 m above the elbow joint: the middle of the upper arm's mesh as this URDF
    // places it (the joint itself is between two meshes).
    let target = w.world.object(elbow).expect("link").world.translation.vector + nalgebra::Vector3::new(0.0, 0.0, 0.2);
    for name in names {
        aim(w, name, target, nalgebra::Vector3::z());
    }
}

/// Turns sensor `name` (keeping its position) towards the world point `target`, with
/// `up` as near its image's up (+Y) as that allows.
fn aim(w: &mut Sim, name: &str, target: nalgebra::Vector3<f64>, up: nalgebra::Vector3<f64>) {
    let h = w.world.find(&format!("/{name}"), None, 0).expect("sensor");
    let eye = w.world.object(h).expect("sensor").world.translation.vector;
    // Sensor +Z towards the target, +Y as near `up` as that allows; +X = Y x Z.
    let z = (target - eye).normalize();
    let x = up.cross(&z).normalize();
    let y = z.cross(&x);
    let r = nalgebra::Rotation3::from_basis_unchecked(&[x, y, z]);
    let pose = Pose::from_parts(eye.into(), nalgebra::UnitQuaternion::from_rotation_matrix(&r));
    w.world.set_world_pose(h, pose).expect("pose");
}

/// Five 128 x 128 cameras on an arc 1.4 m from the origin, 0.5 m up.
fn five_cameras() -> Vec<(String, [u32; 2], [f64; 3])> {
    (0..5)
        .map(|k| (format!("cam{k}"), [128, 128], [1.4, -0.4 + 0.2 * f64::from(k), 0.5]))
        .collect()
}

/// The scenes of issue 30: floor and boxes, and the same with a public UR5 in view.
fn scenes() {
    println!();
    println!("| vision, scenes of issue 30 | ms per frame, median (min) | image hash | centre depth |");
    println!("|---|---|---|---|");
    let mut w = load_text(&scene_text(None, &[("s512", [512, 384], [1.5, 0.0, 0.5])]));
    let (ms, hash, centre) = time_sensor(&mut w, "s512", 200);
    println!("| floor and primitives, 512 x 384 | {ms} | {hash:016x} | {centre:.3} |");

    let urdf = match ur5_urdf() {
        Ok(p) => p,
        Err(why) => {
            println!("| UR5 cases skipped: {why} | | | |");
            return;
        }
    };
    let sensors = [
        ("s1", [1, 1], [1.5, 0.0, 0.5]),
        ("s512", [512, 384], [1.5, 0.0, 0.5]),
        ("s640", [640, 480], [1.5, 0.0, 0.5]),
    ];
    let mut w = load_text(&scene_text(Some(&urdf), &sensors));
    aim_at_arm(&mut w, &sensors.map(|s| s.0));
    for (name, [x, y], _) in sensors {
        let (ms, hash, centre) = time_sensor(&mut w, name, 100);
        println!("| UR5 in view, {x} x {y} | {ms} | {hash:016x} | {centre:.3} |");
    }
    let cams = five_cameras();
    let refs: Vec<_> = cams.iter().map(|(n, r, p)| (n.as_str(), *r, *p)).collect();
    let mut w = load_text(&scene_text(Some(&urdf), &refs));
    aim_at_arm(&mut w, &refs.iter().map(|s| s.0).collect::<Vec<_>>());
    vision::handle_all_vision_sensors(&w.world, &mut w.vision, false).expect("render");
    let ms = median_ms(100, 3, || {
        vision::handle_all_vision_sensors(&w.world, &mut w.vision, false).expect("render");
    });
    // The same five one after the other on this thread, for the single-core figure.
    let handles: Vec<Handle> = cams
        .iter()
        .map(|(name, _, _)| w.world.find(&format!("/{name}"), None, 0).expect("camera"))
        .collect();
    let one_core = median_ms(100, 3, || {
        for &h in &handles {
            vision::handle_vision_sensor(&w.world, &mut w.vision, h).expect("render");
        }
    });
    let mut hash = 0u64;
    for (name, _, _) in &cams {
        let h = w.world.find(&format!("/{name}"), None, 0).expect("camera");
        hash = hash.rotate_left(7) ^ image_hash(w.vision.image(h).expect("image"));
    }
    println!("| UR5 in view, 5 cameras 128 x 128 (sim.handle_all, all cores) | {ms} | {hash:016x} | |");
    println!("| UR5 in view, 5 cameras 128 x 128 (one after the other, one core) | {one_core} | | |");

    // RGB + depth + mask (RLBench's observation): masks on, then drawn with every render.
    for &h in &handles {
        vision::read_mask(&w.world, &mut w.vision, h).expect("mask");
    }
    let masked = median_ms(100, 3, || {
        vision::handle_all_vision_sensors(&w.world, &mut w.vision, false).expect("render");
    });
    let masked_one_core = median_ms(100, 3, || {
        for &h in &handles {
            vision::handle_vision_sensor(&w.world, &mut w.vision, h).expect("render");
        }
    });
    let mut mask_hash = 0u64;
    for &h in &handles {
        let img = w.vision.image(h).expect("image");
        for &id in img.mask().expect("a mask") {
            mask_hash = (mask_hash ^ u64::from(id as u32)).wrapping_mul(0x100_0000_01b3);
        }
    }
    println!(
        "| UR5 in view, 5 cameras 128 x 128 + masks (sim.handle_all, all cores) | {masked} | {mask_hash:016x} | |"
    );
    println!("| UR5 in view, 5 cameras 128 x 128 + masks (one core) | {masked_one_core} | | |");
}

/// A fixed camera: name, eye, target and the world direction up in its image (m).
type View = (&'static str, [f64; 3], [f64; 3], [f64; 3]);

/// RLBench's five views (front, over each shoulder, overhead, close to the hand) as fixed
/// 128 x 128 cameras around pybullet_data's Panda, RGB + depth + mask: the scene of
/// `tools/bench/vision.py`'s `5x128` case (and of the PyBullet referee's Panda: its joint
/// angles and boxes), so the two benches measure the same frames.
fn rlbench_views() {
    println!();
    println!("| vision, RLBench-style views | ms per step, median (min) | image hash | |");
    println!("|---|---|---|---|");
    let urdf = match panda_urdf() {
        Ok(p) => p,
        Err(why) => {
            println!("| Panda cases skipped: {why} | | | |");
            return;
        }
    };
    // (name, eye, target, up), as in tools/bench/vision.py.
    let views: [View; 5] = [
        ("front", [1.35, 0.0, 0.75], [0.2, 0.0, 0.35], [0.0, 0.0, 1.0]),
        ("left_shoulder", [0.3, 0.75, 0.9], [0.35, -0.1, 0.2], [0.0, 0.0, 1.0]),
        ("right_shoulder", [0.3, -0.75, 0.9], [0.35, 0.1, 0.2], [0.0, 0.0, 1.0]),
        ("overhead", [0.35, 0.0, 1.6], [0.35, 0.0, 0.0], [1.0, 0.0, 0.0]),
        ("wrist", [0.75, 0.1, 0.55], [0.45, 0.05, 0.2], [0.0, 0.0, 1.0]),
    ];
    let mut s = format!(
        "[floor]\nsize = [5, 5]\n\n[[robot]]\nurdf = {:?}\nname = \"robot\"\n\
         initial = {{ panda_joint1 = -28.6479, panda_joint2 = 22.9183, panda_joint3 = 17.1887, \
         panda_joint4 = -114.5916, panda_joint5 = 28.6479, panda_joint6 = 103.1324, panda_joint7 = 51.5662, \
         panda_finger_joint1 = 0.03, panda_finger_joint2 = 0.03 }}\n\n\
         [[object]]\nname = \"box_a\"\nkind = \"shape\"\nshape = \"box\"\nsize = [0.25, 0.25, 0.2]\n\
         position = [0.5, -0.3, 0.1]\norientation_deg = [0, 0, 30]\n\n\
         [[object]]\nname = \"box_b\"\nkind = \"shape\"\nshape = \"box\"\nsize = [0.1, 0.4, 0.3]\n\
         position = [0.3, 0.5, 0.15]\n",
        urdf.display().to_string()
    );
    for (name, [x, y, z], _, _) in &views {
        s += &format!(
            "\n[[object]]\nname = \"{name}\"\nkind = \"vision_sensor\"\nresolution = [128, 128]\n\
             fov_deg = 60.0\nnear = 0.05\nfar = 10.0\nposition = [{x}, {y}, {z}]\n"
        );
    }
    let mut w = load_text(&s);
    for (name, _, target, up) in &views {
        aim(&mut w, name, (*target).into(), (*up).into());
    }
    let handles: Vec<Handle> = views
        .iter()
        .map(|(name, ..)| w.world.find(&format!("/{name}"), None, 0).expect("camera"))
        .collect();
    for &h in &handles {
        vision::read_mask(&w.world, &mut w.vision, h).expect("mask");
    }
    let all = median_ms(100, 3, || {
        vision::handle_all_vision_sensors(&w.world, &mut w.vision, false).expect("render");
    });
    let one_core = median_ms(100, 3, || {
        for &h in &handles {
            vision::handle_vision_sensor(&w.world, &mut w.vision, h).expect("render");
        }
    });
    let mut hash = 0u64;
    for &h in &handles {
        hash = hash.rotate_left(7) ^ image_hash(w.vision.image(h).expect("image"));
    }
    println!("| Panda, RLBench's 5 views 128 x 128 + masks (sim.handle_all, all cores) | {all} | {hash:016x} | |");
    println!("| Panda, RLBench's 5 views 128 x 128 + masks (one core) | {one_core} | | |");
}

/// The renders of `tools/bench/pyrep_bench.py`'s RLBench observation, without Python:
/// PyRep's Panda scene (from `../shared/coppelia-files`) with five explicitly handled
/// 128 x 128 cameras and their five colour-coded mask twins, made by the same `sim.*`
/// calls the `pyrep` package makes. One figure per step: the ten renders, then each
/// RGB camera's image and depth read out, as the Python loop does.
#[allow(clippy::approx_constant, reason = "the angles pyrep_bench.py gives, digit for digit")]
fn pyrep_observation() {
    println!();
    println!("| vision, PyRep's Panda scene | ms per step, median (min) | image hash |");
    println!("|---|---|---|");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let files =
        std::env::var_os("GANTRY_COPPELIA_FILES").map_or_else(|| root.join("../shared/coppelia-files"), PathBuf::from);
    let path = files.join("PyRep__scene_panda_reach_target.ttt");
    if !path.is_file() {
        println!("| skipped: {} is absent | | |", path.display());
        return;
    }
    let model = load_scene(&DiskFiles, &path, &LoadOptions::default()).expect("PyRep's scene loads");
    let mut w = Sim::new(&model);
    let ctx = CallContext::default();
    let call = |w: &mut Sim, name: &str, args: Vec<Value>| -> Vec<Value> {
        api::call(w, &ctx, name, &args).unwrap_or_else(|e| panic!("{name}: {e}"))
    };
    let list = |v: &[f64]| Value::Array(v.iter().map(|&x| Value::Float(x)).collect());
    let tip = w.world.find("/Panda_tip", None, 0).expect("Panda_tip");
    // (position m, orientation rad) as the Python bench places them; None: on the tip.
    let cameras: [Option<([f64; 3], [f64; 3])>; 5] = [
        Some(([0.3, 0.6, 1.5], [2.4, 0.0, -2.6])),
        Some(([0.3, -0.6, 1.5], [-2.4, 0.0, -0.5])),
        Some(([0.9, 0.0, 2.0], [3.14, 0.0, 1.57])),
        Some(([1.8, 0.0, 1.4], [2.2, 1.57, 0.0])),
        None,
    ];
    let mut pairs = Vec::new();
    for pose in cameras {
        let mut pair = Vec::new();
        // Render modes: OpenGL 3 for RGB and depth, colour-coded handles for the mask.
        for mode in [6i64, 2] {
            let floats = list(&[0.01, 4.5, 60f64.to_radians(), 0.01, 0.01, 0.03, 0.0, 0.0, 0.0, 0.0, 0.0]);
            let ints = Value::Array(vec![Value::Int(128), Value::Int(128), Value::Int(0), Value::Int(0)]);
            let h = call(&mut w, "sim.createVisionSensor", vec![Value::Int(1 | 2), ints, floats]);
            let h = h[0].clone();
            call(
                &mut w,
                "sim.setObjectInt32Param",
                vec![h.clone(), Value::Int(1017), Value::Int(mode)],
            );
            match pose {
                Some((p, o)) => {
                    call(
                        &mut w,
                        "sim.setObjectPosition",
                        vec![h.clone(), Value::Int(-1), list(&p)],
                    );
                    call(
                        &mut w,
                        "sim.setObjectOrientation",
                        vec![h.clone(), Value::Int(-1), list(&o)],
                    );
                }
                None => {
                    call(
                        &mut w,
                        "sim.setObjectParent",
                        vec![h.clone(), Value::Int(tip), Value::Bool(false)],
                    );
                    call(
                        &mut w,
                        "sim.setObjectPosition",
                        vec![h.clone(), Value::Int(tip), list(&[0.0, 0.0, -0.05])],
                    );
                }
            }
            pair.push(h);
        }
        pairs.push(pair);
    }
    let ms = median_ms(200, 3, || {
        for pair in &pairs {
            for h in pair {
                call(&mut w, "sim.handleVisionSensor", vec![h.clone()]);
            }
            call(&mut w, "sim.getVisionSensorImg", vec![pair[0].clone()]);
            call(&mut w, "sim.getVisionSensorDepth", vec![pair[0].clone()]);
            call(&mut w, "sim.getVisionSensorImg", vec![pair[1].clone()]);
        }
    });
    let mut hash = 0u64;
    for pair in &pairs {
        for h in pair {
            let Value::Int(h) = *h else { panic!("a handle") };
            hash = hash.rotate_left(7) ^ image_hash(w.vision.image(h).expect("image"));
        }
    }
    println!("| 5 cameras + 5 masks, 128 x 128, rendered and read | {ms} | {hash:016x} |");
}
