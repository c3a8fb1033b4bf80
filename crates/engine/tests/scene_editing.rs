//! Editing the scene while the simulation is stopped, as CoppeliaSim does: what is
//! created, moved, renamed or removed while stopped stays through a run (with the same
//! handles), and a stop puts back what the run moved or made; the editor's edits
//! (`Input::Edit`) undo and redo exactly.

use gantry_engine::{HISTORY_STEPS, Input};
use gantry_lua::ScriptLimits;
use gantry_sim_core::Value;
use gantry_test_support::{assert_contains, floats, int};

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

/// A `sim.*` call: the function's name and its arguments.
type Call<'a> = (&'a str, Vec<Value>);

/// The editor's edit `calls` as one undoable step.
fn edit(scene: &mut Scene, label: &str, calls: &[Call<'_>]) -> Result<Vec<Value>, String> {
    let calls: Vec<(String, Vec<Value>)> = calls.iter().map(|(n, a)| ((*n).to_owned(), a.clone())).collect();
    scene
        .sim
        .serve(Input::Edit { label, calls: &calls })
        .into_values()
        .map_err(|e| e.to_string())
}

/// The list `v` holds (an edit's results per call, a call's results).
fn list(v: &Value) -> &[Value] {
    match v {
        Value::Array(items) => items,
        other => panic!("expected a list, got {other:?}"),
    }
}

fn undo(scene: &mut Scene, undo: bool) -> Vec<Value> {
    scene.sim.serve(Input::Undo(undo)).into_values().expect("undo")
}

/// Everything the scene saves, and its handles: equal fingerprints, equal scenes.
fn fingerprint(scene: &Scene) -> String {
    let world = &scene.sim.world();
    let exported = world.export_scene(None).expect("export");
    format!("{:?}\n{:?}", world.handles(), exported.model.objects)
}

#[test]
fn every_kind_of_edit_undoes_and_redoes_exactly() {
    let mut scene = Scene::new("edit-undo", SCENE, &[], ScriptLimits::default());
    let (marker, boxed, spare) = (scene.find("/marker"), scene.find("/box"), scene.find("/spare"));
    let h = Value::Int;
    let mut states = vec![fingerprint(&scene)];
    let added = edit(
        &mut scene,
        "Add cuboid",
        &[("sim.createPrimitiveShape", vec![h(3), Value::floats(&[0.2, 0.1, 0.3])])],
    )
    .expect("add");
    let made = int(&list(&added[0])[0]);
    states.push(fingerprint(&scene));
    let steps: Vec<(&str, Vec<Call<'_>>)> = vec![
        (
            "Move",
            vec![(
                "sim.setObjectPosition",
                vec![h(made), h(-1), Value::floats(&[1.0, -1.0, 0.2])],
            )],
        ),
        (
            "Rotate",
            vec![(
                "sim.setObjectOrientation",
                vec![h(made), h(-1), Value::floats(&[0.1, 0.2, 0.3])],
            )],
        ),
        (
            "Rename",
            vec![("sim.setObjectAlias", vec![h(made), Value::Str("crate".into())])],
        ),
        (
            "Re-parent",
            vec![("sim.setObjectParent", vec![h(made), h(marker), Value::Bool(true)])],
        ),
        (
            "Colour",
            vec![(
                "sim.setShapeColor",
                vec![h(made), Value::Nil, h(0), Value::floats(&[0.9, 0.1, 0.1])],
            )],
        ),
        (
            "Dynamic",
            vec![("sim.setObjectInt32Param", vec![h(boxed), h(3003), h(1)])],
        ),
        ("Mass", vec![("sim.setShapeMass", vec![h(boxed), Value::Float(2.5)])]),
        (
            "Delete",
            vec![("sim.removeObjects", vec![Value::Array(vec![h(spare)])])],
        ),
        (
            "Duplicate",
            vec![("sim.copyPasteObjects", vec![Value::Array(vec![h(made)])])],
        ),
    ];
    for (label, calls) in &steps {
        edit(&mut scene, label, calls).unwrap_or_else(|e| panic!("{label}: {e}"));
        let now = fingerprint(&scene);
        assert_ne!(Some(&now), states.last(), "{label} changed nothing");
        states.push(now);
    }
    assert_eq!(scene.sim.history_depth(), (steps.len() + 1, 0));
    // Back to the scene as loaded, one step at a time, then forward again.
    for k in (0..states.len() - 1).rev() {
        assert!(!undo(&mut scene, true).is_empty());
        assert_eq!(fingerprint(&scene), states[k], "undo to state {k}");
    }
    assert!(undo(&mut scene, true).is_empty(), "nothing left to undo");
    for (k, state) in states.iter().enumerate().skip(1) {
        assert!(!undo(&mut scene, false).is_empty());
        assert_eq!(&fingerprint(&scene), state, "redo to state {k}");
    }
    // A new edit after an undo drops what could have been redone.
    undo(&mut scene, true);
    edit(
        &mut scene,
        "Add dummy",
        &[("sim.createDummy", vec![Value::Float(0.01)])],
    )
    .expect("edit");
    assert_eq!(scene.sim.history_depth().1, 0);
}

#[test]
fn a_paste_of_a_thousand_objects_undoes_exactly() {
    let mut scene = Scene::new("edit-paste", SCENE, &[], ScriptLimits::default());
    let creates: Vec<Call<'_>> = (0..1000)
        .map(|_| {
            (
                "sim.createPrimitiveShape",
                vec![Value::Int(3), Value::floats(&[0.05, 0.05, 0.05])],
            )
        })
        .collect();
    let made: Vec<Value> = edit(&mut scene, "Add 1000", &creates)
        .expect("created")
        .into_iter()
        .map(|r| list(&r)[0].clone())
        .collect();
    let before = fingerprint(&scene);
    let copies = edit(
        &mut scene,
        "Paste",
        &[("sim.copyPasteObjects", vec![Value::Array(made)])],
    )
    .expect("pasted");
    let copies = list(&list(&copies[0])[0]).to_vec();
    assert_eq!(copies.len(), 1000);
    let pasted = fingerprint(&scene);
    undo(&mut scene, true);
    assert_eq!(fingerprint(&scene), before);
    assert!(
        scene.sim.call("getObjectAlias", &[copies[0].clone()]).is_err(),
        "a copy survived the undo"
    );
    undo(&mut scene, false);
    assert_eq!(
        fingerprint(&scene),
        pasted,
        "the redo gives back the same copies, handles included"
    );
}

#[test]
fn a_failed_edit_changes_nothing_and_edits_wait_for_a_stop() {
    let mut scene = Scene::new("edit-refused", SCENE, &[], ScriptLimits::default());
    let marker = scene.find("/marker");
    let before = fingerprint(&scene);
    let e = edit(
        &mut scene,
        "Add and place",
        &[
            ("sim.createDummy", vec![Value::Float(0.01)]),
            (
                "sim.setObjectPosition",
                vec![Value::Int(marker), Value::Int(-1), Value::floats(&[f64::NAN, 0.0, 0.0])],
            ),
        ],
    )
    .expect_err("a NaN position");
    assert_contains(&e, &["call 2 of 2", "nothing changed", "sim.setObjectPosition"]);
    let e = edit(
        &mut scene,
        "Not an edit",
        &[("sim.loadScene", vec![Value::Str("x.toml".into())])],
    )
    .expect_err("host");
    assert_contains(&e, &["not a scene edit"]);
    assert_eq!(fingerprint(&scene), before);
    assert_eq!(scene.sim.history_depth(), (0, 0));
    scene.sim.start();
    let e = edit(&mut scene, "Add", &[("sim.createDummy", vec![Value::Float(0.01)])]).expect_err("running");
    assert_contains(&e, &["while the simulation is stopped", "stop it first"]);
    assert!(scene.sim.serve(Input::Undo(true)).into_values().is_err());
    scene.sim.stop();
    // The history keeps HISTORY_STEPS edits.
    for _ in 0..HISTORY_STEPS + 5 {
        edit(&mut scene, "Add", &[("sim.createDummy", vec![Value::Float(0.01)])]).expect("edit");
    }
    assert_eq!(scene.sim.history_depth(), (HISTORY_STEPS, 0));
}
