//! `require` of the user's own Lua modules (issue 49): modules beside the scene, in a
//! `--lua-path` folder and under dotted names load into the requiring script's sandbox,
//! once; a module that requires itself, a name with `..` and a module whose file is a
//! symbolic link out of the folders are refused with clear errors.

use crate::util;
use util::Drive;

use gantry_lua::ScriptLimits;
use gantry_sim_core::Value;
use gantry_test_support::{TempDir, assert_contains, load, text};
use util::{LUA_ERR, PROBE_ONLY_SCENE, Scene, assert_running, script_error};

/// The probe scene with `source` (plus `err`) as `probe.lua` and `files` beside it,
/// started.
fn scene(tag: &str, source: &str, files: &[(&str, &str)], limits: ScriptLimits) -> Scene {
    let source = format!("{source}\n{LUA_ERR}");
    let mut all = vec![("probe.lua", source.as_str())];
    all.extend_from_slice(files);
    let mut sc = Scene::new(tag, PROBE_ONLY_SCENE, &all, limits);
    sc.sim.start();
    sc
}

fn s(v: &str) -> Value {
    Value::Str(v.to_owned())
}

#[test]
fn a_module_beside_the_scene_loads_once_into_the_scripts_sandbox() {
    let utils = "
        loads = (loads or 0) + 1
        local M = {}
        function M.twice(x) return 2 * x end
        function M.sim_is_mine() return sim ~= nil and helper_seen == 'yes' end
        return M
    ";
    let probe = "
        helper_seen = 'yes'
        local u = require 'utils'
        local again = require('utils')
        function probe() return u.twice(21), loads, u == again, u.sim_is_mine() end
    ";
    let mut sc = scene(
        "modules-beside",
        probe,
        &[("utils.lua", utils)],
        ScriptLimits::default(),
    );
    assert_running(&sc.sim, "probe.lua");
    assert_eq!(
        sc.call("probe", &[]),
        vec![Value::Int(42), Value::Int(1), Value::Bool(true), Value::Bool(true)]
    );
}

#[test]
fn modules_load_from_lua_path_folders_under_dotted_names_and_init_files() {
    let lib = TempDir::new("modules-lua-path");
    std::fs::create_dir_all(lib.path().join("robots/arm")).expect("dir");
    lib.write("blimp.lua", "return { name = 'blimp' }");
    lib.write("robots/gripper.lua", "return { name = 'gripper' }");
    lib.write("robots/arm/init.lua", "return { name = 'arm' }");
    let probe = "
        local a, b, c = require 'blimp', require 'robots.gripper', require 'robots.arm'
        function probe() return a.name, b.name, c.name end
    ";
    let limits = ScriptLimits {
        lua_path: vec![lib.path().to_owned()],
        ..ScriptLimits::default()
    };
    let mut sc = scene("modules-path", probe, &[], limits);
    assert_running(&sc.sim, "probe.lua");
    assert_eq!(sc.call("probe", &[]), vec![s("blimp"), s("gripper"), s("arm")]);
}

#[test]
fn a_missing_module_names_every_folder_searched() {
    let lib = TempDir::new("modules-missing");
    let limits = ScriptLimits {
        lua_path: vec![lib.path().to_owned()],
        ..ScriptLimits::default()
    };
    let mut sc = scene(
        "modules-missing-scene",
        "function probe() return err(require, 'configUi') end",
        &[],
        limits,
    );
    let msg = text(&sc.call("probe", &[])[0]).to_owned();
    let scene_dir = sc.dir.path().display().to_string();
    let lib_dir = lib.path().display().to_string();
    assert_contains(
        &msg,
        &[
            "module 'configUi' not found",
            &scene_dir,
            &lib_dir,
            "configUi.lua",
            "--lua-path",
        ],
    );
}

#[test]
fn a_module_that_requires_itself_is_a_loop_not_a_stack_overflow() {
    let files = [
        ("selfish.lua", "require 'selfish'\nreturn {}"),
        ("ping.lua", "require 'pong'\nreturn {}"),
        ("pong.lua", "require 'ping'\nreturn {}"),
    ];
    let probe = "function probe() return err(require, 'selfish'), err(require, 'ping') end";
    let mut sc = scene("modules-loop", probe, &files, ScriptLimits::default());
    let out = sc.call("probe", &[]);
    assert_contains(text(&out[0]), &["loop or previous error loading module 'selfish'"]);
    assert_contains(text(&out[1]), &["loop or previous error loading module 'ping'"]);
    assert_running(&sc.sim, "probe.lua");
}

#[test]
fn names_that_leave_the_folders_are_refused() {
    let probe = "function probe() return err(require, '..secret'), err(require, '/etc/passwd') end";
    let mut sc = scene("modules-dotdot", probe, &[], ScriptLimits::default());
    let out = sc.call("probe", &[]);
    assert_contains(text(&out[0]), &["'..secret'", "contains '..'"]);
    assert_contains(text(&out[1]), &["'/etc/passwd'", "not a module name"]);
}

#[cfg(unix)]
#[test]
fn a_module_linked_out_of_the_folder_is_refused() {
    let outside = TempDir::new("modules-outside");
    let secret = outside.write("secret.lua", "leaked = true\nreturn {}");
    let mut sc = scene(
        "modules-symlink",
        "function probe() return err(require, 'secret'), leaked == nil end",
        &[],
        ScriptLimits::default(),
    );
    std::os::unix::fs::symlink(&secret, sc.dir.path().join("secret.lua")).expect("symlink");
    let out = sc.call("probe", &[]);
    assert_contains(
        text(&out[0]),
        &["module 'secret'", "outside the folders scripts may load modules from"],
    );
    assert_eq!(out[1], Value::Bool(true), "the module outside ran");
}

#[test]
fn a_failing_main_chunk_require_stops_only_that_script_with_the_modules_name() {
    let mut sc = scene("modules-error", "require 'absent'", &[], ScriptLimits::default());
    sc.sim.step();
    assert_contains(script_error(&sc.sim, "probe.lua"), &["module 'absent' not found"]);
}

#[test]
fn an_embedded_scene_finds_modules_only_in_lua_path_folders() {
    let dir = TempDir::new("modules-embedded");
    dir.write("utils.lua", "return 1");
    dir.write(
        "probe.lua",
        format!("function probe() return err(require, 'utils') end\n{LUA_ERR}"),
    );
    let mut model = load(&dir.write("scene.toml", PROBE_ONLY_SCENE));
    // What the loader gives the scene compiled into the binary.
    model.base_dir = "/embedded/assets/scenes".into();
    let mut sim = util::engine(model, ScriptLimits::default()).expect("builds");
    sim.start();
    let msg = text(&util::call(&mut sim, "probe", &[])[0]).to_owned();
    assert_contains(&msg, &["module 'utils' not found", "no folder on disk", "--lua-path"]);
}
