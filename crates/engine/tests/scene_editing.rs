//! Editing the scene while the simulation is stopped, as CoppeliaSim does: what is
//! created, moved, renamed or removed while stopped stays through a run (with the same
//! handles), and a stop puts back what the run moved or made.

use gantry_lua::ScriptLimits;
use gantry_sim_core::Value;
use gantry_test_support::{floats, int};

use crate::util::{Drive, Scene, int32_signal, log_lines};

const SCENE: &str = r#"
[simulation]
dt = 0.05

[floor]
size = [4, 4]

[[object]]
name = "marker"
kind = "dummy"
position = [0, 0, 1]

[[object]]
name = "box"
kind = "shape"
shape = "box"
size = [0.1, 0.1, 0.1]
position = [0.5, 0, 0.5]
dynamic = true

[[object]]
name = "spare"
kind = "dummy"
position = [0, 1, 0]
"#;

fn position(scene: &mut Scene, h: i64) -> Vec<f64> {
    floats(&scene.remote("getObjectPosition", &[Value::Int(h), Value::Int(-1)])[0])
}

fn exists(scene: &mut Scene, h: i64) -> bool {
    scene.sim.call("getObjectAlias", &[Value::Int(h)]).is_ok()
}

#[test]
fn edits_made_while_stopped_survive_a_run_and_what_the_run_did_goes_back() {
    let mut scene = Scene::new("edit-stopped", SCENE, &[], ScriptLimits::default());
    let (marker, boxed, spare) = (scene.find("/marker"), scene.find("/box"), scene.find("/spare"));
    // Edits while stopped: a new cuboid, a moved and renamed dummy, a removed one.
    let made = int(&scene.remote(
        "createPrimitiveShape",
        &[Value::Int(3), Value::floats(&[0.2, 0.2, 0.2])],
    )[0]);
    scene.remote(
        "setObjectPosition",
        &[Value::Int(made), Value::Int(-1), Value::floats(&[-1.0, 0.0, 0.1])],
    );
    scene.remote(
        "setObjectPosition",
        &[Value::Int(marker), Value::Int(-1), Value::floats(&[0.3, 0.2, 1.5])],
    );
    scene.remote("setObjectAlias", &[Value::Int(marker), Value::Str("beacon".into())]);
    scene.remote("removeObjects", &[Value::Array(vec![Value::Int(spare)])]);
    for _ in 0..2 {
        // The run moves and makes things.
        scene.sim.start();
        scene.remote(
            "setObjectPosition",
            &[Value::Int(made), Value::Int(-1), Value::floats(&[2.0, 2.0, 2.0])],
        );
        let during = int(&scene.remote("createDummy", &[Value::Float(0.01)])[0]);
        for _ in 0..10 {
            scene.sim.step();
        }
        assert!(position(&mut scene, boxed)[2] < 0.45, "the box falls during the run");
        scene.sim.stop();
        // The stop puts back the scene as it started: the edits are there, with their
        // handles; what the run moved is back; what it made is gone.
        assert_eq!(position(&mut scene, made), [-1.0, 0.0, 0.1]);
        assert_eq!(position(&mut scene, marker), [0.3, 0.2, 1.5]);
        assert_eq!(scene.find("/beacon"), marker);
        assert!(!exists(&mut scene, spare), "the removed dummy came back");
        assert!(!exists(&mut scene, during), "an object made during the run stayed");
        assert_eq!(position(&mut scene, boxed), [0.5, 0.0, 0.5]);
    }
}

#[test]
fn a_script_goes_with_its_object_when_the_object_is_removed_while_stopped() {
    let scene_text = format!(
        "{SCENE}\n[[object]]\nname = \"carrier\"\nkind = \"dummy\"\nscript = \"carrier.lua\"\n\n\
         [[object]]\nname = \"keeper\"\nkind = \"dummy\"\nscript = \"keeper.lua\"\n"
    );
    let count = |name: &str| {
        format!("function sysCall_init() sim.setInt32Signal('{name}', (sim.getInt32Signal('{name}') or 0) + 1) end\n")
    };
    let mut scene = Scene::new(
        "edit-script-object",
        &scene_text,
        &[("carrier.lua", &count("carrier")), ("keeper.lua", &count("keeper"))],
        ScriptLimits::default(),
    );
    let carrier = scene.find("/carrier");
    scene.remote("removeObjects", &[Value::Array(vec![Value::Int(carrier)])]);
    for _ in 0..2 {
        scene.sim.start();
        scene.sim.step();
        // (Signals go with the run: read them before the stop.)
        assert_eq!(int32_signal(&mut scene.sim, "keeper"), Some(1));
        assert_eq!(
            int32_signal(&mut scene.sim, "carrier"),
            None,
            "the removed object's script ran"
        );
        scene.sim.stop();
    }
    let lines = log_lines(&scene.sim);
    assert!(
        lines
            .iter()
            .any(|(source, _, m)| source == "carrier.lua" && m.contains("removed with its object")),
        "{lines:?}"
    );
    assert!(lines.iter().all(|(_, v, _)| *v > 200), "an error was logged: {lines:?}");
}
