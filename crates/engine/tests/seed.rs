//! Issue 4's acceptance tests: the seed lab sheet's BubbleRob controller and vision
//! script run verbatim (`scripts/bubble_rob.lua`, `scripts/edge_detect.lua`) and do what
//! the tutorial shows: a distance segment, a trace, a clearance graph, a speed slider,
//! and an edge image.

use crate::util;
use util::Drive;

use gantry_engine::Engine;
use gantry_lua::{ScriptLimits, ScriptState};
use gantry_sim_core::Value;
use gantry_sim_core::math::Pose;
use gantry_test_support::{floats, int, ints, load, repo};
use util::find;

fn bubble_rob() -> Engine {
    let model = load(&repo("assets/scenes/bubble_rob.toml"));
    util::engine(model, ScriptLimits::default()).expect("builds")
}

/// Calls an API function as a remote client would.
fn call(sim: &mut Engine, name: &str, args: &[Value]) -> Vec<Value> {
    sim.call(name, args).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn drawing(sim: &mut Engine, handle: i64) -> (i64, Vec<f64>) {
    let r = call(sim, "getDrawingObjectItems", &[Value::Int(handle)]);
    (int(&r[0]), floats(&r[3]))
}

#[test]
fn seed_controller_draws_plots_and_stays_healthy() {
    let mut sim = bubble_rob();
    for _ in 0..300 {
        sim.step();
    }
    for (path, _, state) in sim.scripts() {
        assert_eq!(state, ScriptState::Running, "{}", path.display());
    }
    // The seed creates the green segment first, then the yellow trace.
    let core = sim.core();
    let handles: Vec<i64> = core.drawings.iter_world(&core.world).map(|d| d.handle).collect();
    drop(core);
    assert_eq!(handles.len(), 2, "two drawing objects");
    let (kind, segment) = drawing(&mut sim, handles[0]);
    assert_eq!(kind, 1, "sim.drawing_lines");
    assert_eq!(segment.len(), 6, "one segment (max 1 item) of two points");
    let (kind, trace) = drawing(&mut sim, handles[1]);
    assert_eq!(kind & 0xff, 8, "sim.drawing_linestrip");
    assert_eq!(trace.len(), 200 * 3, "the cyclic trace keeps its 200 newest points");
    // The last trace point is where the robot was at the last sensing phase.
    let rob = find(&sim, "/bubbleRob");
    let p = sim.world().object(rob).expect("robot").world.translation.vector;
    let last = &trace[trace.len() - 3..];
    assert!(
        (last[0] - p.x).abs() < 0.02 && (last[1] - p.y).abs() < 0.02,
        "{last:?} vs {p:?}"
    );
    // The clearance stream has a value per step, and it is the segment's length.
    let graph = find(&sim, "/bubbleRob/graph");
    let stream = {
        let w = sim.core();
        let s = w.graphs.streams().next().expect("the script added a stream");
        assert_eq!(s.label(), "bubbleRob clearance [m]");
        s.id()
    };
    let r = call(
        &mut sim,
        "getGraphStreamValues",
        &[Value::Int(graph), Value::Int(stream)],
    );
    let values = floats(&r[1]);
    assert!(values.len() >= 290, "{} clearance samples", values.len());
    let len =
        ((segment[3] - segment[0]).powi(2) + (segment[4] - segment[1]).powi(2) + (segment[5] - segment[2]).powi(2))
            .sqrt();
    assert!(
        (values[values.len() - 1] - len).abs() < 1e-9,
        "clearance {} vs segment {len}",
        values[values.len() - 1]
    );
}

#[test]
fn moving_the_speed_slider_changes_the_wheel_speed() {
    let mut sim = bubble_rob();
    sim.step();
    let left = find(&sim, "/bubbleRob/leftMotor");
    let before = sim.world().joint(left).expect("motor").target_velocity;
    assert!(
        (before - 175f64.to_radians()).abs() < 1e-9,
        "starts at the middle speed: {before}"
    );
    let ui = sim.core().uis.iter().next().expect("the script created its UI").handle;
    assert_eq!(
        int(&call(&mut sim, "simUI.getSliderValue", &[Value::Int(ui), Value::Int(1)])[0]),
        50
    );
    // A user moves the slider to 4: the seed maps it through `newVal/10` (sic).
    call(
        &mut sim,
        "simUI.interact",
        &[Value::Int(ui), Value::Int(1), Value::Int(4)],
    );
    sim.step();
    let after = sim.world().joint(left).expect("motor").target_velocity.abs();
    let (lo, hi) = (50f64.to_radians(), 300f64.to_radians());
    let expected = lo + (hi - lo) * 4.0 / 10.0;
    assert!(
        (after - expected).abs() < 1e-9 || (after - expected / 2.0).abs() < 1e-9,
        "{after} vs {expected}"
    );
    assert!((after - before.abs()).abs() > 0.1, "the wheel speed changed");
}

#[test]
fn vision_script_produces_an_edge_image_of_an_obstacle() {
    let mut sim = bubble_rob();
    sim.step();
    // Put an obstacle 0.35 m in front of the camera, centred on its axis.
    let cam = find(&sim, "/bubbleRob/visionSensor");
    let obstacle = find(&sim, "/obstacle");
    let cam_pose = sim.world().object(cam).expect("camera").world;
    let ahead = (cam_pose * Pose::translation(0.0, 0.0, 0.35)).translation.vector;
    let pose = Pose::translation(ahead.x, ahead.y, 0.1);
    sim.world_mut().set_world_pose(obstacle, pose).expect("moves");
    sim.step();
    let r = call(&mut sim, "getVisionSensorImg", &[Value::Int(cam)]);
    let Value::Bytes(img) = &r[0] else {
        panic!("image bytes")
    };
    let res = ints(&r[1]);
    assert_eq!(res, [256, 256]);
    let px = |x: usize, y: usize| img[(y * 256 + x) * 3];
    // The middle row crosses the obstacle: its two silhouette edges are white, its
    // uniform inside black. The cylinder spans ±atan(0.05/0.35) = ±8.1° of a 60° view:
    // about ±35 px around the centre column.
    let row = 128;
    let white: Vec<usize> = (2..254).filter(|&x| px(x, row) > 200).collect();
    let near = |c: f64| white.iter().any(|&x| (x as f64 - c).abs() <= 5.0);
    assert!(
        near(128.0 - 34.6) && near(128.0 + 34.6),
        "edges at the silhouette, white columns {white:?}"
    );
    assert!(
        (110..146).all(|x| px(x, row) < 50),
        "the obstacle's inside has no edges"
    );
    let white_total = img.chunks(3).filter(|p| p[0] > 200).count();
    assert!(
        white_total > 100 && white_total < 256 * 256 / 2,
        "{white_total} edge pixels"
    );
}
