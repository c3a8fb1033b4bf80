//! `sim.getObjectSel` / `sim.setObjectSel`: the selection scripts and clients share with
//! the viewer (whose click selects); the page side is in tests/browser/test_viewer.py.

use std::path::Path;

use gantry_sim_core::api::{self, CallContext};
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene_text};
use gantry_sim_core::{Sim, Value};

fn call(w: &mut Sim, name: &str, args: &[Value]) -> Result<Vec<Value>, String> {
    api::call(w, &CallContext::default(), name, args).map_err(|e| e.to_string())
}

fn ints(v: &[i64]) -> Value {
    Value::Array(v.iter().map(|&h| Value::Int(h)).collect())
}

#[test]
fn the_selection_is_set_read_and_forgets_removed_objects() {
    let text = "[[object]]\nname = \"a\"\nkind = \"dummy\"\n\n[[object]]\nname = \"b\"\nkind = \"dummy\"\n";
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("sel.toml");
    let mut w = Sim::new(&load_scene_text(&DiskFiles, text, &path, &LoadOptions::default()).expect("scene"));
    let (a, b) = (
        w.world.find("/a", None, 0).unwrap(),
        w.world.find("/b", None, 0).unwrap(),
    );
    assert_eq!(call(&mut w, "sim.getObjectSel", &[]).unwrap(), [ints(&[])]);
    call(&mut w, "sim.setObjectSel", &[ints(&[b, a, b])]).unwrap();
    assert_eq!(
        call(&mut w, "sim.getObjectSel", &[]).unwrap(),
        [ints(&[b, a])],
        "order kept, no duplicate"
    );
    let r = w.world.selection.revision();
    call(&mut w, "sim.setObjectSel", &[ints(&[b, a])]).unwrap();
    assert_eq!(
        w.world.selection.revision(),
        r,
        "an unchanged selection is not a change"
    );
    let e = call(&mut w, "sim.setObjectSel", &[ints(&[a, 999])]).unwrap_err();
    assert!(e.contains("999") && e.contains("sim.setObjectSel"), "{e}");
    assert_eq!(
        call(&mut w, "sim.getObjectSel", &[]).unwrap(),
        [ints(&[b, a])],
        "a refused call changes nothing"
    );
    call(&mut w, "sim.removeObjects", &[ints(&[b])]).unwrap();
    assert_eq!(call(&mut w, "sim.getObjectSel", &[]).unwrap(), [ints(&[a])]);
    // An empty Lua table arrives as an empty map.
    call(&mut w, "sim.setObjectSel", &[Value::Map(Vec::new())]).unwrap();
    assert_eq!(call(&mut w, "sim.getObjectSel", &[]).unwrap(), [ints(&[])]);
    let e = call(&mut w, "sim.setObjectSel", &[Value::Int(a)]).unwrap_err();
    assert!(e.contains("argument 1"), "{e}");
}

/// 4.1's `sim.getObjectSelection`, which old customization scripts still call: the same
/// selection, but `nil` when it is empty.
#[test]
fn the_old_selection_function_returns_nil_when_nothing_is_selected() {
    let text = "[[object]]\nname = \"a\"\nkind = \"dummy\"\n";
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("sel.toml");
    let mut w = Sim::new(&load_scene_text(&DiskFiles, text, &path, &LoadOptions::default()).expect("scene"));
    let a = w.world.find("/a", None, 0).unwrap();
    assert_eq!(call(&mut w, "sim.getObjectSelection", &[]).unwrap(), [Value::Nil]);
    call(&mut w, "sim.setObjectSel", &[ints(&[a])]).unwrap();
    assert_eq!(call(&mut w, "sim.getObjectSelection", &[]).unwrap(), [ints(&[a])]);
}
