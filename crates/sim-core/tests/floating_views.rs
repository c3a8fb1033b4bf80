//! `sim.floatingViewAdd`, `sim.adjustView` and `sim.floatingViewRemove` through the
//! API, as CoppeliaSim's quadricopter scripts call them; the viewer's side is in
//! tests/browser/test_viewer.py.

use std::path::Path;

use gantry_sim_core::api::{self, CallContext};
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene_text};
use gantry_sim_core::{Sim, Value};

const SCENE: &str = r#"
[[object]]
name = "floorCam"
kind = "vision_sensor"
resolution = [32, 32]

[[object]]
name = "body"
kind = "dummy"
"#;

fn call(w: &mut Sim, name: &str, args: &[Value]) -> Result<Vec<Value>, String> {
    let ctx = CallContext {
        script_object: None,
        source: "views.lua",
    };
    api::call(w, &ctx, name, args).map_err(|e| e.to_string())
}

fn f(v: f64) -> Value {
    Value::Float(v)
}

#[test]
fn views_are_added_associated_and_removed() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("views.toml");
    let mut w = Sim::new(&load_scene_text(&DiskFiles, SCENE, &path, &LoadOptions::default()).expect("scene"));
    let cam = w.world.find("/floorCam", None, 0).expect("camera");
    let body = w.world.find("/body", None, 0).expect("body");
    let v = call(
        &mut w,
        "sim.floatingViewAdd",
        &[f(0.9), f(0.9), f(0.2), f(0.2), Value::Int(0)],
    )
    .unwrap()[0]
        .as_i64()
        .unwrap();
    assert_eq!(
        call(
            &mut w,
            "sim.adjustView",
            &[Value::Int(v), Value::Int(cam), Value::Int(64)]
        )
        .unwrap(),
        [Value::Int(1)]
    );
    let view = w.views.iter().next().cloned().expect("one view");
    assert_eq!(
        (view.centre, view.size, view.object),
        ([0.9, 0.9], [0.2, 0.2], Some(cam))
    );
    assert_eq!(view.label, "floorCam", "the object's alias without a label");
    call(
        &mut w,
        "sim.adjustView",
        &[
            Value::Int(v),
            Value::Int(cam),
            Value::Int(0),
            Value::Str("floor".into()),
        ],
    )
    .unwrap();
    assert_eq!(w.views.iter().next().map(|x| x.label.clone()), Some("floor".into()));

    // Errors name the argument; a removed sensor leaves its view empty.
    let e = call(
        &mut w,
        "sim.adjustView",
        &[Value::Int(v), Value::Int(body), Value::Int(0)],
    )
    .unwrap_err();
    assert!(e.contains("argument 2") && e.contains("sim.adjustView"), "{e}");
    let e = call(
        &mut w,
        "sim.adjustView",
        &[Value::Int(99), Value::Int(cam), Value::Int(0)],
    )
    .unwrap_err();
    assert!(e.contains("no floating view 99"), "{e}");
    let e = call(
        &mut w,
        "sim.floatingViewAdd",
        &[f(2.0), f(0.5), f(0.1), f(0.1), Value::Int(0)],
    )
    .unwrap_err();
    assert!(e.contains("0..1"), "{e}");
    call(&mut w, "sim.removeObjects", &[Value::Array(vec![Value::Int(cam)])]).unwrap();
    assert_eq!(w.views.iter().next().and_then(|x| x.object), None);

    assert_eq!(
        call(&mut w, "sim.floatingViewRemove", &[Value::Int(v)]).unwrap(),
        [Value::Int(1)]
    );
    assert_eq!(
        call(&mut w, "sim.floatingViewRemove", &[Value::Int(v)]).unwrap(),
        [Value::Int(0)]
    );
    assert_eq!(w.views.iter().count(), 0);
}
