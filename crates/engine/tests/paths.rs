//! Paths from scripts: a V-REP 3.x threaded script that builds a path and has a dummy
//! follow it with `simFollowPath` (issue 34), V-REP 3's `sim.moveToPosition`, the
//! blocking calls refused outside threads, and a CoppeliaSim 4.3+ script reading a
//! created path's points from its custom data to interpolate along it.

use crate::util;
use util::Drive;

use gantry_sim_core::Value;
use gantry_sim_core::sim::SimulationState;
use gantry_test_support::{assert_contains, floats, num};
use util::{Scene, assert_running, int32_signal, script_error, world_position};

/// One dummy carrying the script `mover.lua`, at dt = 0.05 s.
const SCENE: &str = r#"
[simulation]
dt = 0.05

[[object]]
name = "Dummy"
kind = "dummy"
script = "mover.lua"
"#;

/// A V-REP 3 threaded script, top-level code in its own thread, as V-REP 3.x scenes
/// carry it: an L-shaped path, (0,0,0) to (1,0,0) to (1,1,0), its last control point
/// turned a quarter about z, built with V-REP 3's path functions (11 values per control
/// point), then followed from its start at 0.5 m/s, accelerating at 1 m/s^2.
const FOLLOWER_3_X: &str = r#"
simSetThreadAutomaticSwitch(false)
local obj=simGetObjectHandle('Dummy')
local path=simCreatePath(-1,nil,nil,nil)
local pts={0,0,0, 0,0,0, 1,1,0,0,0,
           1,0,0, 0,0,0, 1,1,0,0,0,
           1,1,0, 0,0,math.pi/2, 1,1,0,0,0}
simInsertPathCtrlPoints(path,0,0,3,pts)
simSetIntegerSignal('length_mm',math.floor(simGetPathLength(path)*1000+0.5))
local left=simFollowPath(obj,path,3,0,0.5,1)
simSetIntegerSignal('done',1)
simSetFloatSignal('left',left)
"#;

#[test]
fn a_v_rep_3_threaded_script_follows_a_path_with_follow_path() {
    let (script, r) = gantry_sim_core::scene::modernize_old_script(FOLLOWER_3_X, true);
    assert!(r.thread_body, "{r:?}");
    let mut sc = Scene::new(
        "paths-follow",
        SCENE,
        &[("mover.lua", &script)],
        gantry_lua::ScriptLimits::default(),
    );
    let dummy = sc.find("/Dummy");
    sc.sim.start();
    // 2 m at 0.5 m/s after 0.5 s (0.125 m) to reach that speed; the end is reached at
    // speed, as V-REP's path handling does: 4.25 s, 85 steps (86 when the steps' sum
    // rounds below), then one more for the script to go on and signal.
    let mut trace = Vec::new();
    for _ in 0..100 {
        sc.sim.step();
        trace.push(world_position(&sc.sim, dummy));
        if int32_signal(&mut sc.sim, "done") == Some(1) {
            break;
        }
    }
    assert_running(&sc.sim, "mover.lua");
    assert_eq!(int32_signal(&mut sc.sim, "length_mm"), Some(2000));
    assert_eq!(int32_signal(&mut sc.sim, "done"), Some(1), "followPath returned");
    let n = trace.len();
    assert!((86..=87).contains(&n), "{n} steps");
    // It ends at the path's end, turned as the last control point.
    let end = trace[n - 1];
    assert!((end[0] - 1.0).abs() < 1e-9 && (end[1] - 1.0).abs() < 1e-9, "{end:?}");
    let e = sc.remote("sim.getObjectOrientation", &[Value::Int(dummy), Value::Int(-1)]);
    let gamma = floats(&e[0])[2];
    assert!((gamma - std::f64::consts::FRAC_PI_2).abs() < 1e-9, "{e:?}");
    // Every step on the L, moving forward along it, through both legs.
    let along = |p: [f64; 3]| if p[1].abs() < 1e-9 { p[0] } else { 1.0 + p[1] };
    for p in &trace {
        let on_first = p[1].abs() < 1e-9 && (-1e-9..=1.0 + 1e-9).contains(&p[0]);
        let on_second = (p[0] - 1.0).abs() < 1e-9 && (-1e-9..=1.0 + 1e-9).contains(&p[1]);
        assert!(on_first || on_second, "off the path: {p:?}");
        assert!(p[2].abs() < 1e-9);
    }
    assert!(trace.windows(2).all(|w| along(w[1]) >= along(w[0]) - 1e-12), "forward");
    assert!(trace.iter().any(|p| p[1].abs() < 1e-9 && p[0] > 0.3 && p[0] < 0.7));
    assert!(
        trace
            .iter()
            .any(|p| (p[0] - 1.0).abs() < 1e-9 && p[1] > 0.3 && p[1] < 0.7)
    );
    // Accelerating at first: 0.5 * 1 * 0.05^2 after one step, then faster.
    assert!((trace[0][0] - 0.00125).abs() < 1e-9, "{:?}", trace[0]);
    let left = sc.remote("sim.getFloatSignal", &[Value::from("left")]);
    let left = num(&left[0]);
    assert!((0.0..0.05).contains(&left), "time left in the last step: {left}");
}

/// CoppeliaSim 4.x's threaded form with V-REP 3's straight move: to (1, 2, 0) at 1 m/s
/// without acceleration limit, then a quarter turn about z at 1 rad/s with only the
/// orientation given (V-REP's `{method, angleToLinearCoeff}`: the angle counts 1 m per
/// radian).
const MOVER: &str = r#"
function sysCall_thread()
    local obj = sim.getObjectHandle('Dummy')
    local t0 = sim.getSimulationTime()
    sim.moveToPosition(obj, -1, {1, 2, 0}, nil, 1, nil)
    sim.setFloatSignal('moved', sim.getSimulationTime() - t0)
    sim.moveToPosition(obj, -1, nil, {0, 0, math.pi / 2}, 1, nil, {sim.distcalcmethod_dac, 1})
    sim.setFloatSignal('turned', sim.getSimulationTime() - t0)
    sim.setInt32Signal('done', 1)
end
"#;

#[test]
fn move_to_position_moves_straight_then_turns() {
    let mut sc = Scene::new(
        "paths-move",
        SCENE,
        &[("mover.lua", MOVER)],
        gantry_lua::ScriptLimits::default(),
    );
    let dummy = sc.find("/Dummy");
    sc.sim.start();
    let mut trace = Vec::new();
    for _ in 0..200 {
        sc.sim.step();
        trace.push(world_position(&sc.sim, dummy));
        if int32_signal(&mut sc.sim, "done") == Some(1) {
            break;
        }
    }
    assert_running(&sc.sim, "mover.lua");
    assert_eq!(int32_signal(&mut sc.sim, "done"), Some(1));
    // sqrt(5) m at 1 m/s: 45 steps of 0.05 s; a quarter turn at 1 rad/s: 32 steps more.
    let moved = num(&sc.remote("sim.getFloatSignal", &[Value::from("moved")])[0]);
    assert!((moved - 2.25).abs() < 1e-9, "{moved}");
    let turned = num(&sc.remote("sim.getFloatSignal", &[Value::from("turned")])[0]);
    assert!((turned - 2.25 - 1.6).abs() < 1e-9, "{turned}");
    // On the straight line from the origin, at 0.05 m a step.
    for p in &trace {
        assert!((p[1] - 2.0 * p[0]).abs() < 1e-9 && p[2].abs() < 1e-12, "{p:?}");
    }
    let d0 = (trace[0][0].powi(2) + trace[0][1].powi(2)).sqrt();
    assert!((d0 - 0.05).abs() < 1e-9, "{d0}");
    let end = world_position(&sc.sim, dummy);
    assert!((end[0] - 1.0).abs() < 1e-9 && (end[1] - 2.0).abs() < 1e-9, "{end:?}");
    let e = sc.remote("sim.getObjectOrientation", &[Value::Int(dummy), Value::Int(-1)]);
    assert!((floats(&e[0])[2] - std::f64::consts::FRAC_PI_2).abs() < 1e-9, "{e:?}");
}

#[test]
fn the_blocking_path_motions_need_a_thread() {
    let script = r#"
function sysCall_init()
    local obj = sim.getObjectHandle('Dummy')
    local path = sim.createPath({0, 0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 0, 1})
    sim.followPath(obj, path, 3, 0, 1, 1)
end
"#;
    let mut sc = Scene::new(
        "paths-unthreaded",
        SCENE,
        &[("mover.lua", script)],
        gantry_lua::ScriptLimits::default(),
    );
    sc.sim.start();
    let e = script_error(&sc.sim, "mover.lua");
    assert_contains(&e, &["followPath", "threaded script", "mover.lua:5"]);

    let bad = r#"
function sysCall_thread()
    local obj = sim.getObjectHandle('Dummy')
    local ok, e = pcall(sim.moveToPosition, obj, -1, {1, 0, 0}, nil, 0, nil)
    sim.setStringSignal('e', e)
end
"#;
    let mut sc = Scene::new(
        "paths-bad-velocity",
        SCENE,
        &[("mover.lua", bad)],
        gantry_lua::ScriptLimits::default(),
    );
    sc.sim.start();
    sc.sim.step();
    let e = sc.remote("sim.getStringSignal", &[Value::from("e")]);
    let Value::Bytes(e) = &e[0] else {
        panic!("an error message: {e:?}")
    };
    assert_contains(
        String::from_utf8_lossy(e),
        &["moveToPosition", "argument 5 (velocity)", "non-zero"],
    );
}

/// CoppeliaSim 4.3+'s way to move along a created path: its points from the `PATH`
/// custom data block, lengths from `sim.getPathLengths`, positions from
/// `sim.getPathInterpolatedConfig` with a quadratic Bezier method.
const ALONG_4_3: &str = r#"
function sysCall_init()
    obj = sim.getObject('/Dummy')
    local ctrl = {0, 0, 0, 0, 0, 0, 1,  2, 0, 0, 0, 0, 0, 1}
    path = sim.createPath(ctrl, 0, 11, 0)
    local data = sim.unpackDoubleTable(sim.readCustomDataBlock(path, 'PATH'))
    positions = {}
    for i = 0, #data // 7 - 1 do
        for k = 1, 3 do positions[#positions + 1] = data[7 * i + k] end
    end
    lengths, total = sim.getPathLengths(positions, 3)
    travelled = 0
end
function sysCall_actuation()
    travelled = math.min(total, travelled + 0.25)
    local p = sim.getPathInterpolatedConfig(positions, lengths, travelled,
        {type = 'quadraticBezier', strength = 0.5, forceOpen = true})
    sim.setObjectPosition(obj, -1, p)
    if travelled >= total then sim.setInt32Signal('done', sim.getObjectType(path)) end
end
"#;

#[test]
fn a_4_3_script_interpolates_along_a_created_path() {
    let mut sc = Scene::new(
        "paths-4-3",
        SCENE,
        &[("mover.lua", ALONG_4_3)],
        gantry_lua::ScriptLimits::default(),
    );
    let dummy = sc.find("/Dummy");
    sc.sim.start();
    sc.sim.step();
    assert_running(&sc.sim, "mover.lua");
    let p = world_position(&sc.sim, dummy);
    assert!((p[0] - 0.25).abs() < 1e-9 && p[1].abs() < 1e-12, "{p:?}");
    for _ in 0..7 {
        sc.sim.step();
    }
    assert_running(&sc.sim, "mover.lua");
    let p = world_position(&sc.sim, dummy);
    assert!((p[0] - 2.0).abs() < 1e-9, "{p:?}");
    assert_eq!(int32_signal(&mut sc.sim, "done"), Some(4), "the path reads as a dummy");
    // Created during the simulation: gone with it at stop.
    sc.sim.stop();
    assert_eq!(sc.sim.state(), SimulationState::Stopped);
    let err = sc.sim.call("getPathLength", &[Value::Int(dummy + 1)]);
    assert!(err.is_err(), "{err:?}");
}
