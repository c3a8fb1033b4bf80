//! Imports every public CoppeliaSim file in the shared folder (`../shared/coppelia-files/`
//! from the repository root, or `$GANTRY_COPPELIA_FILES`), builds a world from each and
//! steps it. Checks that the tree survives the import (every object at the world pose the
//! file gives it), that library robots keep their IK tip on their target, and that the
//! simulation stays finite. Where the folder is absent the test prints a note and passes.

use std::path::Path;

use gantry_sim_core::api::{self, CallContext};
use gantry_sim_core::scene::{DiskFiles, JointMode, LoadOptions, ObjectModelKind, load_coppelia, load_scene};
use gantry_sim_core::{Sim, Value};
use gantry_test_support::{coppelia_files, repo};

#[test]
fn shared_files_import_build_and_step() {
    let dir = coppelia_files();
    if !dir.join("SOURCES.md").is_file() {
        println!(
            "coppelia-files not found at {}; skipped (set GANTRY_COPPELIA_FILES)",
            dir.display()
        );
        return;
    }
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("folder")
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".ttt") || n.ends_with(".ttm"))
        .collect();
    names.sort();
    println!(
        "{:<42} {:>7} {:>7} {:>7} {:>8} {:>5}",
        "file", "objects", "dummies", "scripts", "dropped", "warn"
    );
    for name in &names {
        let bytes = std::fs::read(dir.join(name)).expect("read");
        let (model, report) = load_coppelia(&bytes, Path::new(name)).unwrap_or_else(|e| panic!("{e}"));
        let file = gantry_coppelia_file::read(&bytes).expect("reads");
        assert_eq!(model.objects.len(), file.objects.len(), "{name}: every object imported");
        for (k, o) in model.objects.iter().enumerate() {
            assert!(o.parent.is_none_or(|p| p < k), "{name}: {} before its parent", o.alias);
        }

        // Every object at the world pose the file's tree gives it.
        let mut sim = Sim::new(&model);
        let file_world = file.world_poses();
        for (k, &handle) in report.file_handles.iter().enumerate() {
            let i = file
                .objects
                .iter()
                .position(|o| o.handle == handle)
                .expect("handle from the file");
            let want = file_world[i].expect("the file's tree is whole").position;
            let got = sim.world.object(k as _).expect("object").world.translation.vector;
            let d = (0..3).map(|c| (got[c] - want[c]).powi(2)).sum::<f64>().sqrt();
            // 0.1 mm: gantry holds initial joint positions to their limits, and a few
            // files store positions a hair outside them (turtlebot: 9 µm).
            assert!(
                d < 1e-4,
                "{name}: {} is {d} m from where the file puts it",
                model.objects[k].alias
            );
        }

        // A few steps of physics stay finite.
        for _ in 0..5 {
            sim.step();
        }
        for h in 0..model.objects.len() {
            let p = sim.world.object(h as _).expect("object").world.translation.vector;
            assert!(p.iter().all(|v| v.is_finite()), "{name}: object {h} left the reals");
        }
        println!(
            "{:<42} {:>7} {:>7} {:>7} {:>8} {:>5}",
            name,
            report.objects,
            report.as_dummies.len(),
            report.scripts_attached,
            report.scripts_dropped.len(),
            report.warnings.len()
        );
    }
}

/// The RG2 gripper (on a UR3 in a course's scene) closes its finger linkages with
/// dynamic loop closures: pairs of dummies named `...LoopDummyA`/`...LoopDummyB`. The
/// import links each pair, and the physics keeps the two frames together.
#[test]
fn loop_closure_dummies_are_linked_and_held_together() {
    let dir = coppelia_files();
    let name = "Libro-Copp__cap20_abrir_cerrar_pinza.ttt";
    let Ok(bytes) = std::fs::read(dir.join(name)) else {
        println!(
            "{name} not found in {}; skipped (set GANTRY_COPPELIA_FILES)",
            dir.display()
        );
        return;
    };
    let (mut model, _) = load_coppelia(&bytes, Path::new(name)).expect("imports");
    // The UR3's saved targets are 0 with its joints at 2π (its disabled script set them
    // at run time): hold the arm where it is, so that only the gripper's own dynamics act.
    for o in &mut model.objects {
        if let ObjectModelKind::Joint(j) = &mut o.kind
            && o.alias == "joint"
        {
            j.target_position = j.initial;
        }
    }
    let model = model;
    let alias = |k: usize| model.objects[k].alias.as_str();
    let links: Vec<[usize; 2]> = model.dummy_links.iter().chain(&model.ball_links).copied().collect();
    let mut pairs: Vec<(String, String)> = links
        .iter()
        .map(|&[a, b]| (alias(a).to_owned(), alias(b).to_owned()))
        .collect();
    pairs.sort();
    assert_eq!(pairs.len(), 4, "{pairs:?}");
    // The left and right linkages close through the fingers' free spherical joints: those
    // two closures hold the dummies' origins only.
    let mut balls: Vec<&str> = model.ball_links.iter().map(|&[a, _]| alias(a)).collect();
    balls.sort();
    assert_eq!(balls, ["leftLoopDummyB", "rightLoopDummyB"], "{pairs:?}");
    for (a, b) in &pairs {
        let (sa, sb) = (a.trim_end_matches(['A', 'B']), b.trim_end_matches(['A', 'B']));
        assert!(a.contains("LoopDummy") && sa == sb, "{a} is linked to {b}");
    }

    let mut sim = Sim::new(&model);
    for [a, b] in &links {
        assert_eq!(sim.world.linked_dummy(*a as _), Some(*b as _));
    }
    let gap = |sim: &Sim, a: usize, b: usize| {
        let p = |h: usize| sim.world.object(h as _).expect("dummy").world.translation.vector;
        (p(a) - p(b)).norm()
    };
    for &[a, b] in &links {
        assert!(gap(&sim, a, b) < 1e-6, "the file saves the linkages closed");
    }
    for _ in 0..40 {
        sim.step();
    }
    for &[a, b] in &links {
        // Measured: 0.9 to 3.0 mm (rapier's impulse joints between multibody links are
        // soft); unlinked, the free fingers fall 0.18 to 0.49 m apart in the same time.
        let gap = gap(&sim, a, b);
        println!("{} - {}: {:.2} mm apart after 2 s", alias(a), alias(b), gap * 1e3);
        assert!(gap < 0.015, "{} and {} are {gap} m apart", alias(a), alias(b));
    }
}

/// Library arms as CoppeliaSim's model browser has them (PyRep's copies), on gantry's
/// floor: with their own joint settings they hold their saved pose under gravity for
/// 10 s, their tip dummy within 1 mm of where it started, and a joint given a new
/// target reaches it.
#[test]
fn library_arms_hold_their_pose_and_follow_targets() {
    let dir = coppelia_files();
    if !dir.join("SOURCES.md").is_file() {
        println!("coppelia-files not found at {}; skipped", dir.display());
        return;
    }
    let arms = [
        ("PyRep__Panda.ttm", "Panda"),
        ("PyRep__UR10.ttm", "UR10"),
        ("PyRep__LBR_iiwa_14_R820.ttm", "LBR_iiwa_14_R820"),
        ("PyRep__Jaco.ttm", "Jaco"),
        ("PyRep__XArm7.ttm", "xarm"),
        ("PyRep__UR5.ttm", "UR5"),
        ("PyRep__Sawyer.ttm", "Sawyer"),
    ];
    for (file, robot) in arms {
        let model = load_scene(&DiskFiles, &dir.join(file), &LoadOptions::default()).expect("loads");
        let mut sim = Sim::new(&model);
        let tip = sim.world.find(&format!("/{robot}_tip"), None, 0).expect("tip dummy");
        let start = sim.world.object(tip).expect("tip").world.translation.vector;
        let steps = (10.0 / model.settings.dt).round() as usize;
        let mut drift: f64 = 0.0;
        for _ in 0..steps {
            sim.step();
            let p = sim.world.object(tip).expect("tip").world.translation.vector;
            drift = drift.max((p - start).norm());
        }
        println!("{file}: tip drift over 10 s {:.3} mm", drift * 1e3);
        // The issue asks for 1 mm. With one solver pass per substep the Panda and the
        // XArm7 sagged 1.3 mm (their coupled motors converge slowly); imports use
        // COPPELIA_SOLVER_ITERATIONS passes.
        assert!(drift < 1e-3, "{file}: the tip moved {drift} m holding its pose");

        // The second joint of the chain (a shoulder or elbow) follows a new target.
        let joint = sim.world.find(&format!("/{robot}/joint{{1}}"), None, 0).or_else(|_| {
            sim.world
                .handles()
                .iter()
                .copied()
                .filter(|&h| sim.world.joint(h).is_ok_and(|j| j.mode == JointMode::Position))
                .nth(1)
                .ok_or(())
        });
        let joint = joint.unwrap_or_else(|_| panic!("{file}: a second position-controlled joint"));
        let q0 = sim.world.joint(joint).expect("joint").position;
        let target = q0 + 0.2;
        api::call(
            &mut sim,
            &CallContext::default(),
            "sim.setJointTargetPosition",
            &[Value::Int(joint), Value::Float(target)],
        )
        .expect("target set");
        for _ in 0..(3.0 / model.settings.dt).round() as usize {
            sim.step();
        }
        let q = sim.world.joint(joint).expect("joint").position;
        assert!((q - target).abs() < 2e-3, "{file}: joint at {q}, target {target}");
    }
}

/// A course's pendulum (a 5 kg cuboid on a free revolute joint), without its control
/// script and its floor: released 0.05 rad from hanging, it swings with the period of a physical
/// pendulum computed from the imported mass, inertia and geometry, within 1 %.
#[test]
fn a_pendulum_swings_with_the_period_its_geometry_gives() {
    let dir = coppelia_files();
    let name = "modulabs_c__pendulumn_1d_control.ttt";
    let Ok(bytes) = std::fs::read(dir.join(name)) else {
        println!("{name} not found in {}; skipped", dir.display());
        return;
    };
    let (mut model, _) = load_coppelia(&bytes, Path::new(name)).expect("imports");
    // Its script is Python, which gantry does not run; hanging, the cuboid rests on
    // the floor, which is taken out of its way.
    model.scripts.clear();
    for o in &mut model.objects {
        if let ObjectModelKind::Shape(floor) = &mut o.kind
            && o.alias == "Floor"
        {
            floor.respondable = false;
        }
    }
    let joint_index = model.objects.iter().position(|o| o.alias == "Joint").expect("Joint");
    let body_index = model.objects.iter().position(|o| o.alias == "Cuboid").expect("Cuboid");
    let ObjectModelKind::Shape(shape) = &model.objects[body_index].kind else {
        panic!("the cuboid is a shape")
    };
    let gantry_sim_core::scene::MassModel::Inertial { mass, com, inertia, .. } = shape.mass else {
        panic!("the file gives the cuboid's inertia")
    };
    assert_eq!(com, [0.0, 0.0, 0.0], "centre of mass at the shape's frame");
    let mut sim = Sim::new(&model);
    let (joint, body) = (joint_index as i64, body_index as i64);
    let g = model.settings.gravity[2].abs();
    let set = |sim: &mut Sim, q: f64| {
        api::call(
            sim,
            &CallContext::default(),
            "sim.setJointPosition",
            &[Value::Int(joint), Value::Float(q)],
        )
        .expect("joint placed");
    };
    // Hanging: the angle that puts the cuboid lowest (scanned, then refined).
    let z_at = |sim: &mut Sim, q: f64| {
        set(sim, q);
        sim.world.object(body).expect("body").world.translation.z
    };
    let mut hang = (0..360)
        .map(|k| -std::f64::consts::PI + k as f64 * std::f64::consts::PI / 180.0)
        .min_by(|&a, &b| z_at(&mut sim, a).total_cmp(&z_at(&mut sim, b)))
        .expect("angles");
    let mut step = 0.5_f64.to_radians();
    while step > 1e-9 {
        for cand in [hang - step, hang + step] {
            if z_at(&mut sim, cand) < z_at(&mut sim, hang) {
                hang = cand;
            }
        }
        step /= 2.0;
    }
    // The physical pendulum: I about the axis through the pivot, d from pivot to centre.
    set(&mut sim, hang);
    let jw = sim.world.object(joint).expect("joint").world;
    let bw = sim.world.object(body).expect("body").world;
    let axis = jw.rotation * nalgebra::Vector3::z();
    let r = bw.translation.vector - jw.translation.vector;
    let d = (r - axis * axis.dot(&r)).norm();
    let tensor = nalgebra::Matrix3::new(
        inertia[0], inertia[1], inertia[2], inertia[1], inertia[3], inertia[4], inertia[2], inertia[4], inertia[5],
    );
    let local_axis = bw.rotation.inverse() * axis;
    let i_pivot = local_axis.dot(&(tensor * local_axis)) + mass * d * d;
    let expected = 2.0 * std::f64::consts::PI * (i_pivot / (mass * g * d)).sqrt();

    let mut sim = Sim::new(&model);
    set(&mut sim, hang + 0.05);
    let dt = model.settings.dt;
    let mut crossings = Vec::new();
    let mut prev = 0.05;
    for k in 1..=(20.0 / dt) as usize {
        sim.step();
        let q = wrap(sim.world.joint(joint).expect("joint").position - hang);
        if prev > 0.0 && q <= 0.0 {
            // Linear interpolation of the downward zero crossing.
            crossings.push((k as f64 - 1.0 + prev / (prev - q)) * dt);
        }
        prev = q;
    }
    assert!(crossings.len() >= 3, "it swings: {crossings:?}");
    let periods = crossings.len() - 1;
    let measured = (crossings[periods] - crossings[0]) / periods as f64;
    println!("pendulum: period {measured:.4} s, expected {expected:.4} s (d = {d:.4} m)");
    assert!(
        (measured - expected).abs() / expected < 0.01,
        "period {measured} s, the geometry gives {expected} s"
    );
}

/// An angle in (-π, π].
fn wrap(a: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    let w = a.rem_euclid(tau);
    if w > std::f64::consts::PI { w - tau } else { w }
}

/// PyRep's TurtleBot 2 model (a `.ttm`, on gantry's floor): its two wheel motors asked
/// for 6 rad/s drive it straight ahead.
#[test]
fn a_turtlebot_drives_when_its_wheels_turn() {
    let dir = coppelia_files();
    let file = dir.join("PyRep__turtlebot.ttm");
    if !file.is_file() {
        println!("{} not found; skipped", file.display());
        return;
    }
    let model = load_scene(&DiskFiles, &file, &LoadOptions::default()).expect("loads");
    let mut sim = Sim::new(&model);
    let base = sim.world.find("/turtlebot", None, 0).expect("base");
    let left = sim.world.find("/turtlebot_m_joint1", None, 0).expect("left motor");
    let right = sim.world.find("/turtlebot_m_joint2", None, 0).expect("right motor");
    // Settle on the floor first (the model is saved a hair above it).
    for _ in 0..10 {
        sim.step();
    }
    let start = sim.world.object(base).expect("base").world;
    let speed = 6.0;
    for motor in [left, right] {
        api::call(
            &mut sim,
            &CallContext::default(),
            "sim.setJointTargetVelocity",
            &[Value::Int(motor), Value::Float(speed)],
        )
        .expect("velocity set");
    }
    let seconds = 3.0;
    for _ in 0..(seconds / model.settings.dt).round() as usize {
        sim.step();
    }
    let end = sim.world.object(base).expect("base").world;
    let moved = end.translation.vector - start.translation.vector;
    let forward = start.rotation * nalgebra::Vector3::x();
    let along = moved.dot(&forward);
    let across = (moved - forward * along).xy().norm();
    let turned = (start.rotation.inverse() * end.rotation).angle();
    println!(
        "turtlebot: {along:.3} m ahead, {across:.3} m aside, turned {:.1} deg in {seconds} s",
        turned.to_degrees()
    );
    // Measured 0.32 m: the motors' own 0.245 N·m limit holds the wheels at 1.8 and
    // 2.7 rad/s against the casters and bumpers (35 mm wheels at 6 rad/s would go
    // 0.63 m); gantry's floor and CoppeliaSim's contact model differ there.
    assert!(along.abs() > 0.25, "it drove {along} m");
    assert!(
        across < 0.1 * along.abs() && turned < 0.2,
        "straight: {across} m aside, {turned} rad"
    );
}

/// The paper's `Blue Robot.ttt` and gantry's own model of the same arm
/// (`assets/scenes/fk_arm.toml`, an IRB 140 as the paper's): for the same joint angles,
/// the tip in the base's frame is in the same place.
#[test]
fn blue_robot_and_the_fk_arm_put_the_tip_in_the_same_place() {
    let dir = coppelia_files();
    let file = dir.join("paper__Blue_Robot.ttt");
    if !file.is_file() {
        println!("{} not found; skipped", file.display());
        return;
    }
    let mut blue = load_scene(&DiskFiles, &file, &LoadOptions::default()).expect("loads");
    blue.scripts.clear();
    let arm_path = repo("assets/scenes/fk_arm.toml");
    let mut arm = load_scene(&DiskFiles, &arm_path, &LoadOptions::default()).expect("loads");
    arm.scripts.clear();
    let mut blue = Sim::new(&blue);
    let mut arm = Sim::new(&arm);
    let find = |s: &Sim, p: &str| s.world.find(p, None, 0).unwrap_or_else(|_| panic!("{p}"));
    let blue_joints: Vec<i64> = (1..=6).map(|i| find(&blue, &format!("/RobotB_joint{i}"))).collect();
    let arm_joints: Vec<i64> = (1..=6).map(|i| find(&arm, &format!("/arm6/joint{i}"))).collect();
    // Each tip in the frame of the arm's mounting plane: Blue Robot's first joint sits
    // on it (its base shape has its frame at its centre, as CoppeliaSim puts them), and
    // the URDF's base link is on it (its first joint is 0.1 m up).
    let (blue_base, blue_tip) = (blue_joints[0], find(&blue, "/RobotB_tip"));
    let (arm_base, arm_tip) = (find(&arm, "/arm6"), find(&arm, "/tip"));
    let configs: [[f64; 6]; 4] = [
        [0.0, 0.0, 0.0, 0.0, -std::f64::consts::FRAC_PI_2, 0.0],
        [std::f64::consts::FRAC_PI_4, 0.0, -0.5, 0.0, 0.0, 0.0],
        [-0.4, 0.3, 0.2, 0.7, -0.9, 1.1],
        [1.2, -0.6, 0.8, -1.5, 0.6, -0.3],
    ];
    let set = |s: &mut Sim, joints: &[i64], q: &[f64; 6]| {
        for (&j, &v) in joints.iter().zip(q) {
            api::call(
                s,
                &CallContext::default(),
                "sim.setJointPosition",
                &[Value::Int(j), Value::Float(v)],
            )
            .expect("joint set");
        }
    };
    for q in &configs {
        set(&mut blue, &blue_joints, q);
        set(&mut arm, &arm_joints, q);
        let rel = |s: &Sim, base: i64, tip: i64| {
            s.world.object(base).expect("base").world.inverse() * s.world.object(tip).expect("tip").world
        };
        let (b, a) = (rel(&blue, blue_base, blue_tip), rel(&arm, arm_base, arm_tip));
        let d = (b.translation.vector - a.translation.vector).norm();
        println!("q = {q:?}: tips {d:.2e} m apart");
        // Measured 0.40 to 0.56 mm, not 1e-6 m: the file's arm is CoppeliaSim's model,
        // not the datasheet's to a tenth of a millimetre (at zero its tip is 0.39 mm
        // lower and 48 µm off the arm's plane); gantry's URDF uses the datasheet lengths.
        assert!(d < 1e-3, "q = {q:?}: the tips are {d} m apart");
    }
}

/// Thymio's ground sensors are pyramid volumes looking down: on the floor `gantry run`
/// gives a model, each sees the floor straight below it, at its own height.
#[test]
fn thymio_ground_sensors_see_the_floor_below_them() {
    let file = coppelia_files().join("coppeliasi__thymio.ttm");
    if !file.is_file() {
        println!("{} not found; skipped", file.display());
        return;
    }
    let mut model = load_scene(&DiskFiles, &file, &LoadOptions::default()).expect("loads");
    // gantry's floor is not detectable (as CoppeliaSim's default floor); make it a mat the
    // ground sensors can see, as a line-following course would be.
    let ObjectModelKind::Shape(floor) = &mut model.objects[0].kind else {
        panic!("the floor comes first");
    };
    floor.detectable = true;
    let pyramids: Vec<usize> = (0..model.objects.len())
        .filter(|&k| {
            matches!(
                model.objects[k].kind,
                ObjectModelKind::ProximitySensor(gantry_sim_core::scene::ProximityModel::Pyramid { .. })
            )
        })
        .collect();
    assert!(pyramids.len() >= 7, "{} pyramid sensors", pyramids.len());
    let mut sim = Sim::new(&model);
    for _ in 0..20 {
        sim.step();
    }
    let mut ground = 0;
    for &k in &pyramids {
        let alias = model.objects[k].alias.clone();
        let h = k as i64;
        let ctx = CallContext::default();
        api::call(&mut sim, &ctx, "sim.handleProximitySensor", &[Value::Int(h)]).expect("handled");
        let read = api::call(&mut sim, &ctx, "sim.readProximitySensor", &[Value::Int(h)]).expect("read");
        let world = sim.world.object(h as _).expect("sensor").world;
        let look = world.rotation * nalgebra::Vector3::z();
        println!("{alias}: looks {look:.3?}: {:?}", read.get(..2));
        if alias.starts_with("Ground") {
            ground += 1;
            assert!(look.z < -0.99, "{alias} looks down");
            let height = world.translation.vector.z;
            let Some(Value::Float(distance)) = read.get(1) else {
                panic!("{alias} sees nothing {height} m above the floor: {read:?}");
            };
            // The floor's top face is at z = 0; the nearest floor point in the volume is
            // straight below (or 1 mm off it while the robot settles).
            assert!(
                (distance - height / -look.z).abs() < 1.0e-3,
                "{alias}: {distance} m at {height} m"
            );
        }
    }
    assert_eq!(ground, 2, "GroundLeft and GroundRight");

    // A wall 3 cm ahead of the centre sensor, facing it: seen at 3 cm.
    let centre = sim.world.find("/ProximityCenter", None, 0).expect("centre sensor");
    let pose = sim.world.object(centre).expect("sensor").world;
    let ahead = pose.rotation * nalgebra::Vector3::z();
    let ctx = CallContext::default();
    let wall = api::call(
        &mut sim,
        &ctx,
        "sim.createPrimitiveShape",
        &[
            Value::Int(3),
            Value::Array(vec![Value::Float(0.2), Value::Float(0.2), Value::Float(0.01)]),
        ],
    )
    .expect("wall");
    let centre_of_wall = pose.translation.vector + ahead * 0.035;
    let tilt = nalgebra::UnitQuaternion::rotation_between(&nalgebra::Vector3::z(), &ahead).expect("rotation");
    let matrix = gantry_sim_core::math::pose_to_matrix12(&nalgebra::Isometry3::from_parts(centre_of_wall.into(), tilt));
    api::call(
        &mut sim,
        &ctx,
        "sim.setObjectMatrix",
        &[
            wall[0].clone(),
            Value::Int(-1),
            Value::Array(matrix.map(Value::Float).to_vec()),
        ],
    )
    .expect("placed");
    let h = Value::Int(centre as i64);
    api::call(&mut sim, &ctx, "sim.handleProximitySensor", std::slice::from_ref(&h)).expect("handled");
    let read = api::call(&mut sim, &ctx, "sim.readProximitySensor", &[h]).expect("read");
    let Some(Value::Float(distance)) = read.get(1) else {
        panic!("the centre sensor misses the wall: {read:?}");
    };
    assert!((distance - 0.03).abs() < 1.0e-5, "wall at {distance} m");
}

/// 4.7+ files keep referenced handles (`sim.setReferencedHandles`): the UR3 course scene's
/// IK script finds its base, tip and target through them.
#[test]
fn referenced_handles_are_imported() {
    let file = coppelia_files().join("Libro-Copp__cap20_abrir_cerrar_pinza.ttt");
    if !file.is_file() {
        println!("{} not found; skipped", file.display());
        return;
    }
    let model = load_scene(&DiskFiles, &file, &LoadOptions::default()).expect("loads");
    let mut sim = Sim::new(&model);
    let r = model
        .referenced_handles
        .iter()
        .map(|r| {
            let targets: Vec<&str> = r.targets.iter().map(|&t| model.objects[t].alias.as_str()).collect();
            (model.objects[r.object].alias.as_str(), r.tag.as_str(), targets)
        })
        .collect::<Vec<_>>();
    // The script object `IK` (4.7+) names the arm's base and its IK tip and target dummies.
    assert_eq!(
        r,
        [
            ("IK", "ik.base", vec!["UR3"]),
            ("IK", "ik.target", vec!["UR3_target"]),
            ("IK", "ik.tip", vec!["UR3_tip"]),
        ]
    );
    let holder = model.referenced_handles[0].object as i64;
    let ctx = CallContext::default();
    for tag in ["ik.base", "ik.tip", "ik.target"] {
        let got = api::call(
            &mut sim,
            &ctx,
            "sim.getReferencedHandle",
            &[Value::Int(holder), Value::Str(tag.into())],
        )
        .expect("a handle");
        let Value::Int(h) = got[0] else { panic!("{got:?}") };
        assert!(h >= 0, "{tag}: {got:?}");
    }
}

/// Objects keep their extension strings (`Rst`), and `sim.getExtensionString` serves
/// them whole or by key: the Sawyer's cameras carry POV-Ray settings.
#[test]
fn extension_strings_are_imported_and_served() {
    let file = coppelia_files().join("PyRep__Sawyer.ttm");
    if !file.is_file() {
        println!("{} not found; skipped", file.display());
        return;
    }
    let model = load_scene(&DiskFiles, &file, &LoadOptions::default()).expect("loads");
    let camera = model
        .objects
        .iter()
        .position(|o| o.alias == "Sawyer_wristCamera")
        .expect("the wrist camera");
    let whole = "povray {focalBlur {false} focalDist {2.000} aperture {0.050} blurSamples {10}}";
    assert_eq!(model.objects[camera].extension, whole);
    let with_strings = model.objects.iter().filter(|o| !o.extension.is_empty()).count();
    assert_eq!(with_strings, 2, "the two cameras, nothing else");

    let mut sim = Sim::new(&model);
    let ctx = CallContext::default();
    let mut get = |h: i64, key: Value| {
        let got = api::call(
            &mut sim,
            &ctx,
            "sim.getExtensionString",
            &[Value::Int(h), Value::Int(-1), key],
        )
        .expect("a string");
        let [Value::Str(s)] = &got[..] else { panic!("{got:?}") };
        s.clone()
    };
    let h = camera as i64;
    assert_eq!(get(h, Value::Nil), whole);
    assert_eq!(get(h, Value::Str(String::new())), whole);
    assert_eq!(get(h, Value::Str("focalDist@povray".into())), "2.000");
    assert_eq!(
        get(h, Value::Str("povray".into())).split_whitespace().next(),
        Some("focalBlur")
    );
    assert_eq!(get(h, Value::Str("nothing@povray".into())), "");
    // The environment's string is not kept; an object without one reads empty.
    assert_eq!(get(-1, Value::Nil), "");
    assert_eq!(get(0, Value::Nil), "");
    let bad = api::call(
        &mut sim,
        &ctx,
        "sim.getExtensionString",
        &[Value::Int(9999), Value::Int(-1)],
    );
    assert!(bad.is_err(), "no such object: {bad:?}");
}

/// Collections (`GRP`) are imported: PyRep's arms find `<Name>_arm` with
/// `sim.getCollectionHandle`, and the Panda's holds the tree below its base.
#[test]
fn collections_are_imported() {
    let file = coppelia_files().join("PyRep__Panda.ttm");
    if !file.is_file() {
        println!("{} not found; skipped", file.display());
        return;
    }
    let model = load_scene(&DiskFiles, &file, &LoadOptions::default()).expect("loads");
    let names: Vec<&str> = model.collections.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["Panda_arm"]);
    let base = model.objects.iter().position(|o| o.alias == "Panda").expect("the base");
    let mut sim = Sim::new(&model);
    let ctx = CallContext::default();
    let got = api::call(
        &mut sim,
        &ctx,
        "sim.getCollectionHandle",
        &[Value::Str("Panda_arm".into())],
    )
    .expect("found");
    let Value::Int(h) = got[0] else { panic!("{got:?}") };
    let got = api::call(&mut sim, &ctx, "sim.getCollectionObjects", &[Value::Int(h)]).expect("objects");
    let Value::Array(objects) = &got[0] else {
        panic!("{got:?}")
    };
    let objects: Vec<i64> = objects.iter().filter_map(Value::as_i64).collect();
    // The base and everything below it: every object of the model except the floor the
    // loader puts a model on, and whatever else hangs at the root.
    let mut tree = vec![base];
    let mut k = 0;
    while k < tree.len() {
        let p = tree[k];
        tree.extend((0..model.objects.len()).filter(|&c| model.objects[c].parent == Some(p)));
        k += 1;
    }
    tree.sort_unstable();
    let tree: Vec<i64> = tree.into_iter().map(|i| i as i64).collect();
    assert_eq!(objects, tree);
    assert!(objects.len() > 20, "{} objects", objects.len());
    let missing = api::call(
        &mut sim,
        &ctx,
        "sim.getCollectionHandle",
        &[Value::Str("Panda_ik@silentError".into())],
    );
    assert_eq!(missing.expect("silent"), [Value::Int(-1)]);
}
