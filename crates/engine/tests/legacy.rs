//! Scripts written for CoppeliaSim 4.0-4.2 and for 4.6+, run unmodified: the old names
//! (`sim.getObjectHandle` with its suffixes, integer signals, the status bar, auxiliary
//! consoles, user parameters, `sysCall_threadmain`) and the new module form
//! (`sim = require 'sim'`, `sysCall_thread`).

use crate::util;
use util::Drive;

use gantry_lua::ScriptState;
use gantry_sim_core::Value;
use gantry_test_support::{assert_close, assert_contains, floats, int, ints, num, text};
use util::{Scene, log_lines, script_state};

/// The rover of the BubbleRob scene with a 4.2-style threaded script: the old lookup,
/// signals, status bar, console and user parameters, driving the motors for 1 s.
const SCRIPT_4_2: &str = r#"
function sysCall_threadmain()
    sim.setThreadAutomaticSwitch(false)
    local self = sim.getObjectAssociatedWithScript(sim.handle_self)
    local body = sim.getObjectHandle('bubbleRob')
    local same = sim.getObjectHandle('bubbleRob#')
    local left = sim.getObjectHandle('leftMotor')
    local right = sim.getObjectHandle('rightMotor')
    local missing = sim.getObjectHandle('noSuchThing@silentError')
    local ok = pcall(sim.getObjectHandle, 'noSuchThing')
    sim.addStatusbarMessage('handles ' .. tostring(self == body) .. ' ' .. tostring(same == body)
        .. ' ' .. missing .. ' ' .. tostring(ok))
    local console = sim.auxiliaryConsoleOpen('BubbleRob', 10, 1)
    sim.auxiliaryConsolePrint(console, 'line one\nline two\n')
    sim.setScriptSimulationParameter(sim.handle_self, 'speed', 2.5)
    local speed = sim.getScriptSimulationParameter(sim.handle_self, 'speed')
    local t0 = sim.getSystemTimeInMs(-1)
    while sim.getSimulationTime() < 1 do
        sim.setJointTargetVelocity(left, speed)
        sim.setJointTargetVelocity(right, speed)
        sim.setIntegerSignal('loops', (sim.getIntegerSignal('loops') or 0) + 1)
        sim.switchThread()
    end
    sim.setJointTargetVelocity(left, 0)
    sim.setJointTargetVelocity(right, 0)
    sim.addStatusbarMessage('elapsed ms >= 0: ' .. tostring(sim.getSystemTimeInMs(t0) >= 0))
    sim.auxiliaryConsoleClose(console)
    sim.stopSimulation()
end
"#;

#[test]
fn a_coppeliasim_4_2_threaded_script_runs_unmodified() {
    let mut sc = Scene::new(
        "legacy-4-2",
        &util::bubble_rob_toml(Some("probe.lua")),
        &[("probe.lua", SCRIPT_4_2)],
        gantry_lua::ScriptLimits::default(),
    );
    let mut steps = 0;
    while sc.sim.state() != gantry_sim_core::sim::SimulationState::Stopped || steps == 0 {
        sc.sim.step();
        steps += 1;
        assert!(steps < 100, "the script did not stop the simulation");
    }
    // 1 s at dt = 0.05 s: the loop ran 20 times, then the script stopped the simulation
    // (the world is back at its start, the log kept).
    assert_eq!(steps, 21);
    let lines: Vec<(String, String)> = log_lines(&sc.sim).into_iter().map(|(s, _, m)| (s, m)).collect();
    let has = |src: &str, msg: &str| lines.iter().any(|(s, m)| s == src && m == msg);
    assert!(has("probe.lua", "handles true true -1 false"), "{lines:?}");
    assert!(has("console: BubbleRob", "line one"), "{lines:?}");
    assert!(has("console: BubbleRob", "line two"), "{lines:?}");
    assert!(has("probe.lua", "elapsed ms >= 0: true"), "{lines:?}");
    assert!(lines.iter().all(|(_, m)| !m.contains("error")), "{lines:?}");
}

#[test]
fn the_rover_moves_under_the_4_2_script() {
    let mut sc = Scene::new(
        "legacy-4-2-moves",
        &util::bubble_rob_toml(Some("probe.lua")),
        &[("probe.lua", SCRIPT_4_2)],
        gantry_lua::ScriptLimits::default(),
    );
    let body = sc.find("/bubbleRob");
    let start = util::world_position(&sc.sim, body);
    for _ in 0..15 {
        sc.sim.step();
    }
    let now = util::world_position(&sc.sim, body);
    let moved = ((now[0] - start[0]).powi(2) + (now[1] - start[1]).powi(2)).sqrt();
    // 2.5 rad/s on 0.04 m wheels is 0.1 m/s: about 0.07 m in 0.7 s.
    assert!(moved > 0.03, "moved {moved} m");
    assert_eq!(util::int32_signal(&mut sc.sim, "loops"), Some(15));
}

#[test]
fn a_coppeliasim_4_6_module_script_runs_unmodified() {
    let script = r#"
sim = require 'sim'
simUI = require('simUI')

function sysCall_init()
    body = sim.getObject('/bubbleRob')
    left = sim.getObject('/bubbleRob/leftMotor')
end

function sysCall_thread()
    sim.setStepping(true)
    sim.setJointTargetVelocity(left, 1)
    sim.wait(0.5)
    sim.setJointTargetVelocity(left, 0)
    sim.setInt32Signal('done', 1)
end
"#;
    let mut sc = Scene::new(
        "module-4-6",
        &util::bubble_rob_toml(Some("probe.lua")),
        &[("probe.lua", script)],
        gantry_lua::ScriptLimits::default(),
    );
    for _ in 0..12 {
        sc.sim.step();
    }
    assert_eq!(util::int32_signal(&mut sc.sim, "done"), Some(1));
    assert_eq!(script_state(&sc.sim, "probe.lua"), ScriptState::Running);
}

#[test]
fn remote_clients_see_the_old_names_too() {
    let mut sc = Scene::rover("legacy-remote", "function sysCall_init() end");
    let h = sc.remote("getObjectHandle", &[Value::Str("bubbleRob".into())]);
    assert_eq!(h, [Value::Int(sc.find("/bubbleRob"))]);
    sc.remote("setIntegerSignal", &[Value::Str("x".into()), Value::Int(3)]);
    assert_eq!(sc.remote("getInt32Signal", &[Value::Str("x".into())]), [Value::Int(3)]);
    let e = sc
        .sim
        .call("getObjectHandle", &[Value::Str("nope".into())])
        .unwrap_err();
    assert_contains(&e, &["object does not exist", "sim.getObjectHandle"]);
    let e = sc
        .sim
        .call("getObjectAssociatedWithScript", &[Value::Int(-4)])
        .unwrap_err();
    assert_contains(&e, &["remote client"]);
}

/// A V-REP 3.2 non-threaded child script for the rover, as old course scenes carry it:
/// flat names and one chunk switching on `sim_call_type`. The import's rewrite (what
/// CoppeliaSim does when it loads the old file) makes it run on the 4.x hooks.
const SCRIPT_3_2: &str = r#"
if (sim_call_type==sim_childscriptcall_initialization) then
    left=simGetObjectHandle('leftMotor')
    right=simGetObjectHandle('rightMotor')
    passes=0
    simAddStatusbarMessage('init '..simGetObjectName(simGetObjectParent(left)))
end
if (sim_call_type==sim_childscriptcall_actuation) then
    simSetJointTargetVelocity(left,2)
    simSetJointTargetVelocity(right,2)
    passes=passes+1
    simSetIntegerSignal('passes',passes)
end
if (sim_call_type==sim_childscriptcall_sensing) then
    local p=simGetObjectPosition(left,sim_handle_world)
    simSetFloatSignal('x',p[1])
end
"#;

/// A V-REP 3 threaded script: top-level code in its own thread.
const THREAD_3_X: &str = r#"
simSetThreadAutomaticSwitch(false)
local n=0
while simGetSimulationTime()<0.5 do
    n=n+1
    simSetIntegerSignal('loops',n)
    simSwitchThread()
end
"#;

#[test]
fn v_rep_3_scripts_run_after_the_import_rewrite() {
    let (pass_script, r) = gantry_sim_core::scene::modernize_old_script(SCRIPT_3_2, false);
    assert!(r.call_types && r.renamed >= 9, "{r:?}");
    let mut sc = Scene::new(
        "legacy-3-2",
        &util::bubble_rob_toml(Some("probe.lua")),
        &[("probe.lua", &pass_script)],
        gantry_lua::ScriptLimits::default(),
    );
    sc.sim.start();
    let x0 = sc.remote("sim.getFloatSignal", &[Value::Str("x".into())]);
    for _ in 0..20 {
        sc.sim.step();
    }
    assert_eq!(script_state(&sc.sim, "probe.lua"), ScriptState::Running);
    let passes = sc.remote("sim.getInt32Signal", &[Value::Str("passes".into())]);
    assert_eq!(passes, [Value::Int(20)]);
    let x = sc.remote("sim.getFloatSignal", &[Value::Str("x".into())]);
    assert!(
        x0 == [Value::Nil] || x0.is_empty(),
        "sensing ran only after a step: {x0:?}"
    );
    assert!(num(&x[0]) > 0.05, "the rover drove forward: {x:?}");
    let lines = log_lines(&sc.sim);
    assert!(lines.iter().any(|(_, _, m)| m == "init bubbleRob"), "{lines:?}");

    let (thread_script, r) = gantry_sim_core::scene::modernize_old_script(THREAD_3_X, true);
    assert!(r.thread_body, "{r:?}");
    let mut sc = Scene::new(
        "legacy-3-thread",
        &util::bubble_rob_toml(Some("probe.lua")),
        &[("probe.lua", &thread_script)],
        gantry_lua::ScriptLimits::default(),
    );
    sc.sim.start();
    for _ in 0..20 {
        sc.sim.step();
    }
    assert_eq!(script_state(&sc.sim, "probe.lua"), ScriptState::Running);
    // 0.5 s at dt = 0.05 s: one loop per step until the time is reached.
    let loops = sc.remote("sim.getInt32Signal", &[Value::Str("loops".into())]);
    assert_eq!(loops, [Value::Int(10)]);
}

/// V-REP 3's bit operations, handle check and matrix copy, as its course scripts use them.
const SCRIPT_3X: &str = r#"
function sysCall_init()
    local body = sim.getObjectHandle('bubbleRob')
    local m = sim.getObjectMatrix(body, -1)
    local c = sim.copyMatrix(m)
    c[4] = c[4] + 1
    results = {
        sim.boolAnd32(0xF0F0, 0x0FF0), sim.boolOr32(0xF000, 0x000F), sim.boolXor32(0xFF, 0x0F),
        sim.boolAnd32(-1, 0xFFFF), sim.boolOr32(0x1FFFFFFFF, 0),
        sim.isHandleValid(body), sim.isHandleValid(body, 109), sim.isHandleValid(body, 102),
        sim.isHandleValid(123456), m[4] + 1 == c[4] and 1 or 0, #c,
    }
    ok, err = pcall(sim.copyMatrix, {1, 2, 3})
end
function report() return table.concat(results, ','), err end
"#;

#[test]
fn v_rep_3_bit_operations_handle_checks_and_matrix_copies() {
    let mut s = Scene::rover("legacy-3x", SCRIPT_3X);
    let out = s.call("report", &[]);
    assert_eq!(
        out[0],
        Value::from("240,61455,240,65535,4294967295,1,1,0,0,1,12"),
        "and, or, xor on 32 bits; valid handles; a copy, not the same table"
    );
    let Value::Str(err) = &out[1] else {
        panic!("an error message: {out:?}")
    };
    assert_contains(err, &["copyMatrix"]);
}

/// What V-REP-era ROS scripts do before publishing: look for the ROS plugin by name,
/// try to start a driver program, and flip a vision sensor's image.
const SCRIPT_PLUGINS: &str = r#"
function sysCall_init()
    local names, index, moduleName = {}, 0, 0
    while moduleName do
        moduleName = sim.getModuleName(index)
        if moduleName then names[#names + 1] = moduleName end
        index = index + 1
    end
    launched = sim.launchExecutable('hokuyo_node', '', 0)
    -- A laser scanner model's fading rays: transparency flags are accepted.
    rays = sim.addDrawingObject(sim.drawing_lines + sim.drawing_50percenttransparency
        + sim.drawing_25percenttransparency, 1, 0, -1, 1000, {0, 0, 0})
    sim.addDrawingObjectItem(rays, {0, 0, 0, 1, 0, 0})
    local img = string.char(1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4)
    flipped = sim.transformImage(img, {2, 2}, 4)
    mirrored = sim.transformImage(img, {2, 2}, 8)
    ok, err = pcall(sim.transformImage, img, {5, 2}, 4)
    modules = table.concat(names, ',')
end
function report()
    return modules, launched, table.concat({flipped:byte(1, -1)}, ','), mirrored:byte(1), err,
        math.type(rays)
end
"#;

#[test]
fn v_rep_plugin_lookup_program_launch_and_image_flips() {
    let mut s = Scene::rover("legacy-plugins", SCRIPT_PLUGINS);
    let out = s.call("report", &[]);
    let Value::Str(modules) = &out[0] else {
        panic!("{out:?}")
    };
    for m in ["RosInterface", "ROS2", "ROS"] {
        assert!(modules.split(',').any(|x| x == m), "{m} in {modules}");
    }
    assert_eq!(out[1], Value::Int(-1), "not allowed: CoppeliaSim's failure value");
    assert_eq!(out[2], Value::from("3,3,3,4,4,4,1,1,1,2,2,2"), "rows reversed");
    assert_eq!(out[3], Value::Int(2), "pixels of a row reversed");
    let Value::Str(err) = &out[4] else { panic!("{out:?}") };
    assert_contains(err, &["5 x 2", "30 bytes", "got 12", "transformImage"]);
    assert_eq!(
        out[5],
        Value::from("integer"),
        "a drawing object with transparency flags"
    );
    let log = log_lines(&s.sim);
    assert!(
        log.iter()
            .any(|(_, _, m)| m.contains("launchExecutable") && m.contains("--allow-launch hokuyo_node")),
        "{log:?}"
    );
}

/// V-REP's tubes, as its gyroscope and accelerometer models hand readings to another
/// script: a sensor writes every step, a threaded reader blocks on the tube, and a
/// non-threaded one polls.
#[test]
fn tubes_carry_packets_between_scripts_in_order() {
    let scene = r#"
[simulation]
dt = 0.05

[[object]]
name = "gyro"
kind = "dummy"
script = "gyro.lua"

[[object]]
name = "reader"
kind = "dummy"
script = "reader.lua"
"#;
    let gyro = r#"
function sysCall_init()
    tube = sim.tubeOpen(0, 'gyroData', 1)
    n = 0
end
function sysCall_sensing()
    n = n + 1
    sent = sim.tubeWrite(tube, sim.packFloatTable({n, 2 * n}))
end
function gyroReport()
    return sent, sim.tubeStatus(tube)
end
"#;
    let reader = r#"
function sysCall_thread()
    tube = sim.tubeOpen(0, 'gyroData', 1)
    got = {}
    for i = 1, 3 do
        local data = sim.tubeRead(tube, true)
        got[#got + 1] = sim.unpackFloatTable(data)[1]
    end
    sim.tubeClose(tube)
    closed = true
end
function report()
    local ok, err = pcall(sim.tubeRead, 9999)
    return table.concat(got, ','), closed or false, err
end
"#;
    let mut sc = Scene::new(
        "tubes",
        scene,
        &[("gyro.lua", gyro), ("reader.lua", reader)],
        gantry_lua::ScriptLimits::default(),
    );
    sc.sim.start();
    for _ in 0..8 {
        sc.sim.step();
    }
    for f in ["gyro.lua", "reader.lua"] {
        assert_eq!(script_state(&sc.sim, f), gantry_lua::ScriptState::Running, "{f}");
    }
    let r = sc.call("report", &[]);
    let Value::Str(got) = &r[0] else { panic!("{r:?}") };
    let got: Vec<f64> = got.split(',').map(|x| x.parse().unwrap()).collect();
    assert_eq!(got.len(), 3, "{got:?}");
    assert!(got.windows(2).all(|w| w[1] > w[0]), "in order: {got:?}");
    assert_eq!(r[1], Value::Bool(true), "the reader closed its end");
    let Value::Str(err) = &r[2] else { panic!("{r:?}") };
    assert_contains(err, &["tube 9999 does not exist", "tubeRead"]);
    // The writer's end is alone now: its packets are dropped, and it says so.
    let g = sc.call("gyroReport", &[]);
    assert_eq!(g, [Value::Int(0), Value::Int(0), Value::Int(0), Value::Int(0)]);
}

/// `sim.launchExecutable` starts a program the command line allowed (`--allow-launch`),
/// without a shell, and only that one; what a run started ends with it.
#[test]
fn launch_executable_starts_allowed_programs_only() {
    let dir = std::env::temp_dir().join(format!("gantry-launch-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let made = dir.join("made");
    let _ = std::fs::remove_file(&made);
    let script = format!(
        r#"
function sysCall_init()
    touched = sim.launchExecutable('touch', '{}', 0)
    refused = sim.launchExecutable('rm', '-rf {}', 0)
    sleeper = sim.launchExecutable('sleep', '30', 0)
end
function report() return touched, refused, sleeper end
"#,
        made.display(),
        dir.display()
    );
    let scene = "[[object]]\nname = \"node\"\nkind = \"dummy\"\nscript = \"launch.lua\"\n";
    let limits = gantry_lua::ScriptLimits {
        allow_launch: vec!["touch".into(), "sleep".into()],
        ..gantry_lua::ScriptLimits::default()
    };
    let mut sc = Scene::new("launch", scene, &[("launch.lua", &script)], limits);
    sc.sim.start();
    let r = sc.call("report", &[]);
    assert!(r[0].as_i64().is_some_and(|pid| pid > 0), "{r:?}");
    assert_eq!(r[1], Value::Int(-1), "rm is not allowed");
    let sleeper = r[2].as_i64().expect("a pid");
    // The allowed program ran with its argument (no shell, no quoting).
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(30);
    while !made.exists() {
        assert!(
            std::time::Instant::now() < deadline,
            "touch never made {}",
            made.display()
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    assert!(dir.exists(), "the refused rm did not run");
    // Stopping ends what the run started.
    sc.sim.stop();
    let alive = std::path::Path::new(&format!("/proc/{sleeper}")).exists();
    assert!(!alive, "the sleep started by the run was ended and reaped at stop");
    let _ = std::fs::remove_dir_all(&dir);
}

/// V-REP 3's `removeModel` and `getSimulationStopping`, and 4.7's custom string data
/// names, as old scripts call them.
#[test]
fn remove_model_simulation_stopping_and_custom_string_data() {
    let scene = r#"
[[object]]
name = "cart"
kind = "dummy"
model_base = true

[[object]]
name = "wheel"
kind = "dummy"
parent = "cart"

[[object]]
name = "axle"
kind = "dummy"
parent = "wheel"

[[object]]
name = "floor"
kind = "dummy"
script = "probe.lua"
"#;
    let probe = r#"
function sysCall_init()
    local floor = sim.getObject('/floor')
    sim.writeCustomStringData(floor, 'note', 'hello')
    note = sim.readCustomStringData(floor, 'note')
    ok, notModel = pcall(sim.removeModel, floor)
    removed = sim.removeModel(sim.getObject('/cart'))
    left = #sim.getObjectsInTree(sim.handle_scene)
end
function sysCall_actuation()
    stopping = sim.getSimulationStopping()
end
function sysCall_cleanup()
    sim.addLog(sim.verbosity_scriptinfos, 'stopping at cleanup: ' .. tostring(sim.getSimulationStopping()))
end
function report() return note, notModel, removed, left, stopping end
"#;
    let mut sc = Scene::new(
        "remove-model",
        scene,
        &[("probe.lua", probe)],
        gantry_lua::ScriptLimits::default(),
    );
    sc.sim.start();
    sc.sim.step();
    let r = sc.call("report", &[]);
    assert_eq!(r[0], Value::from("hello"));
    let Value::Str(e) = &r[1] else { panic!("{r:?}") };
    assert_contains(e, &["not a model base", "removeModel"]);
    assert_eq!(r[2], Value::Int(3), "the base and the two objects below it");
    assert_eq!(r[3], Value::Int(1), "only the floor is left");
    assert_eq!(r[4], Value::Bool(false), "an ordinary pass is not the last");
    sc.sim.stop();
    let log = log_lines(&sc.sim);
    assert!(
        log.iter().any(|(_, _, m)| m == "stopping at cleanup: true"),
        "the cleanup pass is the stopping one: {log:?}"
    );
}

/// CoppeliaSim's `matrix` library as scripts use it: a mobile base's inverse kinematics
/// (`Matrix(3, 3, data) * (1 / r)`, `Vector3{...}`, a product, `v[i]`), and the rest of
/// the everyday surface.
#[test]
fn the_matrix_library_builds_multiplies_and_indexes() {
    let script = r#"
function sysCall_init()
    require 'matrix'
    local L, r = 0.135, 0.04
    local Minv = Matrix(3, 3, {-math.sqrt(3) / 2, 0.5, L, 0.0, -1.0, L, math.sqrt(3) / 2, 0.5, L}) * (1 / r)
    local v = Minv * Vector3{1, 0, 0}
    wheels = {v[1], v[2], v[3]}
    local m = Matrix{{1, 2}, {3, 4}}
    local t = m:t()
    local e = Matrix:eye(2)
    checks = {
        m[2][1], t:get(1, 2), (m * e == m) and 1 or 0, #m, m:rows() * 10 + m:cols(),
        Vector{3, 4}:norm(), Vector3{1, 0, 0}:cross(Vector3{0, 1, 0})[3],
        Vector{1, 2, 3}:dot(Vector{4, 5, 6}), (m + m - m):sum(), (-m):abs():sum(), (m / 2)[1][2],
    }
    ok1, shapeErr = pcall(function() return m * Vector3{1, 2, 3} end)
    ok2, sizeErr = pcall(Vector3, {1, 2})
    local w = Vector(2)
    w[2] = 5
    text = tostring(w)
    -- The shared metatables are hidden: no script can change another's matrices.
    hidden = getmetatable(w) == 'Matrix' and not pcall(setmetatable, w, {})
        and not pcall(setmetatable, Matrix, {})
end
function report()
    return table.concat(wheels, ','), table.concat(checks, ','), shapeErr, sizeErr, text, hidden
end
"#;
    let mut s = Scene::rover("matrix", script);
    let r = s.call("report", &[]);
    let Value::Str(wheels) = &r[0] else { panic!("{r:?}") };
    let w: Vec<f64> = wheels.split(',').map(|x| x.parse().unwrap()).collect();
    let k = 1.0 / 0.04;
    assert_close(&w, &[-(3f64.sqrt()) / 2.0 * k, 0.0, 3f64.sqrt() / 2.0 * k], 1e-12);
    assert_eq!(r[1], Value::from("3,3,1,2,22,5.0,1,32,10,10,1.0"));
    let (Value::Str(shape), Value::Str(size), Value::Str(text)) = (&r[2], &r[3], &r[4]) else {
        panic!("{r:?}")
    };
    assert_contains(shape, &["2 x 2 times 3 x 1", "inner sizes differ"]);
    assert_contains(size, &["Vector3", "expected 3 x 1, got 2 x 1"]);
    assert_eq!(text, "Matrix(2, 1, {[0], [5]})");
    assert_eq!(r[5], Value::Bool(true), "the shared metatables are protected");
}

/// V-REP 3's global names (`simGetObjectHandle`, `sim_handle_parent`) reach the same
/// functions as `sim.*`, and a script's own globals win.
#[test]
fn v_rep_3_global_names_reach_the_api() {
    let script = r#"
function simMyHelper() return 'mine' end
function sysCall_init()
    local h = simGetObjectHandle('bubbleRob')
    local m = simGetObjectMatrix(h, -1)
    local inv = simGetInvertedMatrix(m)
    results = {
        h == sim.getObject('/bubbleRob') and 1 or 0,
        sim_handle_parent == sim.handle_parent and 1 or 0,
        math.abs(simMultiplyMatrices(m, inv)[1] - 1) < 1e-12 and 1 or 0,
        simMyHelper(),
        tostring(simNoSuchFunction),
        tostring(sim_no_such_constant),
        type(simExtRosInterface_advertise),
    }
end
function report() return table.concat(results, ',') end
"#;
    let mut s = Scene::rover("vrep3-names", script);
    assert_eq!(s.call("report", &[]), [Value::from("1,1,1,mine,nil,nil,function")]);
}

/// The selection as V-REP 3 to CoppeliaSim 4.4 scripts edit it.
#[test]
fn add_and_remove_objects_from_the_selection() {
    let scene = r#"
[[object]]
name = "base"
kind = "dummy"

[[object]]
name = "arm"
kind = "dummy"
parent = "base"

[[object]]
name = "tip"
kind = "dummy"
parent = "arm"

[[object]]
name = "probe"
kind = "dummy"
script = "probe.lua"
"#;
    let probe = r#"
local function names()
    local out = {}
    for _, h in ipairs(sim.getObjectSel()) do out[#out + 1] = sim.getObjectAlias(h) end
    return table.concat(out, ' ')
end
function sysCall_init()
    local base, arm, tip = sim.getObject('/base'), sim.getObject('/base/arm'), sim.getObject('/base/arm/tip')
    steps = {}
    sim.addObjectToSelection(sim.handle_single, arm); steps[#steps + 1] = names()
    sim.addObjectToSelection(sim.handle_tree, base); steps[#steps + 1] = names()
    sim.removeObjectFromSelection(sim.handle_chain, arm); steps[#steps + 1] = names()
    sim.removeObjectFromSelection(sim.handle_all, -1); steps[#steps + 1] = names()
    sim.addObjectToSelection({tip, base}); steps[#steps + 1] = names()
    ok, err = pcall(sim.addObjectToSelection, 5, tip)
end
function report() return table.concat(steps, '|'), err end
"#;
    let mut sc = Scene::new(
        "selection",
        scene,
        &[("probe.lua", probe)],
        gantry_lua::ScriptLimits::default(),
    );
    sc.sim.start();
    let r = sc.call("report", &[]);
    assert_eq!(r[0], Value::from("arm|arm base tip|tip||tip base"));
    let Value::Str(e) = &r[1] else { panic!("{r:?}") };
    assert_contains(e, &["sim.handle_single", "addObjectToSelection"]);
}

/// V-REP 3's depth buffer: a table, normalised or (with the flag) in metres, the same
/// depths as `sim.getVisionSensorDepth`.
#[test]
fn vision_sensor_depth_buffer_as_v_rep_3_returned_it() {
    let script = r#"
function sysCall_sensing()
    local cam = sim.getObject('/bubbleRob/visionSensor')
    sim.handleVisionSensor(cam)
    local buf = sim.getVisionSensorDepthBuffer(cam)
    local metres = sim.getVisionSensorDepthBuffer(cam + sim.handleflag_depthbuffermeters)
    local packed, res = sim.getVisionSensorDepth(cam, 1)
    local ref = sim.unpackFloatTable(packed)
    local part = sim.getVisionSensorDepthBuffer(cam, 1, 1, 2, 3)
    local inRange, same = true, true
    for i = 1, #buf do
        if buf[i] < 0 or buf[i] > 1 then inRange = false end
        if math.abs(metres[i] - ref[i]) > 1e-6 then same = false end
    end
    result = {#buf == res[1] * res[2] and 1 or 0, inRange and 1 or 0, same and 1 or 0, #part}
end
function report() return table.concat(result, ',') end
"#;
    let mut s = Scene::rover("depth-buffer", script);
    s.sim.step();
    assert_eq!(s.call("report", &[]), [Value::from("1,1,1,6")]);
}

/// V-REP 3's model properties: `sim.modelproperty_not_dynamic` on a model base holds
/// its shapes still (the kinematic mode V-REP 3 rover scripts switch to) and clearing
/// it lets them fall again; `not_model` bits turn the base into an ordinary object.
#[test]
fn model_properties_hold_a_model_still_and_release_it() {
    let scene = r#"
[[object]]
name = "cart"
kind = "dummy"
model_base = true
position = [0, 0, 1]

[[object]]
name = "box"
kind = "shape"
shape = "box"
size = [0.1, 0.1, 0.1]
parent = "cart"
dynamic = true
script = "probe.lua"
"#;
    let probe = r#"
function sysCall_init()
    cart = sim.getObject('/cart')
    box = sim.getObject('/cart/box')
    before = sim.getModelProperty(cart)
    boxProp = sim.getModelProperty(box)
    sim.setModelProperty(cart, sim.boolOr32(before, sim.modelproperty_not_dynamic))
    held = sim.getModelProperty(cart)
    special = sim.getObjectSpecialProperty(box)
    sim.setObjectSpecialProperty(box, 0)
    sim.setObjectProperty(box, sim.objectproperty_selectable)
    ok, err = pcall(sim.setModelProperty, cart, 0x10000)
end
function release()
    sim.setModelProperty(cart, sim.getModelProperty(cart) - sim.modelproperty_not_dynamic)
end
function report()
    return before, boxProp, held, special, sim.getObjectSpecialProperty(box), sim.getObjectProperty(box), err,
        sim.getObjectPosition(box, -1)[3]
end
"#;
    let mut sc = Scene::new(
        "model-property",
        scene,
        &[("probe.lua", probe)],
        gantry_lua::ScriptLimits::default(),
    );
    sc.sim.start();
    for _ in 0..20 {
        sc.sim.step();
    }
    let r = sc.call("report", &[]);
    assert_eq!(r[0], Value::Int(0), "a model base without overrides");
    assert_eq!(
        r[1],
        Value::Int(0xf000),
        "a shape that is no model says sim.modelproperty_not_model"
    );
    assert_eq!(r[2], Value::Int(0x20));
    assert_eq!(
        r[3],
        Value::Int(0x3f3),
        "a shape is collidable, measurable, detectable and renderable"
    );
    assert_eq!(r[4], Value::Int(0));
    assert_eq!(r[5], Value::Int(0x20));
    assert_contains(text(&r[6]), &["setModelProperty", "does not define"]);
    assert_close(&[num(&r[7])], &[1.0], 1e-9);
    sc.call("release", &[]);
    for _ in 0..10 {
        sc.sim.step();
    }
    let z = num(&sc.call("report", &[])[7]);
    assert!(z < 0.9, "the box falls once the model is dynamic again: z = {z}");
}

/// Old names and small functions V-REP 3 and CoppeliaSim 4.0 scripts call: a pure shape
/// (`sim.createPureShape`: a dynamic, respondable cuboid that falls), the string
/// parameters, a message box answered at once, a matrix inverted in place, a free
/// thread, the float image setter, object colours and a collection's objects.
#[test]
fn pure_shapes_string_parameters_message_boxes_and_in_place_inverses() {
    let scene = r#"
[[object]]
name = "camera"
kind = "vision_sensor"
resolution = [2, 1]
script = "probe.lua"
"#;
    let probe = r#"
function sysCall_init()
    cube = sim.createPureShape(0, 8, {0.1, 0.1, 0.1}, 0.5)
    sim.setObjectPosition(cube, -1, {0, 0, 1})
    ok, badType = pcall(sim.createPureShape, 7, 0, {0.1, 0.1, 0.1}, 1)
    sceneName = sim.getStringParameter(sim.stringparam_scene_name)
    scenePath = sim.getStringParam(sim.stringparam_scene_path)
    answer = sim.msgBox(sim.msgbox_type_question, sim.msgbox_buttons_yesno, 'Quit?', 'Really?')
    uiAnswer = simUI.msgBox(simUI.msgbox_type_info, simUI.msgbox_buttons_ok, 'Note', 'Saved')
    m = {1, 0, 0, 1, 0, 1, 0, 2, 0, 0, 1, 3}
    inverted = sim.invertMatrix(m)
    colorSet = sim.setObjectColor(cube, 0, sim.colorcomponent_ambient_diffuse, {1, 0, 0})
    color = sim.getObjectColor(cube, 0, sim.colorcomponent_ambient_diffuse)
    noColor = sim.setObjectColor(sim.getObject('/camera'), 0, sim.colorcomponent_ambient_diffuse, {1, 0, 0})
    local c = sim.createCollection(0)
    sim.addItemToCollection(c, sim.handle_single, cube, 0)
    members = sim.getCollectionObjects(c)
    local cam = sim.getObject('/camera')
    sim.setVisionSensorImage(cam, {1, 0, 0, 0, 0.5, 1})
    img = sim.getVisionSensorImg(cam)
end
function report()
    return cube, sim.getObjectPosition(cube, -1)[3], badType, sceneName, scenePath, answer, uiAnswer, m,
        inverted, colorSet, color, noColor, members, img
end
"#;
    let mut sc = Scene::new(
        "pure-shape",
        scene,
        &[("probe.lua", probe)],
        gantry_lua::ScriptLimits::default(),
    );
    sc.sim.start();
    for _ in 0..10 {
        sc.sim.step();
    }
    let r = sc.call("report", &[]);
    let z = num(&r[1]);
    assert!(
        z < 0.95,
        "a pure shape without option bit 4 is dynamic and falls: z = {z}"
    );
    assert_contains(text(&r[2]), &["createPureShape", "invalid primitive type 7"]);
    assert!(text(&r[3]).ends_with(".toml"), "{:?}", r[3]);
    assert!(!text(&r[4]).is_empty());
    assert_eq!(r[5], Value::Int(2), "a yes/no box is answered yes");
    assert_eq!(r[6], Value::Int(3), "an OK box is answered OK");
    assert_close(
        &floats(&r[7]),
        &[1.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0, -2.0, 0.0, 0.0, 1.0, -3.0],
        1e-12,
    );
    assert_eq!(r[8], Value::Int(1));
    assert_eq!(r[9], Value::Bool(true));
    assert_close(&floats(&r[10]), &[1.0, 0.0, 0.0], 1e-12);
    assert_eq!(r[11], Value::Bool(false), "a vision sensor has no colour 0");
    assert_eq!(ints(&r[12]), vec![int(&r[0])]);
    assert_eq!(r[13], Value::Bytes(vec![255, 0, 0, 0, 128, 255]));
    let log = log_lines(&sc.sim);
    assert!(log.iter().any(|(_, _, m)| m == "Quit?: Really?"), "{log:?}");
}

/// `sim.saveImage` writes PNG files in the scene's folder (or returns the encoded file
/// for a bare extension) and `sim.loadImage` reads them back; writing outside the
/// folder and other formats are refused.
#[test]
fn images_are_saved_and_loaded_as_png_in_the_scene_folder() {
    let probe = r#"
function sysCall_init()
    local img = string.char(255, 0, 0, 0, 255, 0, 0, 0, 255, 10, 20, 30)
    sim.saveImage(img, {2, 2}, 0, 'shot.png', -1)
    encoded = sim.saveImage(img, {2, 2}, 0, '.png', -1)
    loaded, res = sim.loadImage(0, 'shot.png')
    rgba = sim.loadImage(1, 'shot.png')
    okJpg, jpgErr = pcall(sim.saveImage, img, {2, 2}, 0, 'shot.jpg', 90)
    okOut, outErr = pcall(sim.saveImage, img, {2, 2}, 0, '../outside.png', -1)
    okSize, sizeErr = pcall(sim.saveImage, img, {3, 2}, 0, 'shot.png', -1)
end
function report()
    return loaded, res, #rgba, encoded:sub(2, 4), jpgErr, outErr, sizeErr
end
"#;
    let mut sc = Scene::new(
        "save-image",
        util::PROBE_ONLY_SCENE,
        &[("probe.lua", probe)],
        gantry_lua::ScriptLimits::default(),
    );
    sc.sim.start();
    sc.sim.step();
    let r = sc.call("report", &[]);
    assert_eq!(r[0], Value::Bytes(vec![255, 0, 0, 0, 255, 0, 0, 0, 255, 10, 20, 30]));
    assert_eq!(ints(&r[1]), vec![2, 2]);
    assert_eq!(r[2], Value::Int(16));
    assert_eq!(text(&r[3]), "PNG");
    assert_contains(text(&r[4]), &["saveImage", "PNG"]);
    assert_contains(text(&r[5]), &["saveImage", "outside the scene's folder"]);
    assert_contains(text(&r[6]), &["saveImage", "18 bytes"]);
}

/// V-REP 3's free threads: `sim.setThreadIsFree` is accepted (gantry's threads are
/// coroutines whose blocking calls yield) and the thread goes on.
#[test]
fn a_free_thread_goes_on() {
    let probe = r#"
function sysCall_threadmain()
    freed = sim.setThreadIsFree(true)
    sim.switchThread()
    sim.setThreadIsFree(false)
    done = true
end
function report() return freed, done end
"#;
    let mut sc = Scene::new(
        "free-thread",
        util::PROBE_ONLY_SCENE,
        &[("probe.lua", probe)],
        gantry_lua::ScriptLimits::default(),
    );
    sc.sim.start();
    for _ in 0..3 {
        sc.sim.step();
    }
    assert_eq!(sc.call("report", &[]), vec![Value::Int(1), Value::Bool(true)]);
}

/// `sim.createMeshShape` builds a shape from a script's triangles (checked indices),
/// and `sim.getApiFunc` lists the API's functions by prefix or part of a name.
#[test]
fn mesh_shapes_from_script_triangles_and_the_api_listing() {
    let probe = r#"
function sysCall_init()
    local h = sim.createMeshShape(0, 0, {0, 0, 0, 0.5, 0, 0, 0, 0.25, 0, 0, 0, 0.1}, {0, 1, 2, 0, 1, 3})
    size = sim.getShapeBB(h)
    kind = sim.getObjectType(h)
    ok1, badIndex = pcall(sim.createMeshShape, 0, 0, {0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 3})
    ok2, badVertices = pcall(sim.createMeshShape, 0, 0, {0, 0}, {0, 1, 2})
    prefixed = sim.getApiFunc(-1, '+sim.getObjectPos')
    containing = sim.getApiFunc(-1, 'ObjectPosition')
end
function report() return size, kind, badIndex, badVertices, prefixed, containing end
"#;
    let mut sc = Scene::new(
        "mesh-shape",
        util::PROBE_ONLY_SCENE,
        &[("probe.lua", probe)],
        gantry_lua::ScriptLimits::default(),
    );
    sc.sim.start();
    sc.sim.step();
    let r = sc.call("report", &[]);
    assert_close(&floats(&r[0]), &[0.5, 0.25, 0.1], 1e-6);
    assert_eq!(r[1], Value::Int(0), "a shape");
    assert_contains(text(&r[2]), &["createMeshShape", "index 3 is not a vertex"]);
    assert_contains(text(&r[3]), &["createMeshShape", "triples"]);
    let names = |v: &Value| -> Vec<String> {
        let Value::Array(items) = v else { panic!("{v:?}") };
        items.iter().map(|s| text(s).to_owned()).collect()
    };
    assert_eq!(names(&r[4]), ["sim.getObjectPose", "sim.getObjectPosition"]);
    let containing = names(&r[5]);
    assert!(
        containing.contains(&"sim.setObjectPosition".to_owned()),
        "{containing:?}"
    );
    assert!(
        containing.contains(&"sim.getObjectPosition".to_owned()),
        "{containing:?}"
    );
}
