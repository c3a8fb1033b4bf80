//! Threaded scripts: `sysCall_thread` (4.6+), `sysCall_threadmain` and script-owned
//! coroutines (4.0-4.5), the blocking calls, pre-emption, errors, stop and restart,
//! hot reload, `require`, and simulation control from scripts.
//!
//! Each expectation is CoppeliaSim's documented behaviour: threads are resumed once per
//! step at the start of actuation; `sim.step` yields until the next step; `sim.wait`
//! waits in simulation time with the step's resolution and returns the overshoot;
//! non-stepping threads are pre-empted instead of freezing the simulator.

use crate::util;
use util::Drive;

use std::time::Duration;

use gantry_engine::Engine;
use gantry_lua::{ScriptLimits, ScriptState};
use gantry_sim_core::Value;
use gantry_sim_core::sim::SimulationState;
use gantry_test_support::{assert_contains, int, load, num, repo, text};
use util::{Scene, log_lines, script_error, script_state};

/// Two dummies, each with a script: `a.lua` on `/a`, `b.lua` on `/b`.
const TWO: &str = r#"
[[object]]
name = "a"
kind = "dummy"
script = "a.lua"

[[object]]
name = "b"
kind = "dummy"
script = "b.lua"
"#;

/// One dummy with `a.lua`.
const ONE: &str = r#"
[[object]]
name = "a"
kind = "dummy"
script = "a.lua"
"#;

fn scene(tag: &str, toml: &str, files: &[(&str, &str)]) -> Scene {
    Scene::new(tag, toml, files, ScriptLimits::default())
}

fn steps(sim: &mut Engine, n: usize) {
    for _ in 0..n {
        sim.step();
    }
}

/// The `print` lines of `file` (information, not errors), in order.
fn printed(sim: &Engine, file: &str) -> Vec<String> {
    log_lines(sim)
        .into_iter()
        .filter(|(src, v, _)| src == file && *v == 450)
        .map(|(_, _, m)| m)
        .collect()
}

#[test]
fn a_thread_is_resumed_once_per_step_at_the_start_of_actuation() {
    let a = "function sysCall_thread()
        sim.setStepping(true)
        for i = 1, 3 do
            print(string.format('thread %d t=%.2f', i, sim.getSimulationTime()))
            sim.step()
        end
        print('thread done')
    end";
    let b = "function sysCall_actuation() print(string.format('actuation t=%.2f', sim.getSimulationTime())) end";
    let mut sc = scene("order", TWO, &[("a.lua", a), ("b.lua", b)]);
    steps(&mut sc.sim, 5);
    let all: Vec<String> = log_lines(&sc.sim)
        .into_iter()
        .filter(|(src, _, _)| src.ends_with(".lua"))
        .map(|(_, _, m)| m)
        .collect();
    assert_eq!(
        all,
        [
            "thread 1 t=0.00",
            "actuation t=0.00",
            "thread 2 t=0.05",
            "actuation t=0.05",
            "thread 3 t=0.10",
            "actuation t=0.10",
            "thread done",
            "actuation t=0.15",
            "actuation t=0.20",
        ]
    );
    // A thread that returned has ended cleanly: no error, the script keeps running.
    assert_eq!(script_state(&sc.sim, "a.lua"), ScriptState::Running);
}

#[test]
fn sim_wait_blocks_in_simulation_time_and_returns_the_overshoot() {
    let a = "function sysCall_thread()
        sim.setStepping(true)
        local t0 = sim.getSimulationTime()
        local left = sim.wait(0.12)
        print(string.format('waited %.2f left %.3f', sim.getSimulationTime() - t0, left))
        left = sim.wait(0.1)
        print(string.format('then at %.2f, on time: %s', sim.getSimulationTime(), tostring(math.abs(left) < 1e-9)))
    end";
    let mut sc = scene("wait", ONE, &[("a.lua", a)]);
    steps(&mut sc.sim, 10);
    // dt = 0.05 s: 0.12 s ends at the first step starting >= 0.12 s later, t = 0.15,
    // 0.03 s late; 0.1 s is two steps exactly.
    assert_eq!(
        printed(&sc.sim, "a.lua"),
        ["waited 0.15 left -0.030", "then at 0.25, on time: true"]
    );
}

/// Issue 47: `sim.wait` returned `(t0 + dt) - t1` of two simulation times, so the same
/// wait returned 0, a few 1e-16 below or above it, depending on the step it started at
/// (a Python test saw +8.9e-16 from `sim.wait(0.5)`, asserting <= 0).
#[test]
fn sim_wait_takes_and_returns_the_same_whatever_step_it_starts_at() {
    // Five waits, then one step, forty times over: 200 waits starting at steps 0 to
    // 919, where the old difference of times came out above, below and on zero (and
    // where 0.5 s at step 20 or 40 took the same ten steps as at step 0). `steps` counts
    // the actuations, the steps the thread saw pass. `%.17g` prints a double exactly.
    let a = "steps = 0
    function sysCall_actuation() steps = steps + 1 end
    function sysCall_thread()
        sim.setStepping(true)
        for round = 1, 40 do
            for _, dt in ipairs({0.5, 0.3, 0.12, 0.05, 0.1}) do
                local s0 = steps
                local left = sim.wait(dt)
                print(string.format('%g %d %.17g', dt, steps - s0, left))
            end
            sim.step()
        end
        print('done')
    end";
    let mut sc = scene("wait-start", ONE, &[("a.lua", a)]);
    steps(&mut sc.sim, 40 * 23 + 2);
    let lines = printed(&sc.sim, "a.lua");
    assert_eq!(lines.last().map(String::as_str), Some("done"), "{lines:?}");
    // dt = 0.05 s: a wait of a whole number of steps is on time (0 left, not a rounding
    // residue of either sign); 0.12 s takes three steps and is 0.15 - 0.12 s late, the
    // same number every time.
    let expected: [(f64, u32, f64); 5] = [
        (0.5, 10, 0.0),
        (0.3, 6, 0.0),
        (0.12, 3, 0.12 - 3.0 * 0.05),
        (0.05, 1, 0.0),
        (0.1, 2, 0.0),
    ];
    let waits = &lines[..lines.len() - 1];
    assert_eq!(waits.len(), 40 * expected.len());
    for (line, (dt, n, left)) in waits.iter().zip(expected.iter().cycle()) {
        let fields: Vec<&str> = line.split(' ').collect();
        assert_eq!(fields[..2], [dt.to_string(), n.to_string()], "steps taken: {line}");
        let got: f64 = fields[2].parse().expect("a number");
        // Bit for bit: 0.0 and -0.0 differ, and so do two overshoots an ulp apart.
        assert!(
            got.to_bits() == left.to_bits(),
            "sim.wait({dt}) left {got:e}, not {left:e} ({line})"
        );
    }
}

#[test]
fn sim_wait_of_whole_steps_takes_as_many_when_the_division_rounds_up() {
    // At 0.01 s steps, 0.07 / 0.01 is 7.000000000000001 in doubles (0.14, 0.28 and 0.56
    // likewise): rounded up as it is, the wait would take an eighth step.
    let a = "steps = 0
    function sysCall_actuation() steps = steps + 1 end
    function sysCall_thread()
        sim.setStepping(true)
        for _, dt in ipairs({0.07, 0.14, 0.28, 0.56}) do
            local s0 = steps
            local left = sim.wait(dt)
            print(string.format('%g %d %.17g', dt, steps - s0, left))
        end
    end";
    let toml = format!("[simulation]\ndt = 0.01\n{ONE}");
    let mut sc = scene("wait-round", &toml, &[("a.lua", a)]);
    steps(&mut sc.sim, 7 + 14 + 28 + 56 + 2);
    assert_eq!(
        printed(&sc.sim, "a.lua"),
        ["0.07 7 0", "0.14 14 0", "0.28 28 0", "0.56 56 0"]
    );
}

#[test]
fn a_thread_waits_for_a_signal_set_by_another_script() {
    let a = "function sysCall_thread()
        local v = sim.waitForSignal('go')
        print(string.format('go=%s at t=%.2f', tostring(v), sim.getSimulationTime()))
        local w = sim.waitForSignal(sim.handle_scene, 'name')
        print('name=' .. w)
    end";
    let b = "function sysCall_sensing()
        local t = sim.getSimulationTime()
        if t > 0.19 and t < 0.21 then sim.setInt32Signal('go', 7) end
        if t > 0.29 and t < 0.31 then sim.setStringSignal('name', 'gripper') end
    end";
    let mut sc = scene("signal", TWO, &[("a.lua", a), ("b.lua", b)]);
    steps(&mut sc.sim, 10);
    // Set during the sensing of the step at t = 0.2, seen at the next resumption.
    assert_eq!(printed(&sc.sim, "a.lua"), ["go=7 at t=0.25", "name=gripper"]);
}

#[test]
fn a_thread_that_errors_names_file_and_line_and_the_others_go_on() {
    let a = "function sysCall_thread()
        sim.step()
        sim.step()
        local x = nil
        return x.field
    end";
    let b = "n = 0
    function sysCall_actuation() n = n + 1 end
    function count() return n end";
    let mut sc = scene("error", TWO, &[("a.lua", a), ("b.lua", b)]);
    steps(&mut sc.sim, 6);
    let e = script_error(&sc.sim, "a.lua");
    assert_contains(&e, &["a.lua:5:", "attempt to index a nil value"]);
    assert_eq!(sc.call("count", &[]), [Value::Int(6)]);
    let errors = log_lines(&sc.sim)
        .iter()
        .filter(|(s, v, _)| s == "a.lua" && *v == 200)
        .count();
    assert_eq!(errors, 1, "the error is reported once");
}

#[test]
fn blocking_calls_in_non_threaded_hooks_fail_clearly() {
    for call in [
        "sim.step()",
        "sim.wait(0.1)",
        "sim.waitForSignal('x')",
        "sim.switchThread()",
    ] {
        let a = format!("function sysCall_actuation()\n    {call}\nend");
        let mut sc = scene("blocking", ONE, &[("a.lua", &a)]);
        steps(&mut sc.sim, 2);
        let e = script_error(&sc.sim, "a.lua");
        assert_contains(
            &e,
            &["a.lua:2:", "blocking calls need a threaded script", "sysCall_thread"],
        );
        // The simulation went on.
        assert!((sc.sim.world().time() - 0.1).abs() < 1e-9, "{call}");
    }
}

#[test]
fn non_stepping_threads_are_preempted_and_stepping_ones_hit_the_budget() {
    // A busy loop that never yields: CoppeliaSim pre-empts it after the auto-yield
    // delay, so the simulation advances and the loop continues next step.
    let a = "n = 0
    function sysCall_thread()
        while true do n = n + 1 end
    end
    function count() return n end";
    let limits = ScriptLimits {
        time_budget: Duration::from_millis(300),
        ..ScriptLimits::default()
    };
    let mut sc = Scene::new("preempt", ONE, &[("a.lua", a)], limits.clone());
    steps(&mut sc.sim, 3);
    let after3 = int(&sc.call("count", &[])[0]);
    steps(&mut sc.sim, 3);
    let after6 = int(&sc.call("count", &[])[0]);
    assert!(after3 > 0 && after6 > after3, "{after3} then {after6}");
    assert_eq!(script_state(&sc.sim, "a.lua"), ScriptState::Running);

    // In stepping mode nothing pre-empts it: the per-resumption budget stops it.
    let a = "function sysCall_thread()
        sim.setStepping(true)
        while true do end
    end";
    let mut sc = Scene::new("budget", ONE, &[("a.lua", a)], limits);
    steps(&mut sc.sim, 2);
    assert_contains(script_error(&sc.sim, "a.lua"), &["a.lua:3:", "time budget"]);
}

#[test]
fn stepping_levels_nest_and_report_the_previous_level() {
    let a = "function sysCall_thread()
        local r = {}
        r[#r+1] = sim.setStepping(true)
        r[#r+1] = sim.setStepping(true)
        r[#r+1] = sim.setStepping(false)
        r[#r+1] = sim.getThreadAutomaticSwitch() and 1 or 0
        r[#r+1] = sim.setStepping(false)
        r[#r+1] = sim.getThreadAutomaticSwitch() and 1 or 0
        r[#r+1] = sim.getAutoYieldDelay()
        sim.setThreadSwitchTiming(5) -- the 4.0-4.5 setter, in milliseconds
        r[#r+1] = sim.getAutoYieldDelay()
        r[#r+1] = select(2, pcall(sim.setAutoYieldDelay, -1)):match('between 0 and 3600 s') and 'refused' or 'accepted'
        print(table.concat(r, ','))
    end";
    let mut sc = scene("levels", ONE, &[("a.lua", a)]);
    steps(&mut sc.sim, 1);
    assert_eq!(printed(&sc.sim, "a.lua"), ["0,1,2,0,1,1,0.002,0.005,refused"]);
}

#[test]
fn coppeliasim_4_2_threadmain_with_switch_thread_runs() {
    // The 4.0-4.2 threaded child script: one function, automatic switching off and
    // an explicit switch per loop iteration, until the simulation stops.
    let a = "function sysCall_threadmain()
        sim.setThreadAutomaticSwitch(false)
        local n = 0
        while sim.getSimulationState() ~= sim.simulation_advancing_abouttostop do
            n = n + 1
            sim.setIntegerSignal('loops', n)
            sim.switchThread()
        end
    end";
    let mut sc = scene("threadmain", ONE, &[("a.lua", a)]);
    steps(&mut sc.sim, 4);
    assert_eq!(util::int32_signal(&mut sc.sim, "loops"), Some(4));
}

#[test]
fn coppeliasim_4_3_coroutine_pattern_runs() {
    // The 4.3-4.5 template: a coroutine created in sysCall_init, resumed from
    // sysCall_actuation, its errors reported with debug.traceback.
    let a = "function sysCall_init()
        corout = coroutine.create(coroutineMain)
    end
    function sysCall_actuation()
        if coroutine.status(corout) ~= 'dead' then
            local ok, errorMsg = coroutine.resume(corout)
            if errorMsg then error(debug.traceback(corout, errorMsg), 2) end
        end
    end
    function coroutineMain()
        sim.setThreadAutomaticSwitch(false)
        for i = 1, 2 do
            print('step ' .. i)
            sim.switchThread()
        end
        sim.wait(0.1)
        print('waited')
        error('boom')
    end";
    let mut sc = scene("coroutine", ONE, &[("a.lua", a)]);
    steps(&mut sc.sim, 8);
    assert_eq!(printed(&sc.sim, "a.lua"), ["step 1", "step 2", "waited"]);
    assert_contains(script_error(&sc.sim, "a.lua"), &["a.lua:18:", "boom"]);
}

#[test]
fn stop_and_restart_while_a_thread_is_suspended() {
    let a = "function sysCall_init() print('init') end
    function sysCall_thread()
        sim.setStepping(true)
        local i = 0
        while true do
            i = i + 1
            sim.setInt32Signal('i', i)
            sim.wait(0.05)
        end
    end
    function sysCall_cleanup() print('cleanup') end";
    let mut sc = scene("restart", ONE, &[("a.lua", a)]);
    steps(&mut sc.sim, 5);
    assert_eq!(util::int32_signal(&mut sc.sim, "i"), Some(5));
    sc.sim.stop();
    assert_eq!(sc.sim.state(), SimulationState::Stopped);
    // The restarted thread starts from the top, in a fresh world (signals cleared).
    assert_eq!(util::int32_signal(&mut sc.sim, "i"), None);
    steps(&mut sc.sim, 2);
    assert_eq!(util::int32_signal(&mut sc.sim, "i"), Some(2));
    assert_eq!(printed(&sc.sim, "a.lua"), ["init", "cleanup", "init"]);
}

#[test]
fn hot_reload_restarts_a_threaded_script_with_the_new_code() {
    let v1 = "function sysCall_thread()
        sim.setStepping(true)
        while true do sim.setInt32Signal('version', 1); sim.step() end
    end";
    let v2 = "function sysCall_thread()
        sim.setStepping(true)
        while true do sim.setInt32Signal('version', 2); sim.step() end
    end";
    let mut sc = scene("reload", ONE, &[("a.lua", v1)]);
    steps(&mut sc.sim, 3);
    assert_eq!(util::int32_signal(&mut sc.sim, "version"), Some(1));
    sc.dir.write("a.lua", v2);
    sc.sim.reload(0);
    steps(&mut sc.sim, 2);
    assert_eq!(util::int32_signal(&mut sc.sim, "version"), Some(2));
    assert_eq!(script_state(&sc.sim, "a.lua"), ScriptState::Running);
}

#[test]
fn a_script_can_stop_and_pause_the_simulation() {
    let a = "function sysCall_thread()
        sim.setStepping(true)
        sim.wait(0.1)
        sim.pauseSimulation()
        sim.step()
        sim.stopSimulation()
        sim.step()
        print('never')
    end
    function sysCall_cleanup() print('cleanup') end";
    let mut sc = scene("control", ONE, &[("a.lua", a)]);
    steps(&mut sc.sim, 3);
    // Paused at the end of the step during which it asked (the third, t = 0.1).
    assert_eq!(sc.sim.state(), SimulationState::Paused);
    assert!((sc.sim.world().time() - 0.15).abs() < 1e-9);
    sc.sim.start();
    sc.sim.step();
    assert_eq!(sc.sim.state(), SimulationState::Stopped);
    assert_eq!(printed(&sc.sim, "a.lua"), ["cleanup"]);
}

#[test]
fn require_returns_the_api_and_refuses_anything_else_by_name() {
    let a = "local s = require('sim')
    local ik = require 'simIK'
    same = (s == sim) and (ik == simIK) and require('sim-2') == sim
        and require('socket') == socket and require('socket.core') == socket
    function check() return same end
    function other(name) return pcall(require, name) end";
    let mut sc = scene("require", ONE, &[("a.lua", a)]);
    sc.sim.start();
    assert_eq!(sc.call("check", &[]), [Value::Bool(true)]);
    let r = sc.call("other", &[Value::Str("lfs".into())]);
    assert_eq!(r[0], Value::Bool(false));
    assert_contains(
        text(&r[1]),
        &[
            "module 'lfs' not found: it is none of gantry's modules",
            "Matrix, sim, simIK, simOMPL, simROS, simROS2, simRemoteApi, simUI, simVision, socket",
            "--lua-path",
        ],
    );
}

#[test]
fn a_loop_in_a_coroutine_of_a_non_threaded_hook_is_interrupted() {
    // Coroutines a script creates get the time-budget hook too: before threads, a
    // loop inside one ran forever.
    let a = "function sysCall_actuation()
        local co = coroutine.create(function() while true do end end)
        coroutine.resume(co)
    end";
    let limits = ScriptLimits {
        time_budget: Duration::from_millis(200),
        ..ScriptLimits::default()
    };
    let mut sc = Scene::new("coroutine-budget", ONE, &[("a.lua", a)], limits);
    steps(&mut sc.sim, 2);
    assert_contains(script_error(&sc.sim, "a.lua"), &["time budget"]);
}

/// The arm of the paper's scene with kinematic joints, a pick-and-place thread on it
/// and a non-threaded script that gives the start signal.
fn pick_and_place_scene(thread: &str, starter: &str) -> Scene {
    let urdf = repo("assets/robots/arm6/arm6.urdf");
    let toml = format!(
        r#"
[simulation]
dt = 0.05

[floor]
size = [4, 4]

[[robot]]
name = "arm6"
urdf = "{}"
joint_mode = "kinematic"
script = "pick.lua"

[[object]]
name = "starter"
kind = "dummy"
script = "starter.lua"
"#,
        urdf.display()
    );
    Scene::new(
        "pick",
        &toml,
        &[("pick.lua", thread), ("starter.lua", starter)],
        ScriptLimits::default(),
    )
}

#[test]
fn pick_and_place_with_move_to_config_in_a_thread() {
    // Written in the style of the manual's threaded examples: wait for a start
    // signal, move to the pick configuration, grasp (attach), move to the place
    // configuration with the 4.0-4.5 call form, release, go home.
    let thread = "
    local qPick = {0.5, 0.3, 0.2, 0, -1.2, 0}
    local qPlace = {-0.6, 0.2, 0.4, 0, -1.0, 0.3}
    local vmax, amax, jmax = 1.0, 2.0, 10.0

    local function tipAt(q)
        -- Forward kinematics by posing the arm, as a script would with IK off.
        local saved = {}
        for i = 1, 6 do saved[i] = sim.getJointPosition(joints[i]); sim.setJointPosition(joints[i], q[i]) end
        local p = sim.getObjectPosition(tip, sim.handle_world)
        for i = 1, 6 do sim.setJointPosition(joints[i], saved[i]) end
        return p
    end

    function sysCall_init()
        joints = {}
        for i = 1, 6 do joints[i] = sim.getObject('./joint' .. i) end
        tip = sim.getObject('./tip')
        pickAt, placeAt = tipAt(qPick), tipAt(qPlace)
        cube = sim.createPrimitiveShape(sim.primitiveshape_cuboid, {0.04, 0.04, 0.04})
        sim.setObjectPosition(cube, pickAt, sim.handle_world)
        sim.setObjectAlias(cube, 'cube')
    end

    function sysCall_thread()
        sim.setStepping(true)
        sim.waitForSignal('start')
        local t0 = sim.getSimulationTime()
        local r = sim.moveToConfig({joints = joints, targetPos = qPick,
            maxVel = {vmax, vmax, vmax, vmax, vmax, vmax},
            maxAccel = {amax, amax, amax, amax, amax, amax},
            maxJerk = {jmax, jmax, jmax, jmax, jmax, jmax}})
        sim.setFloatSignal('pickTime', sim.getSimulationTime() - t0)
        sim.setObjectParent(cube, tip, true)

        local current = {}
        for i = 1, 6 do current[i] = sim.getJointPosition(joints[i]) end
        local v, a, j = {}, {}, {}
        for i = 1, 6 do v[i], a[i], j[i] = vmax, amax, jmax end
        local endPos = sim.moveToConfig(-1, current, nil, nil, v, a, j, qPlace, nil,
            function(q) for i = 1, 6 do sim.setJointPosition(joints[i], q[i]) end end)
        sim.setObjectParent(cube, -1, true)
        local c = sim.getObjectPosition(cube, sim.handle_world)
        local err = 0
        for k = 1, 3 do err = math.max(err, math.abs(c[k] - placeAt[k])) end
        sim.setFloatSignal('placeError', err)
        sim.setFloatSignal('endError', math.abs(endPos[1] - qPlace[1]))

        sim.moveToConfig({joints = joints, targetPos = {0, 0, 0, 0, 0, 0},
            maxVel = v, maxAccel = a, maxJerk = j})
        local after = sim.getObjectPosition(cube, sim.handle_world)
        local moved = 0
        for k = 1, 3 do moved = math.max(moved, math.abs(after[k] - c[k])) end
        sim.setFloatSignal('cubeMovedAfterRelease', moved)
        sim.setInt32Signal('done', 1)
    end";
    // The non-threaded part: gives the start signal at t = 0.2 s, and measures the
    // fastest joint 1 motion seen between two steps.
    let starter = "
    function sysCall_init() j1 = sim.getObject('/arm6/joint1'); last = nil; fastest = 0 end
    function sysCall_actuation()
        if sim.getSimulationTime() >= 0.2 then sim.setInt32Signal('start', 1) end
    end
    function sysCall_sensing()
        local q = sim.getJointPosition(j1)
        if last then fastest = math.max(fastest, math.abs(q - last) / sim.getSimulationTimeStep()) end
        last = q
        sim.setFloatSignal('fastest', fastest)
    end";
    let mut sc = pick_and_place_scene(thread, starter);
    let mut n = 0;
    while util::int32_signal(&mut sc.sim, "done").is_none() {
        sc.sim.step();
        n += 1;
        assert!(
            n < 400,
            "the sequence did not finish in 20 s; log: {:?}",
            log_lines(&sc.sim)
        );
    }
    let float = |sc: &mut Scene, name: &str| num(&sc.remote("getFloatSignal", &[Value::Str(name.into())])[0]);
    // Joint 1 moves 0.5 rad at <= 1 rad/s with accel <= 2 rad/s^2: at least
    // 0.5 s + ramp time; jerk-limited, so a little more.
    let pick_time = float(&mut sc, "pickTime");
    assert!((0.55..3.0).contains(&pick_time), "pick took {pick_time} s");
    let fastest = float(&mut sc, "fastest");
    assert!(
        fastest <= 1.0 + 1e-6 && fastest > 0.5,
        "joint 1 moved at up to {fastest} rad/s"
    );
    // The cube rode on the tip to the place pose and stayed there.
    assert!(float(&mut sc, "placeError") < 1e-6);
    assert!(float(&mut sc, "endError") < 1e-9);
    assert!(float(&mut sc, "cubeMovedAfterRelease") < 1e-9);
    assert_eq!(script_state(&sc.sim, "pick.lua"), ScriptState::Running);
    assert_eq!(script_state(&sc.sim, "starter.lua"), ScriptState::Running);
}

#[test]
fn every_sim_function_a_script_sees_is_in_the_registry_or_the_host_list() {
    // The docs are generated from these two lists; a function installed without
    // being listed (or listed without being installed) would make them lie.
    let a = "function names()
        local t = {}
        for k, v in pairs(sim) do if type(v) == 'function' then t[#t + 1] = k end end
        table.sort(t)
        return table.concat(t, ',')
    end";
    let mut sc = scene("names", ONE, &[("a.lua", a)]);
    sc.sim.start();
    let seen: std::collections::BTreeSet<String> =
        text(&sc.call("names", &[])[0]).split(',').map(str::to_owned).collect();
    let module = gantry_sim_core::api::module("sim").expect("sim");
    let mut listed: std::collections::BTreeSet<String> = module.callable().map(|(n, _)| n.to_owned()).collect();
    listed.extend(gantry_sim_core::api::host::script_host_names().map(str::to_owned));
    let unlisted: Vec<&String> = seen.difference(&listed).collect();
    let missing: Vec<&String> = listed.difference(&seen).collect();
    assert!(unlisted.is_empty(), "installed but not listed: {unlisted:?}");
    assert!(missing.is_empty(), "listed but not installed: {missing:?}");
}

#[test]
fn the_default_scene_starts_and_runs_without_a_warning() {
    let path = repo("assets/scenes/bubble_rob.toml");
    let mut sim = util::engine(load(&path), ScriptLimits::default()).expect("builds");
    steps(&mut sim, 40);
    let warnings: Vec<(String, i64, String)> = log_lines(&sim).into_iter().filter(|(_, v, _)| *v <= 300).collect();
    assert!(warnings.is_empty(), "{warnings:?}");
    assert!(sim.world().warnings().is_empty(), "{:?}", sim.world().warnings());
}

#[test]
fn simulation_lifecycle_hooks_run_at_coppeliasims_moments() {
    let a = "function sysCall_beforeSimulation() print('before') end
    function sysCall_init() print('init') end
    function sysCall_suspend() print('suspend') end
    function sysCall_resume() print('resume') end
    function sysCall_cleanup() print('cleanup') end
    function sysCall_afterSimulation() print('after') end
    function sysCall_nonSimulation() print('non') end";
    let mut sc = scene("lifecycle", ONE, &[("a.lua", a)]);
    sc.sim.non_simulation();
    steps(&mut sc.sim, 1);
    sc.sim.non_simulation(); // running: not called
    sc.sim.pause();
    sc.sim.pause(); // already paused: no second suspend
    sc.sim.start();
    steps(&mut sc.sim, 1);
    sc.sim.stop();
    sc.sim.non_simulation();
    // The log survives the stop; the scripts are new after it.
    assert_eq!(
        printed(&sc.sim, "a.lua"),
        ["non", "before", "init", "suspend", "resume", "cleanup", "after", "non"]
    );
}

#[test]
fn an_unsupported_hook_is_named_once_at_load() {
    let a = "function sysCall_init() end
    function sysCall_contactCallback() end
    function sysCall_beforeInstanceSwitch() end";
    let mut sc = scene("unsupported", ONE, &[("a.lua", a)]);
    steps(&mut sc.sim, 3);
    let warnings: Vec<String> = log_lines(&sc.sim)
        .into_iter()
        .filter(|(s, v, _)| s == "a.lua" && *v == 300)
        .map(|(_, _, m)| m)
        .collect();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert_contains(
        &warnings[0],
        &[
            "sysCall_beforeInstanceSwitch, sysCall_contactCallback not supported by gantry",
            "never be called",
        ],
    );
}

#[test]
fn simulation_state_reports_coppeliasims_advancing_passes() {
    let a = "function sysCall_init() print('init ' .. sim.getSimulationState()) end
    function sysCall_actuation()
        local t = sim.getSimulationTime()
        print(string.format('%.2f %d', t, sim.getSimulationState()))
        if t > 0.09 and t < 0.11 then sim.pauseSimulation(); print('asked ' .. sim.getSimulationState()) end
        if t > 0.19 and t < 0.21 then sim.stopSimulation(); print('asked ' .. sim.getSimulationState()) end
    end
    function sysCall_cleanup() print('cleanup ' .. sim.getSimulationState()) end";
    let mut sc = scene("states", ONE, &[("a.lua", a)]);
    steps(&mut sc.sim, 3);
    assert_eq!(sc.sim.state(), SimulationState::Paused);
    sc.sim.start();
    steps(&mut sc.sim, 2);
    assert_eq!(sc.sim.state(), SimulationState::Stopped);
    assert_eq!(
        printed(&sc.sim, "a.lua"),
        [
            "init 16",
            "0.00 16",
            "0.05 17",
            "0.10 17",
            "asked 19",
            "0.15 20",
            "0.20 17",
            "asked 21",
            "cleanup 21",
        ]
    );
}

/// CoppeliaSim 3.x-4.2's `sim.rmlMoveToJointPositions` in a `sysCall_threadmain`, as
/// the raven2 example calls it: the joints reach the target within the limits, and the
/// call returns 1 with the end state.
#[test]
fn rml_move_to_joint_positions_in_a_4_2_thread() {
    let thread = "
    function sysCall_threadmain()
        local joints = {}
        for i = 1, 3 do joints[i] = sim.getObjectHandle('joint' .. i) end
        local vmax, amax, jmax = {1, 1, 1}, {2, 2, 2}, {20, 20, 20}
        local target = {0.5, -0.4, 0.3}
        local t0 = sim.getSimulationTime()
        local result, pos, vel = sim.rmlMoveToJointPositions(joints, -1, {0, 0, 0}, {0, 0, 0},
            vmax, amax, jmax, target, {0, 0, 0})
        sim.setFloatSignal('rmlTime', sim.getSimulationTime() - t0)
        sim.setInt32Signal('rmlResult', result)
        local err = 0
        for i = 1, 3 do err = math.max(err, math.abs(sim.getJointPosition(joints[i]) - target[i]), math.abs(pos[i] - target[i])) end
        sim.setFloatSignal('rmlError', err)
        local ok, e = pcall(sim.rmlMoveToJointPositions, joints, -1, nil, nil, vmax, amax, jmax, target, nil, {1, 0, 0})
        sim.setStringSignal('rmlDirection', tostring(e))
        sim.setInt32Signal('done', 1)
    end";
    let starter = "function sysCall_init() end";
    let mut sc = pick_and_place_scene(thread, starter);
    let mut n = 0;
    while util::int32_signal(&mut sc.sim, "done").is_none() {
        sc.sim.step();
        n += 1;
        assert!(n < 200, "did not finish in 10 s; log: {:?}", log_lines(&sc.sim));
    }
    let float = |sc: &mut Scene, name: &str| num(&sc.remote("getFloatSignal", &[Value::Str(name.into())])[0]);
    assert_eq!(util::int32_signal(&mut sc.sim, "rmlResult"), Some(1));
    assert!(float(&mut sc, "rmlError") < 1e-9);
    // 0.5 rad at <= 1 rad/s and <= 2 rad/s^2: more than 0.5 s, not instantaneous.
    let t = float(&mut sc, "rmlTime");
    assert!((0.55..3.0).contains(&t), "the motion took {t} s");
    // String signals read back as bytes by remote callers (CoppeliaSim 4.6+).
    let e = match &sc.remote("getStringSignal", &[Value::Str("rmlDirection".into())])[0] {
        Value::Bytes(b) => String::from_utf8_lossy(b).into_owned(),
        other => panic!("{other:?}"),
    };
    assert_contains(&e, &["only 0", "sim.rmlMoveToJointPositions"]);
}
