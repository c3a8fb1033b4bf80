//! The scene changed while it runs: `sim.loadModel(path)` adds a robot (`.urdf`) or a
//! gantry model (`.toml` with objects, robots and scripts), from a remote client (any
//! readable path, as `sim.loadScene`) or from a script (inside the scene's folder only);
//! the model's scripts run as the scene's do, and the model stays part of the scene
//! across a stop. `sim.removeScript` takes a script out until a stop restores it.

use crate::util;
use util::Drive;

use gantry_engine::Engine;
use gantry_lua::ScriptLimits;
use gantry_sim_core::Value;
use gantry_test_support::{assert_contains, int, repo, text};
use util::{Scene, find, int32_signal};

fn s(v: &str) -> Value {
    Value::Str(v.to_owned())
}

fn step(sim: &mut Engine, n: usize) {
    for _ in 0..n {
        sim.step();
    }
}

/// A model with a dummy carrying a script that counts its hooks in signals, and a
/// shape below it.
const BEACON: &str = r#"
[[object]]
name = "beacon"
kind = "dummy"
position = [1, 2, 0.5]
script = "beacon.lua"

[[object]]
name = "lamp"
kind = "shape"
shape = "sphere"
radius = 0.05
parent = "beacon"
position = [0, 0, 0.1]
"#;

const BEACON_LUA: &str = "
function sysCall_init()
    sim.setInt32Signal('beacon_init', (sim.getInt32Signal('beacon_init') or 0) + 1)
    self = sim.getObject('.')
end
function sysCall_actuation()
    sim.setInt32Signal('beacon_steps', (sim.getInt32Signal('beacon_steps') or 0) + 1)
end
";

const EMPTY_SCENE: &str = "[floor]\nsize = [2, 2]\n";

#[test]
fn a_remote_client_loads_a_urdf_robot_that_stays_across_a_stop() {
    let mut scene = Scene::new("load-urdf", EMPTY_SCENE, &[], ScriptLimits::default());
    let urdf = repo("assets/robots/arm6/arm6.urdf");
    let base = int(&scene.remote("loadModel", &[s(urdf.to_str().unwrap())])[0]);
    assert_eq!(base, scene.find("/arm6"), "the handle is the model base's");
    let joint = scene.find("/arm6/joint2");
    scene.remote("setJointPosition", &[Value::Int(joint), Value::Float(0.5)]);
    assert_eq!(
        scene.remote("getJointPosition", &[Value::Int(joint)]),
        [Value::Float(0.5)]
    );
    // Part of the scene from now on: it runs, and a stop restores it as it started,
    // the joint where the client put it while stopped (CoppeliaSim's rule).
    scene.sim.start();
    scene.remote("setJointPosition", &[Value::Int(joint), Value::Float(0.9)]);
    step(&mut scene.sim, 3);
    scene.sim.stop();
    assert_eq!(scene.find("/arm6"), base);
    assert_eq!(
        scene.remote("getJointPosition", &[Value::Int(joint)]),
        [Value::Float(0.5)]
    );
}

#[test]
fn a_models_scripts_run_at_once_when_loaded_during_the_run() {
    let mut scene = Scene::new("load-running", EMPTY_SCENE, &[], ScriptLimits::default());
    let model = scene.dir.write("beacon.toml", BEACON);
    scene.dir.write("beacon.lua", BEACON_LUA);
    scene.sim.start();
    step(&mut scene.sim, 2);
    let base = int(&scene.remote("loadModel", &[s(model.to_str().unwrap())])[0]);
    assert_eq!(base, find(&scene.sim, "/beacon"));
    assert_eq!(
        int32_signal(&mut scene.sim, "beacon_init"),
        Some(1),
        "sysCall_init ran on load"
    );
    step(&mut scene.sim, 3);
    assert_eq!(int32_signal(&mut scene.sim, "beacon_steps"), Some(3));
    let lamp = find(&scene.sim, "/beacon/lamp");
    let pos = scene.remote("getObjectPosition", &[Value::Int(lamp), Value::Int(-1)]);
    assert_eq!(pos, [Value::floats(&[1.0, 2.0, 0.6])]);
    // After a stop and a start, the model's script initialises again, with the scene.
    scene.sim.stop();
    scene.sim.start();
    assert_eq!(
        int32_signal(&mut scene.sim, "beacon_init"),
        Some(1),
        "signals were cleared by the stop"
    );
}

#[test]
fn a_script_loads_a_model_from_its_scene_folder_only() {
    let toml = r#"
[floor]
size = [2, 2]

[[object]]
name = "loader"
kind = "dummy"
script = "loader.lua"
"#;
    let loader = r#"
function sysCall_init()
    local h = sim.loadModel('beacon.toml')
    sim.setInt32Signal('model_base', h)
    -- The model's objects are there at once; its script loads after this hook.
    sim.setInt32Signal('lamp_seen', sim.getObject('/beacon/lamp') >= 0 and 1 or 0)
end
function outside()
    local ok, e = pcall(sim.loadModel, '../elsewhere.toml')
    return tostring(e)
end
function wrong()
    local ok, e = pcall(sim.loadModel, 42)
    return tostring(e)
end
"#;
    let mut scene = Scene::new(
        "load-script",
        toml,
        &[
            ("loader.lua", loader),
            ("beacon.toml", BEACON),
            ("beacon.lua", BEACON_LUA),
        ],
        ScriptLimits::default(),
    );
    scene.sim.start();
    let base = find(&scene.sim, "/beacon");
    assert_eq!(int32_signal(&mut scene.sim, "model_base"), Some(base));
    assert_eq!(int32_signal(&mut scene.sim, "lamp_seen"), Some(1));
    assert_eq!(int32_signal(&mut scene.sim, "beacon_init"), Some(1));
    step(&mut scene.sim, 1);
    assert_eq!(int32_signal(&mut scene.sim, "beacon_steps"), Some(1));
    let e = scene.call("outside", &[]);
    assert_contains(
        text(&e[0]),
        &["elsewhere.toml", "inside the scene's folder", "sim.loadModel"],
    );
    let e = scene.call("wrong", &[]);
    assert_contains(text(&e[0]), &["argument 1", "string", "sim.loadModel"]);
}

#[test]
fn files_that_are_not_models_are_refused_and_change_nothing() {
    let mut scene = Scene::new("load-bad", EMPTY_SCENE, &[], ScriptLimits::default());
    let whole = scene.dir.write(
        "whole.toml",
        "[floor]\nsize = [1, 1]\n[[object]]\nname = \"x\"\nkind = \"dummy\"\n",
    );
    let ttm = scene.dir.write("robot.ttm", "binary");
    let empty = scene.dir.write("empty.toml", "# nothing\n");
    let missing = scene.dir.path().join("missing.urdf");
    let before = scene.sim.world().len();
    for (path, expected) in [
        (whole, "no [floor] section"),
        (ttm, "not a CoppeliaSim scene or model file"),
        (empty, "no objects"),
        (missing, "missing.urdf"),
    ] {
        let e = scene
            .sim
            .call("loadModel", &[s(path.to_str().unwrap())])
            .expect_err("refused");
        assert_contains(&e, &[expected, "(in function 'sim.loadModel')"]);
    }
    let e = scene.sim.call("loadModel", &[Value::Int(3)]).expect_err("refused");
    assert_contains(&e, &["argument 1"]);
    assert_eq!(scene.sim.world().len(), before);
}

/// `sim.removeScript`, as the crane example's window does when closed: a script
/// removes itself and finishes the function it is in; its cleanup runs, it gets no more
/// hooks, `sim.getScript` no longer finds it; a stop restores the scene with it.
#[test]
fn a_script_removes_itself_and_a_client_removes_another() {
    let toml = r#"
[[object]]
name = "window"
kind = "dummy"
script = "window.lua"

[[object]]
name = "other"
kind = "dummy"
script = "other.lua"
"#;
    let window = "
function sysCall_init() sim.setInt32Signal('window_init', (sim.getInt32Signal('window_init') or 0) + 1) end
function sysCall_actuation() sim.setInt32Signal('window_steps', (sim.getInt32Signal('window_steps') or 0) + 1) end
function sysCall_cleanup() sim.setInt32Signal('window_cleanup', 1) end
function close()
    sim.removeScript(sim.handle_self)
    sim.setInt32Signal('after_remove', 1)   -- the function goes on to its end
    return 'closed'
end
";
    let other = "
function sysCall_actuation() sim.setInt32Signal('other_steps', (sim.getInt32Signal('other_steps') or 0) + 1) end
function probe(h)
    local ok, e = pcall(sim.removeScript, h)
    return tostring(e)
end
";
    let mut scene = Scene::new(
        "remove-script",
        toml,
        &[("window.lua", window), ("other.lua", other)],
        ScriptLimits::default(),
    );
    scene.sim.start();
    step(&mut scene.sim, 2);
    let win = scene.find("/window");
    assert_eq!(scene.call("close", &[]), [s("closed")]);
    assert_eq!(int32_signal(&mut scene.sim, "after_remove"), Some(1));
    assert_eq!(
        int32_signal(&mut scene.sim, "window_cleanup"),
        Some(1),
        "its cleanup ran"
    );
    step(&mut scene.sim, 3);
    assert_eq!(
        int32_signal(&mut scene.sim, "window_steps"),
        Some(2),
        "no hook after removal"
    );
    assert_eq!(int32_signal(&mut scene.sim, "other_steps"), Some(5));
    let script = scene.remote("getScript", &[Value::Int(1), Value::Int(win)]);
    assert_eq!(script, [Value::Int(-1)], "sim.getScript no longer finds it");
    let e = scene.call("probe", &[Value::Int(win)]);
    assert_contains(text(&e[0]), &["no script has handle", "sim.removeScript"]);
    // A remote client removes the other one.
    let other_h = scene.find("/other");
    scene.remote("removeScript", &[Value::Int(other_h)]);
    step(&mut scene.sim, 1);
    assert_eq!(int32_signal(&mut scene.sim, "other_steps"), Some(5));
    let e = scene
        .sim
        .call("removeScript", &[Value::Int(other_h)])
        .expect_err("gone");
    assert_contains(&e, &["no script has handle", "(in function 'sim.removeScript')"]);
    // A stop restores the scene as loaded, scripts included.
    scene.sim.stop();
    scene.sim.start();
    assert_eq!(int32_signal(&mut scene.sim, "window_init"), Some(1));
    step(&mut scene.sim, 1);
    assert_eq!(int32_signal(&mut scene.sim, "other_steps"), Some(1));
}

/// What cleanup hooks ask for at a stop: a model loaded there joins the rebuilt scene
/// (its script runs in the next run), a removal ends with the run; and a script that
/// removes itself is the one removed even when its object carries another script.
#[test]
fn requests_made_by_cleanup_hooks_and_scripts_sharing_an_object() {
    let toml = r#"
[[object]]
name = "base"
kind = "dummy"

[[script]]
object = "base"
file = "first.lua"

[[script]]
object = "base"
file = "second.lua"
"#;
    let first = "
function sysCall_actuation() sim.setInt32Signal('first', (sim.getInt32Signal('first') or 0) + 1) end
function sysCall_cleanup()
    if not sim.getInt32Signal('loaded') then
        sim.setInt32Signal('loaded', sim.loadModel('beacon.toml'))
    end
end
";
    let second = "
function sysCall_actuation() sim.setInt32Signal('second', (sim.getInt32Signal('second') or 0) + 1) end
function leave() sim.removeScript(sim.handle_self) end
function sysCall_cleanup() sim.removeScript(sim.handle_self) end
";
    let mut scene = Scene::new(
        "cleanup-requests",
        toml,
        &[
            ("first.lua", first),
            ("second.lua", second),
            ("beacon.toml", BEACON),
            ("beacon.lua", BEACON_LUA),
        ],
        ScriptLimits::default(),
    );
    scene.sim.start();
    step(&mut scene.sim, 1);
    scene.call("leave", &[]);
    step(&mut scene.sim, 2);
    assert_eq!(
        int32_signal(&mut scene.sim, "first"),
        Some(3),
        "the other script on the object runs on"
    );
    assert_eq!(
        int32_signal(&mut scene.sim, "second"),
        Some(1),
        "the one that left does not"
    );
    // The stop runs first.lua's cleanup, which loads the model: it is in the new run.
    scene.sim.stop();
    assert!(
        scene.sim.world().find("/beacon", None, 0).is_ok(),
        "the model joined the scene"
    );
    scene.sim.start();
    assert_eq!(int32_signal(&mut scene.sim, "beacon_init"), Some(1));
    step(&mut scene.sim, 1);
    assert_eq!(
        int32_signal(&mut scene.sim, "second"),
        Some(1),
        "restored by the stop, and running"
    );
    assert_eq!(int32_signal(&mut scene.sim, "beacon_steps"), Some(1));
}
