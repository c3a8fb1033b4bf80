//! CoppeliaSim 4.0-4.5 names in the registry: each behaves as the version that
//! documented it, and renames run the current implementation.

use crate::util;

use gantry_sim_core::api::{self, CallContext};
use gantry_sim_core::{Handle, Sim, Value};
use util::find;

/// Three shapes named as CoppeliaSim names copies (`box`, `box#0`'s original name is
/// `box` too), a dynamic one, and a joint.
const SCENE: &str = r#"
[[object]]
name = "box"
kind = "shape"
shape = "box"
size = [0.1, 0.1, 0.1]
position = [0, 0, 0.05]

[[object]]
name = "box2"
alias = "box"
kind = "shape"
shape = "box"
size = [0.1, 0.1, 0.1]
position = [1, 0, 0.05]

[[object]]
name = "ball"
kind = "shape"
shape = "sphere"
radius = 0.05
position = [0, 1, 1]
dynamic = true

[[object]]
name = "hinge"
kind = "joint"
joint = "revolute"
mode = "velocity"
position = [2, 0, 0.5]
"#;

fn world() -> Sim {
    util::text_scene("legacy.toml", SCENE)
}

/// A call as the script attached to `object` makes it.
fn call(w: &mut Sim, object: Option<Handle>, name: &str, args: &[Value]) -> Result<Vec<Value>, String> {
    let ctx = CallContext {
        script_object: object,
        source: "legacy.lua",
    };
    api::call(w, &ctx, name, args).map_err(|e| e.to_string())
}

fn ok(w: &mut Sim, name: &str, args: &[Value]) -> Vec<Value> {
    call(w, None, name, args).unwrap_or_else(|e| panic!("sim.{name}: {e}"))
}

fn s(v: &str) -> Value {
    Value::Str(v.to_owned())
}

#[test]
fn get_object_handle_resolves_names_and_copy_suffixes() {
    let mut w = world();
    let first = find(&w, "/box");
    let second = find(&w, "/box[1]");
    assert_ne!(first, second);
    assert_eq!(ok(&mut w, "getObjectHandle", &[s("box")]), [Value::Int(first)]);
    assert_eq!(ok(&mut w, "getObjectHandle", &[s("box#")]), [Value::Int(first)]);
    // `name#0` is the first copy: the second object of that name.
    assert_eq!(ok(&mut w, "getObjectHandle", &[s("box#0")]), [Value::Int(second)]);
    assert_eq!(
        ok(&mut w, "getObjectHandle", &[s("/ball")]),
        [Value::Int(find(&w, "/ball"))]
    );
    assert_eq!(
        ok(&mut w, "getObjectHandle", &[s("nothing@silentError")]),
        [Value::Int(-1)]
    );
    assert_eq!(
        ok(&mut w, "getObjectHandle", &[s("box#7@silentError")]),
        [Value::Int(-1)]
    );
    let e = call(&mut w, None, "getObjectHandle", &[s("nothing")]).unwrap_err();
    assert_eq!(
        e,
        "object does not exist: 'nothing' (in function 'sim.getObjectHandle')"
    );
    // Scripts may pass sim.handle_self, which is their own object.
    let ball = find(&w, "/ball");
    assert_eq!(
        call(&mut w, Some(ball), "getObjectHandle", &[Value::Int(-4)]).unwrap(),
        [Value::Int(ball)]
    );
}

#[test]
fn renamed_functions_run_the_current_ones() {
    let mut w = world();
    ok(&mut w, "setIntegerSignal", &[s("n"), Value::Int(5)]);
    assert_eq!(ok(&mut w, "getInt32Signal", &[s("n")]), [Value::Int(5)]);
    assert_eq!(ok(&mut w, "getIntegerSignal", &[s("n")]), [Value::Int(5)]);
    ok(&mut w, "clearIntegerSignal", &[s("n")]);
    assert_eq!(ok(&mut w, "getIntegerSignal", &[s("n")]), [Value::Nil]);
    let ball = find(&w, "/ball");
    assert_eq!(ok(&mut w, "getObjectName", &[Value::Int(ball)]), [s("ball")]);
    // An old name reports errors under its own name.
    let e = call(&mut w, None, "getIntegerSignal", &[Value::Int(3)]).unwrap_err();
    assert!(e.ends_with("(in function 'sim.getIntegerSignal')"), "{e}");
    // Every alias names a function that exists.
    let sim = api::module("sim").expect("sim");
    for (old, current) in sim.aliases {
        assert!(sim.function(current).is_some(), "{old} -> {current}");
        assert!(
            sim.iter().all(|f| f.name != *old),
            "{old} is both an alias and a function"
        );
    }
}

#[test]
fn old_parameter_getters_return_a_result_first() {
    let mut w = world();
    let ball = find(&w, "/ball");
    // sim.shapeintparam_static = 3003: the ball is dynamic.
    let r = ok(&mut w, "getObjectInt32Parameter", &[Value::Int(ball), Value::Int(3003)]);
    assert_eq!(r, [Value::Int(1), Value::Int(0)]);
    let current = ok(&mut w, "getObjectInt32Param", &[Value::Int(ball), Value::Int(3003)]);
    assert_eq!(current, [Value::Int(0)]);
}

#[test]
fn status_bar_consoles_and_dialogs_write_to_the_log() {
    let mut w = world();
    ok(&mut w, "addStatusbarMessage", &[s("hello")]);
    ok(&mut w, "addStatusbarMessage", &[Value::Nil]);
    let c = ok(
        &mut w,
        "auxiliaryConsoleOpen",
        &[s("Out"), Value::Int(10), Value::Int(1)],
    )[0]
    .clone();
    assert_eq!(
        ok(&mut w, "auxiliaryConsolePrint", &[c.clone(), s("a\nb\n")]),
        [Value::Int(1)]
    );
    assert_eq!(
        ok(&mut w, "auxiliaryConsoleClose", std::slice::from_ref(&c)),
        [Value::Int(1)]
    );
    // A closed console prints nothing and says so.
    assert_eq!(
        ok(&mut w, "auxiliaryConsolePrint", &[c.clone(), s("c")]),
        [Value::Int(0)]
    );
    assert_eq!(ok(&mut w, "auxiliaryConsoleClose", &[c]), [Value::Int(0)]);
    let d = ok(
        &mut w,
        "displayDialog",
        &[s("Title"), s("Proceed?"), Value::Int(4), Value::Bool(false)],
    )[0]
    .clone();
    assert_eq!(ok(&mut w, "getDialogResult", std::slice::from_ref(&d)), [Value::Int(1)]);
    assert_eq!(ok(&mut w, "endDialog", &[d]), [Value::Int(1)]);
    let lines: Vec<(String, String)> = w
        .world
        .log
        .lines()
        .map(|l| (l.source.clone(), l.message.clone()))
        .collect();
    assert_eq!(
        lines,
        [
            ("legacy.lua".to_owned(), "hello".to_owned()),
            ("console: Out".to_owned(), "a".to_owned()),
            ("console: Out".to_owned(), "b".to_owned()),
            ("legacy.lua".to_owned(), "Title: Proceed?".to_owned()),
        ]
    );
}

#[test]
fn user_parameters_script_association_and_misc() {
    let mut w = world();
    let ball = find(&w, "/ball");
    let hinge = find(&w, "/hinge");
    let own = |w: &mut Sim, name: &str, args: &[Value]| call(w, Some(ball), name, args).expect(name);
    assert_eq!(
        own(&mut w, "getScriptSimulationParameter", &[Value::Int(-4), s("gain")]),
        [Value::Nil]
    );
    own(
        &mut w,
        "setScriptSimulationParameter",
        &[Value::Int(-4), s("gain"), Value::Float(0.5)],
    );
    assert_eq!(
        own(&mut w, "getScriptSimulationParameter", &[Value::Int(-4), s("gain")]),
        [Value::Float(0.5)]
    );
    assert_eq!(
        own(&mut w, "getObjectAssociatedWithScript", &[Value::Int(-4)]),
        [Value::Int(ball)]
    );
    assert_eq!(own(&mut w, "getScriptHandle", &[]), [Value::Int(ball)]);
    assert_eq!(
        ok(&mut w, "isDynamicallyEnabled", &[Value::Int(ball)]),
        [Value::Bool(true)]
    );
    assert_eq!(
        ok(&mut w, "isDynamicallyEnabled", &[Value::Int(hinge)]),
        [Value::Bool(true)]
    );
    let fixed = find(&w, "/box");
    assert_eq!(
        ok(&mut w, "isDynamicallyEnabled", &[Value::Int(fixed)]),
        [Value::Bool(false)]
    );
    assert_eq!(ok(&mut w, "isHandle", &[Value::Int(ball)]), [Value::Bool(true)]);
    assert_eq!(ok(&mut w, "isHandle", &[Value::Int(9999)]), [Value::Bool(false)]);
    assert_eq!(
        ok(&mut w, "getObjectSizeFactor", &[Value::Int(ball)]),
        [Value::Float(1.0)]
    );
    assert_eq!(ok(&mut w, "getNamedInt32Param", &[s("anything")]), [Value::Nil]);
    assert_eq!(ok(&mut w, "getNameSuffix", &[s("arm#2")]), [Value::Int(2), s("arm")]);
    assert_eq!(ok(&mut w, "getNameSuffix", &[s("arm")]), [Value::Int(-1), s("arm")]);
    assert_eq!(ok(&mut w, "getNameSuffix", &[Value::Nil]), [Value::Int(-1), s("")]);
    ok(&mut w, "setUserParameter", &[Value::Int(hinge), s("k"), s("v")]);
    assert_eq!(ok(&mut w, "getUserParameter", &[Value::Int(hinge), s("k")]), [s("v")]);
    let bb = ok(&mut w, "getShapeBB", &[Value::Int(fixed)]);
    let Value::Array(size) = &bb[0] else { panic!("{bb:?}") };
    for v in size {
        assert!((v.as_f64().expect("number") - 0.1).abs() < 1e-9, "{bb:?}");
    }
    assert!(call(&mut w, None, "getShapeBB", &[Value::Int(hinge)]).is_err());
    let t = ok(&mut w, "getSystemTimeInMs", &[Value::Int(-1)])[0]
        .as_i64()
        .expect("ms");
    let dt = ok(&mut w, "getSystemTimeInMs", &[Value::Int(t)])[0]
        .as_i64()
        .expect("ms");
    assert!(t >= 0 && (0..10_000).contains(&dt), "{t} {dt}");
}
