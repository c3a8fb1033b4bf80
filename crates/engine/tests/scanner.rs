//! The bundled scanners scene (`assets/scenes/scanners.toml`) run with its Lua scripts,
//! written as CoppeliaSim's Hokuyo and Velodyne models are: each sensor's
//! `sysCall_vision` turns its depth map into points with `simVision`, and each scanner's
//! `sysCall_sensing` gathers them from `sim.readVisionSensor` and publishes them. The
//! published ranges must agree with `sim.castRays` along the same beams (itself checked
//! against analytic distances in crates/sim-core/tests/scanner.rs).

use crate::util;
use util::Drive;

use gantry_engine::Engine;
use gantry_lua::{ScriptLimits, ScriptState};
use gantry_sim_core::math::Vec3;
use gantry_sim_core::scene::{LoadOptions, load_bundled};
use gantry_sim_core::{Handle, Value};
use gantry_test_support::{floats, ints, load, repo};
use util::find;

/// The pillar's radius and axis (x, y) in scanners.toml, and how far inside the true
/// cylinder its 32-sided drawing lies, m.
const PILLAR: (f64, [f64; 2]) = (0.2, [-0.8, -1.6]);
const PILLAR_SAGITTA: f64 = 0.2 * (1.0 - 0.995_184_726_672_196_9);

/// The points a scanner's script published: x, y, z in its frame.
fn published(sim: &mut Engine, signal: &str) -> Vec<Vec3> {
    let reply = sim
        .call("sim.getStringSignal", &[Value::Str(signal.into())])
        .unwrap_or_else(|e| panic!("{signal}: {e}"));
    let bytes = match &reply[0] {
        Value::Bytes(b) => b.clone(),
        Value::Str(s) => s.as_bytes().to_vec(),
        other => panic!("{signal} was not published: {other:?}"),
    };
    bytes
        .chunks_exact(12)
        .map(|c| {
            let f = |k: usize| f64::from(f32::from_le_bytes([c[k], c[k + 1], c[k + 2], c[k + 3]]));
            Vec3::new(f(0), f(4), f(8))
        })
        .collect()
}

/// `sim.castRays` from `scanner` towards each point (in its frame), passing through the
/// scanner's own model: the distances and the shapes hit.
fn rays(sim: &mut Engine, scanner: Handle, points: &[Vec3], max: f64) -> (Vec<f64>, Vec<i64>) {
    let dirs = Value::Array(points.iter().flat_map(|p| [p.x, p.y, p.z]).map(Value::Float).collect());
    let reply = sim
        .call(
            "sim.castRays",
            &[Value::Int(scanner), dirs, Value::Float(max), Value::Int(scanner)],
        )
        .expect("castRays");
    (floats(&reply[0]), ints(&reply[1]))
}

#[test]
fn the_scanner_scripts_publish_the_ranges_the_rays_measure() {
    // The scene as compiled into gantry (`gantry.Client("scanners")`), which must be the file.
    let bundled = load_bundled("scanners", &LoadOptions::default())
        .expect("a bundled scene named scanners")
        .expect("it loads");
    let file = load(&repo("assets/scenes/scanners.toml"));
    assert_eq!(bundled.objects.len(), file.objects.len());
    let sources =
        |m: &gantry_sim_core::scene::SceneModel| m.scripts.iter().map(|s| s.source.clone()).collect::<Vec<_>>();
    assert_eq!(sources(&bundled), sources(&file));
    let mut sim = util::engine(bundled, ScriptLimits::default()).expect("the scanners scene builds");
    sim.start();
    for _ in 0..3 {
        sim.step();
    }
    for (path, _, state) in sim.scripts() {
        assert_eq!(state, ScriptState::Running, "{}", path.display());
    }
    let pillar = find(&sim, "/pillar");
    let world = |sim: &Engine, h: Handle| sim.world().object(h).expect("object").world;

    // The 2-D scanner: every published point within 1 mm of the ray cast, except on the
    // pillar, whose drawing is a prism inside the cylinder the rays hit.
    let hokuyo = find(&sim, "/hokuyo");
    let points = published(&mut sim, "hokuyo_points");
    assert!(points.len() > 500, "{} points", points.len());
    let (distances, handles) = rays(&mut sim, hokuyo, &points, 5.0);
    let pose = world(&sim, hokuyo);
    for (k, p) in points.iter().enumerate() {
        if handles[k] == pillar {
            let w = pose.transform_point(&(*p).into());
            let radial = ((w.x - PILLAR.1[0]).powi(2) + (w.y - PILLAR.1[1]).powi(2)).sqrt();
            assert!(
                (radial - PILLAR.0).abs() <= PILLAR_SAGITTA + 1e-4,
                "point {k}: {radial} m from the axis"
            );
        } else {
            assert!(
                (p.norm() - distances[k]).abs() < 1e-3,
                "point {k}: {} vs ray {}",
                p.norm(),
                distances[k]
            );
        }
    }

    // The 3-D scanner: four sensors, 1,800 azimuths of 16 beams; those returning
    // (beams over the walls and past the floor's edge do not) agree with the rays but
    // where a beam passes within a pixel of a silhouette or a corner (the pillar's and
    // the block's edges, their feet on the floor): there the depth map holds two
    // surfaces, and a point read between them lies up to a pixel's footprint off
    // (1.7 % of the points in this scene; crates/sim-core/tests/scanner.rs bounds them).
    let velodyne = find(&sim, "/velodyne");
    let points = published(&mut sim, "velodyne_points");
    assert!(points.len() > 10_000, "{} points", points.len());
    let (distances, handles) = rays(&mut sim, velodyne, &points, 10.0);
    let agree = points
        .iter()
        .zip(&distances)
        .zip(&handles)
        .filter(|((p, d), h)| (p.norm() - **d).abs() < if **h == pillar { 3e-3 } else { 1e-3 })
        .count();
    assert!(
        agree * 100 >= 98 * points.len(),
        "{agree} of {} points agree",
        points.len()
    );
}
