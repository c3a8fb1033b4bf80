//! The script lifecycle: hook order, per-script globals, `'.'`, runtime errors, the time
//! and memory budgets, the sandbox, hot reload, `check_syntax` and `print`.

use crate::util;
use util::Drive;

use std::time::{Duration, Instant, SystemTime};

use gantry_engine::Engine;
use gantry_lua::{ScriptLimits, ScriptState, check_syntax};
use gantry_sim_core::Value;
use gantry_test_support::{TempDir, assert_close, assert_contains, floats, int, load, repo};
use util::{Scene, log_lines, messages_from, script_error, script_state, world_position};

fn s(v: &str) -> Value {
    Value::Str(v.to_owned())
}

/// The value of an Int32 signal, `None` when unset.
fn signal(sim: &mut Engine, name: &str) -> Option<i64> {
    match sim.call("getInt32Signal", &[s(name)]).expect("signal")[0] {
        Value::Int(v) => Some(v),
        Value::Nil => None,
        ref other => panic!("{other:?}"),
    }
}

/// A script that logs each hook's name with `print`.
const TRACER: &str = "function sysCall_init() print('init') end
function sysCall_actuation() print('actuation') end
function sysCall_sensing() print('sensing') end
function sysCall_cleanup() print('cleanup') end
";

#[test]
fn hooks_run_in_coppeliasim_order_children_first() {
    let toml = r#"
[[object]]
name = "parent"
kind = "dummy"
script = "parent.lua"

[[object]]
name = "child"
kind = "dummy"
parent = "parent"
script = "child.lua"

[[object]]
name = "grandchild"
kind = "dummy"
parent = "child"
script = "grandchild.lua"

[[object]]
name = "sibling"
kind = "dummy"
parent = "parent"
script = "sibling.lua"
"#;
    let mut sc = Scene::new(
        "order",
        toml,
        &[
            ("parent.lua", TRACER),
            ("child.lua", TRACER),
            ("grandchild.lua", TRACER),
            ("sibling.lua", TRACER),
        ],
        ScriptLimits::default(),
    );
    for _ in 0..2 {
        sc.sim.step();
    }
    sc.sim.stop();
    let trace: Vec<String> = log_lines(&sc.sim)
        .into_iter()
        .filter(|(src, _, _)| src.ends_with(".lua"))
        .map(|(src, _, m)| format!("{}:{m}", src.trim_end_matches(".lua")))
        .collect();
    let each = |hook: &str| {
        ["grandchild", "child", "sibling", "parent"]
            .iter()
            .map(|s| format!("{s}:{hook}"))
            .collect::<Vec<_>>()
    };
    let mut expected = each("init");
    for _ in 0..2 {
        expected.extend(each("actuation"));
        expected.extend(each("sensing"));
    }
    expected.extend(each("cleanup"));
    assert_eq!(trace, expected);
}

#[test]
fn actuation_runs_before_physics_and_sensing_after() {
    let toml = r#"
[[object]]
name = "ball"
kind = "shape"
shape = "sphere"
radius = 0.1
mass = 1.0
dynamic = true
position = [0, 0, 10]
script = "probe.lua"
"#;
    let body = "zs = {}
        local function z() return sim.getObjectPosition(sim.getObject('.'))[3] end
        function sysCall_init() zs[#zs + 1] = z() end
        function sysCall_actuation()
            zs[#zs + 1] = z()
            if sim.getSimulationTime() > 0.1 and not moved then
                moved = true
                sim.setObjectPosition(sim.getObject('.'), {0, 0, 20})
            end
        end
        function sysCall_sensing() zs[#zs + 1] = z() end
        function t() return zs end";
    let mut sc = Scene::new("physicsorder", toml, &[("probe.lua", body)], ScriptLimits::default());
    for _ in 0..4 {
        sc.sim.step();
    }
    let zs = floats(&sc.call("t", &[])[0]);
    // init, then (actuation, sensing) for 4 steps.
    assert_eq!(zs.len(), 9, "{zs:?}");
    assert_eq!(zs[0], 10.0);
    assert_eq!(zs[1], 10.0, "the first actuation precedes any physics");
    assert!(zs[2] < zs[1], "sensing sees this step's physics: {zs:?}");
    assert_eq!(zs[3], zs[2], "the next actuation sees the same state");
    assert!(zs[4] < zs[3]);
    // Step 4 (t = 0.15): teleported to 20 in actuation, sensing sees it after physics.
    assert!(zs[8] > 19.9 && zs[8] < 20.0, "{zs:?}");
}

#[test]
fn each_script_has_its_own_globals_and_dot_is_its_object() {
    let toml = format!(
        "{}\n[[script]]\nobject = \"leftMotor\"\nfile = \"a.lua\"\n\n[[script]]\nobject = \"rightMotor\"\nfile = \"b.lua\"\n",
        util::bubble_rob_toml(None)
    );
    let a = "counter = 1
        function sysCall_init()
            local me = sim.getObject('.')
            sim.setInt32Signal('a.self', me)
            sim.setInt32Signal('a.parent', sim.getObject('..'))
            sim.setInt32Signal('a.wheel', sim.getObject('./leftWheel'))
            sim.setStringSignal('a.alias', sim.getObjectAlias(me))
        end
        function sysCall_actuation()
            counter = counter + 1
            sim.setInt32Signal('a.counter', counter)
            sim.setInt32Signal('a.seesSecret', secret == nil and 0 or 1)
        end";
    let b = "counter = 100
        secret = 'b only'
        function sysCall_init()
            sim.setInt32Signal('b.self', sim.getObject('.'))
            sim.setInt32Signal('b.wheel', sim.getObject('./rightWheel'))
        end
        function sysCall_actuation()
            counter = counter + 1
            sim.setInt32Signal('b.counter', counter)
        end";
    let mut sc = Scene::new("globals", &toml, &[("a.lua", a), ("b.lua", b)], ScriptLimits::default());
    for _ in 0..3 {
        sc.sim.step();
    }
    let sim = &mut sc.sim;
    assert_eq!(signal(sim, "a.counter"), Some(4));
    assert_eq!(signal(sim, "b.counter"), Some(103));
    assert_eq!(signal(sim, "a.seesSecret"), Some(0));
    assert_eq!(signal(sim, "a.self"), Some(util::find(sim, "/bubbleRob/leftMotor")));
    assert_eq!(signal(sim, "a.parent"), Some(util::find(sim, "/bubbleRob")));
    assert_eq!(signal(sim, "a.wheel"), Some(util::find(sim, "/bubbleRob/leftWheel")));
    assert_eq!(signal(sim, "b.self"), Some(util::find(sim, "/bubbleRob/rightMotor")));
    assert_eq!(signal(sim, "b.wheel"), Some(util::find(sim, "/bubbleRob/rightWheel")));
    assert_eq!(
        sim.call("getStringSignal", &[s("a.alias")]).expect("signal"),
        vec![Value::Bytes(b"leftMotor".to_vec())]
    );
    // Stop runs cleanup and restores the scene; the next start begins afresh.
    sim.stop();
    sim.call("clearInt32Signal", &[]).expect("clear");
    sim.step();
    assert_eq!(signal(sim, "a.counter"), Some(2));
    assert_eq!(signal(sim, "b.counter"), Some(101));
}

#[test]
fn a_runtime_error_stops_only_that_script() {
    let toml = r#"
[[object]]
name = "good"
kind = "dummy"
script = "good.lua"

[[object]]
name = "bad"
kind = "dummy"
script = "bad.lua"
"#;
    let bad = "function sysCall_init() n = 0 end
function sysCall_actuation()
    n = n + 1
    sim.setInt32Signal('bad.actuation', n)
    if n == 3 then
        local t = nil
        t.field = 1
    end
end
function sysCall_sensing()
    sensed = (sensed or 0) + 1
    sim.setInt32Signal('bad.sensing', sensed)
end
function sysCall_cleanup() print('bad cleanup') end
";
    let good = "n = 0
function sysCall_actuation() n = n + 1; sim.setInt32Signal('good.actuation', n) end
";
    let mut sc = Scene::new(
        "runtimeerror",
        toml,
        &[("good.lua", good), ("bad.lua", bad)],
        ScriptLimits::default(),
    );
    for _ in 0..10 {
        sc.sim.step();
    }
    let sim = &mut sc.sim;
    assert_eq!(signal(sim, "bad.actuation"), Some(3));
    assert_eq!(signal(sim, "bad.sensing"), Some(2));
    assert_eq!(signal(sim, "good.actuation"), Some(10));
    assert!((sim.world().time() - 0.5).abs() < 1e-9);
    let e = script_error(sim, "bad.lua");
    assert_contains(&e, &["bad.lua:7:", "attempt to index"]);
    assert_contains(&e, &["traceback"]);
    assert_eq!(script_state(sim, "good.lua"), ScriptState::Running);
    let logged = messages_from(sim, "bad.lua");
    assert!(
        logged.iter().any(|m| m.contains("bad.lua:7:")),
        "the error is logged with file and line: {logged:?}"
    );
    // Errored scripts receive no hooks but cleanup, and no calls from transports.
    assert_eq!(sim.call_script_function("sysCall_sensing", &[]), Ok(None));
    sim.stop();
    assert!(messages_from(sim, "bad.lua").contains(&"bad cleanup".to_owned()));
}

#[test]
fn errors_at_load_and_in_init_stop_only_that_script() {
    let toml = r#"
[[object]]
name = "good"
kind = "dummy"
script = "good.lua"

[[object]]
name = "atload"
kind = "dummy"
script = "atload.lua"

[[object]]
name = "ininit"
kind = "dummy"
script = "ininit.lua"
"#;
    let mut sc = Scene::new(
        "initerror",
        toml,
        &[
            (
                "good.lua",
                "function sysCall_actuation() sim.setInt32Signal('good', 1) end",
            ),
            (
                "atload.lua",
                "local x = nil\nx()\nfunction sysCall_actuation() sim.setInt32Signal('atload', 1) end",
            ),
            (
                "ininit.lua",
                "function sysCall_init()\n  error('boom in init')\nend\nfunction sysCall_actuation() sim.setInt32Signal('ininit', 1) end",
            ),
        ],
        ScriptLimits::default(),
    );
    assert_contains(script_error(&sc.sim, "atload.lua"), &["atload.lua:2:"]);
    for _ in 0..3 {
        sc.sim.step();
    }
    assert_contains(script_error(&sc.sim, "ininit.lua"), &["ininit.lua:2:", "boom in init"]);
    assert_eq!(signal(&mut sc.sim, "good"), Some(1));
    assert_eq!(signal(&mut sc.sim, "atload"), None);
    assert_eq!(signal(&mut sc.sim, "ininit"), None);
}

const TWO_DUMMIES: &str = r#"
[[object]]
name = "good"
kind = "dummy"
script = "good.lua"

[[object]]
name = "rogue"
kind = "dummy"
script = "rogue.lua"
"#;

const COUNTER: &str = "n = 0\nfunction sysCall_actuation() n = n + 1; sim.setInt32Signal('good', n) end\n";

#[test]
fn an_infinite_loop_is_interrupted_and_the_simulation_continues() {
    let limits = ScriptLimits {
        time_budget: Duration::from_millis(200),
        ..ScriptLimits::default()
    };
    let rogue = "function sysCall_actuation()
    while true do end
end
function sysCall_cleanup() print('rogue cleanup') end
";
    let mut sc = Scene::new(
        "loop",
        TWO_DUMMIES,
        &[("good.lua", COUNTER), ("rogue.lua", rogue)],
        limits,
    );
    let t0 = Instant::now();
    sc.sim.step();
    let first = t0.elapsed();
    assert!(
        first >= Duration::from_millis(150) && first < Duration::from_secs(3),
        "the first step took {first:?}"
    );
    let t1 = Instant::now();
    for _ in 0..5 {
        sc.sim.step();
    }
    assert!(t1.elapsed() < Duration::from_secs(2), "later steps are fast");
    assert_eq!(signal(&mut sc.sim, "good"), Some(6));
    assert_contains(script_error(&sc.sim, "rogue.lua"), &["time budget"]);
    sc.sim.stop();
    assert!(messages_from(&sc.sim, "rogue.lua").contains(&"rogue cleanup".to_owned()));
}

#[test]

fn the_interrupt_error_says_where_the_loop_is() {
    let limits = ScriptLimits {
        time_budget: Duration::from_millis(200),
        ..ScriptLimits::default()
    };
    let rogue = "function sysCall_actuation()\n    while true do end\nend\n";
    let mut sc = Scene::new(
        "loopwhere",
        TWO_DUMMIES,
        &[("good.lua", COUNTER), ("rogue.lua", rogue)],
        limits,
    );
    sc.sim.step();
    assert_contains(
        script_error(&sc.sim, "rogue.lua"),
        &["time budget", "rogue.lua:2:", "traceback"],
    );
}

#[test]
fn loops_in_init_and_around_api_calls_are_interrupted() {
    let limits = ScriptLimits {
        time_budget: Duration::from_millis(200),
        ..ScriptLimits::default()
    };
    let rogue = "function sysCall_init() end
function sysCall_sensing()
    while true do sim.getObject('.') end
end
";
    let toml = format!("{TWO_DUMMIES}\n[[object]]\nname = \"initloop\"\nkind = \"dummy\"\nscript = \"initloop.lua\"\n");
    let mut sc = Scene::new(
        "loop2",
        &toml,
        &[
            ("good.lua", COUNTER),
            ("rogue.lua", rogue),
            ("initloop.lua", "function sysCall_init() while true do end end"),
        ],
        limits,
    );
    let t0 = Instant::now();
    for _ in 0..4 {
        sc.sim.step();
    }
    assert!(t0.elapsed() < Duration::from_secs(4), "{:?}", t0.elapsed());
    assert_eq!(signal(&mut sc.sim, "good"), Some(4));
    assert_contains(script_error(&sc.sim, "rogue.lua"), &["time budget"]);
    assert_contains(script_error(&sc.sim, "initloop.lua"), &["time budget"]);
}

#[test]

fn a_loop_that_catches_the_interrupt_is_still_stopped() {
    // `pcall` catches the interruption error; the budget must still end the hook. Run on
    // another thread so that a failure cannot hang the test run.
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let limits = ScriptLimits {
            time_budget: Duration::from_millis(200),
            ..ScriptLimits::default()
        };
        let rogue = "function sysCall_actuation()
    while true do pcall(function() while true do end end) end
end
";
        let mut sc = Scene::new(
            "pcallloop",
            TWO_DUMMIES,
            &[("good.lua", COUNTER), ("rogue.lua", rogue)],
            limits,
        );
        for _ in 0..3 {
            sc.sim.step();
        }
        let good = signal(&mut sc.sim, "good");
        let state = script_state(&sc.sim, "rogue.lua");
        let _ = tx.send((good, state));
    });
    let (good, state) = rx
        .recv_timeout(Duration::from_secs(10))
        .expect("a pcall-wrapped infinite loop hung the simulation");
    assert_eq!(good, Some(3));
    assert!(matches!(state, ScriptState::Errored(_)), "{state:?}");
}

#[test]
fn a_memory_bomb_fails_with_a_memory_error_and_the_simulation_continues() {
    let limits = ScriptLimits {
        memory: 64 << 20,
        ..ScriptLimits::default()
    };
    let rogue = "function sysCall_actuation()
    local t = {}
    for i = 1, 1e9 do t[i] = string.rep('x', 1000) end
end
";
    // The good script keeps allocating after the bomb.
    let good = "n = 0
function sysCall_actuation()
    n = n + 1
    local t = {}
    for i = 1, 1000 do t[i] = string.rep('y', 1000) .. i end
    sim.setInt32Signal('good', n)
    sim.setInt32Signal('goodLen', #t)
end
";
    let mut sc = Scene::new(
        "memory",
        TWO_DUMMIES,
        &[("good.lua", good), ("rogue.lua", rogue)],
        limits,
    );
    for _ in 0..5 {
        sc.sim.step();
    }
    assert_contains(script_error(&sc.sim, "rogue.lua"), &["memory"]);
    assert_eq!(signal(&mut sc.sim, "good"), Some(5));
    assert_eq!(signal(&mut sc.sim, "goodLen"), Some(1000));
    assert_eq!(script_state(&sc.sim, "good.lua"), ScriptState::Running);
}

#[test]
fn the_sandbox_has_no_process_file_or_code_loading_access() {
    let mut sc = Scene::rover(
        "sandbox",
        "function t()
            -- `require` serves the API's namespaces and the scene's own modules, `io`
            -- only files in allowed folders, and `debug` holds only `traceback` (see the
            -- sandbox, modules and files tests): the attempts below check the refusals.
            return type(os.execute), type(debug.getinfo), type(loadfile), type(dofile),
                type(load), type(loadstring), type(package), type(debug.sethook), type(os.exit),
                type(os.remove), type(os.rename), type(os.getenv), type(os.tmpname),
                type(_G.load)
        end
        function attempts()
            local opened = pcall(function() return io.open('/tmp/gantry-sandbox-probe', 'w') end)
            local popened = pcall(function() return io.popen('echo hi') end)
            local executed = pcall(function() return os.execute('true') end)
            local required = pcall(function() return require('os') end)
            local loaded = pcall(function() return load('return 1')() end)
            local dofiled = pcall(function() return dofile('/etc/hostname') end)
            local loadlib = pcall(function() return package.loadlib('libc.so.6', 'system') end)
            return opened, popened, executed, required, loaded, dofiled, loadlib
        end
        function safe()
            return type(string.format), type(table.insert), type(math.sin), type(os.time),
                type(os.clock), type(pcall), type(coroutine.create)
        end",
    );
    let r = sc.call("t", &[]);
    assert_eq!(r.len(), 14);
    for (k, v) in r.iter().enumerate() {
        assert_eq!(v, &s("nil"), "value {k} of t() is available: {r:?}");
    }
    let a = sc.call("attempts", &[]);
    assert_eq!(a, vec![Value::Bool(false); 7], "{a:?}");
    assert!(!std::path::Path::new("/tmp/gantry-sandbox-probe").exists());
    let safe = sc.call("safe", &[]);
    assert_eq!(safe, vec![s("function"); 7]);
}

/// Sets a file's modification time explicitly, so that reloads do not depend on the
/// file system's timestamp resolution.
fn touch(path: &std::path::Path, offset: Duration) {
    let f = std::fs::File::options().write(true).open(path).expect("open for touch");
    f.set_modified(SystemTime::now() + offset).expect("set mtime");
}

fn version(v: u32) -> String {
    format!(
        "function sysCall_init() print('init v{v} at ' .. sim.getSimulationTime()) end
function sysCall_actuation() sim.setInt32Signal('version', {v}) end
function sysCall_cleanup() print('cleanup v{v}') end
"
    )
}

const HOT: &str = r#"
[[object]]
name = "holder"
kind = "dummy"
script = "hot.lua"

[[object]]
name = "ball"
kind = "shape"
shape = "sphere"
radius = 0.1
dynamic = true
position = [0, 0, 10]
"#;

#[test]
fn hot_reload_swaps_the_script_and_keeps_the_world() {
    let mut sc = Scene::new("hotreload", HOT, &[("hot.lua", &version(1))], ScriptLimits::default());
    let path = sc.dir.path().join("hot.lua");
    for _ in 0..5 {
        sc.sim.step();
    }
    assert_eq!(signal(&mut sc.sim, "version"), Some(1));
    // Unchanged files are not reloaded.
    sc.sim.reload_changed();
    assert!(!messages_from(&sc.sim, "hot.lua").contains(&"cleanup v1".to_owned()));

    let ball = util::find(&sc.sim, "/ball");
    let before = world_position(&sc.sim, ball);
    std::fs::write(&path, version(2)).expect("write v2");
    touch(&path, Duration::from_secs(5));
    sc.sim.reload_changed();
    let msgs = messages_from(&sc.sim, "hot.lua");
    let cleanup = msgs.iter().position(|m| m == "cleanup v1");
    let init = msgs.iter().position(|m| m == "init v2 at 0.25");
    assert!(
        cleanup.is_some() && init.is_some() && cleanup < init,
        "old cleanup, then new init at the current time: {msgs:?}"
    );
    assert_eq!(world_position(&sc.sim, ball), before, "the world is kept");
    assert!((sc.sim.world().time() - 0.25).abs() < 1e-12);
    sc.sim.step();
    assert_eq!(signal(&mut sc.sim, "version"), Some(2));
    assert!(world_position(&sc.sim, ball)[2] < before[2], "physics goes on");

    // A syntax error keeps v2 running and reports file and line.
    std::fs::write(
        &path,
        "function sysCall_actuation()\n  sim.setInt32Signal('version', 3\nend\n",
    )
    .expect("write v3");
    touch(&path, Duration::from_secs(10));
    sc.sim.reload_changed();
    sc.sim.step();
    assert_eq!(signal(&mut sc.sim, "version"), Some(2));
    assert_eq!(script_state(&sc.sim, "hot.lua"), ScriptState::Running);
    let msgs = messages_from(&sc.sim, "hot.lua");
    assert!(
        msgs.iter()
            .any(|m| m.contains("reload failed") && m.contains("hot.lua:")),
        "{msgs:?}"
    );
    assert!(!msgs.contains(&"cleanup v2".to_owned()));

    // An explicit reload of the fixed file.
    std::fs::write(&path, version(4)).expect("write v4");
    sc.sim.reload(0);
    sc.sim.step();
    assert_eq!(signal(&mut sc.sim, "version"), Some(4));
    assert!(messages_from(&sc.sim, "hot.lua").contains(&"cleanup v2".to_owned()));
}

#[test]

fn a_hot_reloaded_script_survives_stop_and_restart() {
    let mut sc = Scene::new("hotrestart", HOT, &[("hot.lua", &version(1))], ScriptLimits::default());
    let path = sc.dir.path().join("hot.lua");
    sc.sim.step();
    std::fs::write(&path, version(2)).expect("write v2");
    touch(&path, Duration::from_secs(5));
    sc.sim.reload_changed();
    sc.sim.step();
    assert_eq!(signal(&mut sc.sim, "version"), Some(2));
    sc.sim.stop();
    sc.sim.call("clearInt32Signal", &[]).expect("clear");
    sc.sim.reload_changed();
    sc.sim.step();
    assert_eq!(signal(&mut sc.sim, "version"), Some(2), "the edited file on disk is v2");
}

#[test]
fn check_syntax_reports_file_and_line() {
    let dir = TempDir::new("checksyntax");
    dir.write(
        "good.lua",
        "function sysCall_actuation() sim.setInt32Signal('good', 1) end\n",
    );
    dir.write(
        "broken.lua",
        "function sysCall_init()\n  local x = 1\n  if x then\nend\n",
    );
    let scene = dir.write(
        "scene.toml",
        "[[object]]\nname = \"a\"\nkind = \"dummy\"\nscript = \"good.lua\"\n\n\
         [[object]]\nname = \"b\"\nkind = \"dummy\"\nscript = \"broken.lua\"\n",
    );
    let model = load(&scene);
    let errors = check_syntax(&model);
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_contains(&errors[0], &["broken.lua:", "end"]);
    // The line is where Lua noticed the missing `end`: the end of the file, line 4 or 5.
    assert!(
        errors[0].contains("broken.lua:4:") || errors[0].contains("broken.lua:5:"),
        "{errors:?}"
    );
    let mut sim = util::engine(model, ScriptLimits::default()).expect("builds");
    assert_contains(script_error(&sim, "broken.lua"), &["broken.lua:"]);
    sim.step();
    assert_eq!(signal(&mut sim, "good"), Some(1));
    let clean = load(&repo("assets/scenes/bubble_rob.toml"));
    assert_eq!(check_syntax(&clean), Vec::<String>::new());
}

#[test]
fn print_goes_to_the_log_with_the_script_name() {
    let mut sc = Scene::rover(
        "print",
        "function sysCall_init() print('hello', 42, nil, true, 1.5) end
        function sysCall_sensing() print('step ' .. sim.getSimulationTime()) end",
    );
    sc.sim.step();
    let lines = log_lines(&sc.sim);
    assert!(
        lines
            .iter()
            .any(|(src, _, m)| src == "probe.lua" && m == "hello\t42\tnil\ttrue\t1.5"),
        "{lines:?}"
    );
    assert!(
        lines.iter().any(|(src, _, m)| src == "probe.lua" && m == "step 0.0"),
        "{lines:?}"
    );
}

#[test]
fn cleanup_runs_on_process_exit() {
    let mut sc = Scene::rover(
        "exit",
        "function sysCall_cleanup() print('bye at ' .. sim.getSimulationTime()) end",
    );
    for _ in 0..2 {
        sc.sim.step();
    }
    sc.sim.cleanup();
    assert_eq!(messages_from(&sc.sim, "probe.lua"), vec!["bye at 0.1".to_owned()]);
    assert_eq!(int(&sc.remote("getSimulationState", &[])[0]), 0);
    // Cleanup runs once.
    sc.sim.cleanup();
    assert_eq!(messages_from(&sc.sim, "probe.lua").len(), 1);
    assert_close(&[sc.sim.world().time()], &[0.1], 1e-12);
}
