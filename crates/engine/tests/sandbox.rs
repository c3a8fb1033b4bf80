//! The script sandbox (issue 9, security): one test per way a script might try to reach
//! the machine, the process or the other scripts. Each asserts that the attempt fails
//! with an error that names what was refused, and that the simulation carries on: the
//! script keeps receiving hooks and the world keeps stepping.

use crate::util;
use util::Drive;

use std::path::Path;
use std::time::{Duration, Instant};

use gantry_lua::sandbox::{REMOVED_GLOBALS, REMOVED_OS};
use gantry_lua::{ScriptLimits, ScriptState};
use gantry_sim_core::Value;
use gantry_test_support::{TempDir, assert_contains, load, text};
use util::{LUA_ERR, Scene, script_error, script_state};

/// One dummy carrying `probe.lua`, and a graph for the export tests.
const PROBE_SCENE: &str = r#"
[[object]]
name = "probe"
kind = "dummy"
script = "probe.lua"

[[object]]
name = "plot"
kind = "graph"
"#;

/// Counts its actuation hooks in the `steps` signal, so a test can tell that the
/// script still runs after an attempt.
const PROBE_PRELUDE: &str = "
steps = 0
function sysCall_actuation()
    steps = steps + 1
    sim.setInt32Signal('steps', steps)
end
";

fn s(v: &str) -> Value {
    Value::Str(v.to_owned())
}

/// The probe scene with `body` as the body of the script function `attempt()`, started.
fn probe_scene(tag: &str, body: &str) -> Scene {
    let source = format!(
        "{PROBE_PRELUDE}\nfunction attempt()\n{body}\nend\nfunction probe() return err(attempt) end\n{LUA_ERR}"
    );
    let mut sc = Scene::new(tag, PROBE_SCENE, &[("probe.lua", &source)], ScriptLimits::default());
    sc.sim.start();
    sc
}

/// Asserts that the probe script still runs and the world still steps.
#[track_caller]
fn assert_carries_on(sc: &mut Scene) {
    let before = sc.sim.world().steps();
    for _ in 0..3 {
        sc.sim.step();
    }
    assert_eq!(sc.sim.world().steps(), before + 3, "the world stopped stepping");
    assert_eq!(script_state(&sc.sim, "probe.lua"), ScriptState::Running);
    let steps = sc.sim.call("getInt32Signal", &[s("steps")]).expect("signal");
    assert!(
        matches!(steps[0], Value::Int(n) if n >= 3),
        "the probe's hooks stopped: {steps:?}"
    );
}

/// Runs `attempt()` made of `body` under `pcall`, checks that it failed and that the
/// simulation carries on, and returns the error message.
fn refused(tag: &str, body: &str) -> String {
    let mut sc = probe_scene(tag, body);
    let msg = text(&sc.call("probe", &[])[0]).to_owned();
    assert_carries_on(&mut sc);
    msg
}

/// One test per escape attempt: `name: "lua body" => ["parts", "of", "the error"]`.
macro_rules! refused {
    ($($name:ident: $lua:expr => [$($part:expr),+ $(,)?];)*) => {$(
        #[test]
        fn $name() {
            let msg = refused(stringify!($name), $lua);
            assert_contains(&msg, &[$($part),+]);
        }
    )*};
}

refused! {
    os_execute_is_absent: "return os.execute('touch /tmp/gantry-sandbox-execute')"
        => ["attempt to call a nil value", "execute"];
    io_popen_is_refused: "return io.popen('id')" => ["io.popen is not available in gantry scripts"];
    io_open_for_reading_outside_is_refused: "return io.open('/etc/hostname'):read('a')"
        => ["/etc/hostname is outside the folders scripts may read", "--allow-files"];
    io_lines_outside_is_refused: "for l in io.lines('/etc/hostname') do end"
        => ["outside the folders scripts may read", "--allow-files"];
    os_remove_is_absent: "return os.remove('/tmp/gantry-sandbox-remove')" => ["attempt to call a nil value", "remove"];
    os_rename_is_absent: "return os.rename('/tmp/a', '/tmp/b')" => ["attempt to call a nil value", "rename"];
    os_exit_is_absent: "os.exit(0)" => ["attempt to call a nil value", "exit"];
    os_getenv_is_absent: "return os.getenv('HOME')" => ["attempt to call a nil value", "getenv"];
    os_tmpname_is_absent: "return os.tmpname()" => ["attempt to call a nil value", "tmpname"];
    // LuaFileSystem, a C module (`socket.core` is served now: gantry's LuaSocket subset).
    require_of_a_c_module_is_refused: "return require('lfs')"
        => ["module 'lfs' not found", "lfs.lua", "--lua-path"];
    require_of_a_file_is_refused: "return require('../../etc/passwd')" => ["contains '..'"];
    package_loadlib_is_absent: "return package.loadlib('libc.so.6', 'system')" => ["global 'package'"];
    package_cpath_is_absent: "package.cpath = '/tmp/?.so'" => ["global 'package'"];
    load_of_bytecode_is_absent: "return load(string.dump(function() return 1 end), 'x', 'b')()"
        => ["attempt to call a nil value", "load"];
    loadstring_is_absent: "return loadstring('return 1')()" => ["attempt to call a nil value", "loadstring"];
    dofile_is_absent: "return dofile('/etc/hostname')" => ["attempt to call a nil value", "dofile"];
    loadfile_is_absent: "return loadfile('/etc/hostname')" => ["attempt to call a nil value", "loadfile"];
    debug_sethook_is_absent: "debug.sethook()" => ["attempt to call a nil value", "sethook"];
    debug_getregistry_is_absent: "return debug.getregistry()" => ["attempt to call a nil value", "getregistry"];
    debug_upvalue_tricks_are_absent: "return debug.getupvalue(sim.getObject, 1)"
        => ["attempt to call a nil value", "getupvalue"];
    string_metatable_is_protected: "getmetatable('').__index = { upper = function() return 'pwned' end }"
        => ["attempt to index a boolean value"];
    gc_finalizers_are_refused: "setmetatable({}, { __gc = function() while true do end end })"
        => ["__gc finalizers are not allowed", "time budget"];
    gc_finalizer_placeholders_are_refused: "local mt = { __gc = true }; setmetatable({}, mt); mt.__gc = print"
        => ["__gc finalizers are not allowed"];
    collectgarbage_stop_is_refused: "collectgarbage('stop')" => ["collectgarbage('stop') is not allowed", "shared"];
    collectgarbage_tuning_is_refused: "collectgarbage('incremental', 1000, 1000)"
        => ["collectgarbage('incremental') is not allowed"];
    memory_cannot_be_exhausted_in_one_call: "return string.rep('x', 1 << 40)" => ["too large"];
    graph_export_to_an_absolute_path_is_refused:
        "return sim.exportGraphStreams('/tmp/gantry-sandbox-export')"
        => ["exportGraphStreams", "outside the scene's folder", "--export-graphs"];
    graph_export_out_of_the_scene_folder_is_refused:
        "return sim.exportGraphStreams('../../gantry-sandbox-export')"
        => ["exportGraphStreams", "outside the scene's folder"];
    scene_save_to_an_absolute_path_is_refused: "return sim.saveScene('/tmp/gantry-sandbox-save.toml')"
        => ["saveScene", "outside the scene's folder"];
    scene_save_out_of_the_scene_folder_is_refused: "return sim.saveScene('../../gantry-sandbox-save.toml')"
        => ["saveScene", "outside the scene's folder"];
}

#[test]
fn every_removed_name_is_nil_and_the_rest_of_the_library_works() {
    let globals: Vec<String> = REMOVED_GLOBALS.iter().map(|n| format!("{n}=type({n})")).collect();
    let os: Vec<String> = REMOVED_OS.iter().map(|n| format!("os_{n}=type(os.{n})")).collect();
    let source = format!(
        "{PROBE_PRELUDE}
        function removed()
            local t = {{ {}, {}, package=type(package),
                -- the confined io library (crate::script_io) has no standard streams.
                ['io.stdin']=type(io.stdin), ['io.stdout']=type(io.stdout), ['io.stderr']=type(io.stderr) }}
            -- debug.traceback is the one debug function scripts keep.
            for k in pairs(debug) do if k ~= 'traceback' then t['debug.' .. k] = 'present' end end
            local present = {{}}
            for k, v in pairs(t) do if v ~= 'nil' then present[#present + 1] = k end end
            table.sort(present)
            return table.concat(present, ',')
        end
        function kept()
            return string.format('%d %s %s', collectgarbage('count') > 0 and 1 or 0,
                type(os.time()), type(os.clock())), ('abc'):upper(), math.floor(2.5),
                type(setmetatable({{}}, {{ __index = {{}} }}))
        end",
        globals.join(", "),
        os.join(", ")
    );
    let mut sc = Scene::new(
        "removed",
        PROBE_SCENE,
        &[("probe.lua", &source)],
        ScriptLimits::default(),
    );
    sc.sim.start();
    assert_eq!(sc.call("removed", &[]), vec![s("")], "names still present");
    assert_eq!(
        sc.call("kept", &[]),
        vec![s("1 number number"), s("ABC"), Value::Int(2), s("table")]
    );
    assert_carries_on(&mut sc);
}

#[test]
fn io_open_for_writing_outside_is_refused_and_writes_nothing() {
    let dir = TempDir::new("sandbox-write");
    let target = dir.path().join("written.txt");
    let body = format!(
        "local f = io.open('{}', 'w'); f:write('x'); f:close()",
        target.display()
    );
    let msg = refused("io-write", &body);
    assert_contains(&msg, &["outside the folders scripts may write", "--allow-files"]);
    assert!(!target.exists(), "a script created {}", target.display());
}

#[test]
fn graph_export_refusals_write_nothing_and_inside_the_scene_folder_works() {
    let mut sc = probe_scene(
        "export",
        "local g = sim.getObject('/plot')
        local id = sim.addGraphStream(g, 'x', 'm')
        sim.setGraphStreamValue(g, id, 1.5)
        return sim.exportGraphStreams('out/csv')",
    );
    sc.sim.step();
    let outside = sc.dir.path().join("../gantry-sandbox-outside");
    let _ = std::fs::remove_dir_all(&outside);
    let paths = sc.call("attempt", &[]);
    let Value::Array(paths) = &paths[0] else {
        panic!("paths: {paths:?}")
    };
    let written = Path::new(text(&paths[0])).to_owned();
    assert_eq!(written, sc.dir.path().join("out/csv/plot.csv"), "relative to the scene");
    assert!(
        std::fs::read_to_string(&written)
            .expect("csv")
            .starts_with("time,x [m]")
    );
    // The same call from a remote client (ZMQ goes through Engine::call) is
    // confined the same way.
    let abs = outside.display().to_string();
    for dir in [
        abs.as_str(),
        "../gantry-sandbox-outside",
        "out/../../gantry-sandbox-outside",
    ] {
        let e = sc.sim.call("exportGraphStreams", &[s(dir)]).expect_err(dir);
        assert_contains(&e, &["outside the scene's folder", "sim.exportGraphStreams"]);
    }
    assert!(!outside.exists(), "an export escaped to {}", outside.display());
    assert_carries_on(&mut sc);
}

#[test]
fn an_embedded_scene_cannot_export_from_scripts() {
    let dir = TempDir::new("sandbox-embedded");
    dir.write("probe.lua", PROBE_PRELUDE);
    let mut model = load(&dir.write("scene.toml", PROBE_SCENE));
    // What the loader gives the scene compiled into the binary.
    model.base_dir = "/embedded/assets/scenes".into();
    let mut sim = util::engine(model, ScriptLimits::default()).expect("builds");
    sim.start();
    let e = sim.call("exportGraphStreams", &[s("out")]).expect_err("no folder");
    assert_contains(&e, &["no folder on disk", "--export-graphs"]);
}

#[test]
fn overwriting_the_shared_tables_affects_only_the_script_that_does_it() {
    let scene = r#"
[[object]]
name = "rogue"
kind = "dummy"
script = "rogue.lua"

[[object]]
name = "victim"
kind = "dummy"
script = "victim.lua"
"#;
    // Runs at load time, before the victim's chunk and hooks.
    let rogue = "
        rawset(sim, 'getObject', nil)
        sim.getSimulationTime = function() return -1 end
        string.upper = function() return 'pwned' end
        math.pi = 3
        rawset(_G, 'tostring', nil)
        _G.pcall = nil
        coroutine.resume = nil
        function rogueSees() return sim.getObject == nil, string.upper('a'), ('a'):upper() end
    ";
    let victim = "
        function victimSees()
            return sim.getObject('/victim'), sim.getSimulationTime(), string.upper('a'),
                ('b'):upper(), math.pi, tostring(1), type(pcall), type(coroutine.resume),
                _G == _ENV
        end
    ";
    let mut sc = Scene::new(
        "shared",
        scene,
        &[("rogue.lua", rogue), ("victim.lua", victim)],
        ScriptLimits::default(),
    );
    sc.sim.start();
    sc.sim.step();
    let victim_handle = sc.find("/victim");
    let seen = sc.call("victimSees", &[]);
    assert_eq!(seen[0], Value::Int(victim_handle));
    assert!(matches!(seen[1], Value::Float(t) if t > 0.0), "{seen:?}");
    assert_eq!(&seen[2..4], &[s("A"), s("B")]);
    assert_eq!(seen[4], Value::Float(std::f64::consts::PI));
    assert_eq!(&seen[5..], &[s("1"), s("function"), s("function"), Value::Bool(true)]);
    // The rogue changed its own copy only; string methods are not its to change.
    assert_eq!(sc.call("rogueSees", &[]), vec![Value::Bool(true), s("pwned"), s("A")]);
    assert_eq!(script_state(&sc.sim, "victim.lua"), ScriptState::Running);
}

#[test]
fn a_binary_chunk_script_file_is_refused() {
    // A precompiled chunk starts with ESC "Lua"; Lua does not verify bytecode, so a
    // crafted one could corrupt memory. Script files are compiled as text only.
    let bad = "\x1bLua\u{54}\u{0}garbage that a bytecode loader would try to run";
    let mut sc = Scene::new("binary", PROBE_SCENE, &[("probe.lua", bad)], ScriptLimits::default());
    assert_contains(script_error(&sc.sim, "probe.lua"), &["binary chunk"]);
    sc.sim.start();
    sc.sim.step();
    assert_eq!(sc.sim.world().steps(), 1, "the simulation runs without it");
}

#[test]
fn a_remote_call_into_a_looping_script_function_is_interrupted() {
    let limits = ScriptLimits {
        time_budget: Duration::from_millis(200),
        ..ScriptLimits::default()
    };
    let source = format!("{PROBE_PRELUDE}\nfunction spin() while true do end end\n");
    let mut sc = Scene::new("remote-loop", PROBE_SCENE, &[("probe.lua", &source)], limits);
    sc.sim.start();
    let probe = sc.find("/probe");
    let t0 = Instant::now();
    let e = sc
        .sim
        .call("callScriptFunction", &[s("spin"), Value::Int(probe)])
        .expect_err("interrupted");
    assert!(t0.elapsed() < Duration::from_secs(5), "took {:?}", t0.elapsed());
    assert_contains(&e, &["time budget", "sim.callScriptFunction"]);
    // The next hook gets a fresh budget.
    sc.sim.step();
    assert_eq!(sc.sim.world().steps(), 1);
}
