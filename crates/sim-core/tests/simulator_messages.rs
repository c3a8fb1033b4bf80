//! `sim.getSimulatorMessage` as CoppeliaSim documents it: each script (and, here, the
//! remote clients together) reads its own queue of user-interface events until it gets
//! -1; gantry's events are the viewer's key presses (`sim.message_keypress`).

use std::path::Path;

use gantry_sim_core::api::{self, CallContext};
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene_text};
use gantry_sim_core::ui::keys;
use gantry_sim_core::{Handle, Sim, Value};

fn next(w: &mut Sim, reader: Option<Handle>) -> (i64, Vec<Value>) {
    let ctx = CallContext {
        script_object: reader,
        source: "messages.lua",
    };
    let r = api::call(w, &ctx, "sim.getSimulatorMessage", &[]).expect("getSimulatorMessage");
    assert_eq!(r.len(), 3, "message, auxiliaryData, auxiliaryData2");
    let Value::Array(aux) = &r[1] else { panic!("{r:?}") };
    assert_eq!(aux.len(), 4);
    (r[0].as_i64().expect("an integer"), aux.clone())
}

#[test]
fn each_reader_drains_its_own_queue() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("messages.toml");
    let model = load_scene_text(
        &DiskFiles,
        "[[object]]\nname = \"a\"\nkind = \"dummy\"\n",
        &path,
        &LoadOptions::default(),
    )
    .expect("scene");
    let mut w = Sim::new(&model);
    let keypress = api::module("sim")
        .and_then(|m| m.constants.iter().find(|(n, _)| *n == "message_keypress"))
        .map(|(_, v)| *v)
        .expect("sim.message_keypress");
    assert_eq!(keypress, 6, "CoppeliaSim's value");
    assert_eq!(next(&mut w, Some(0)).0, -1, "nothing yet");
    w.messages.post_key(keys::UP, 0);
    w.messages.post_key(i64::from(b'q'), 1);
    for reader in [Some(0), None] {
        let (m, aux) = next(&mut w, reader);
        assert_eq!((m, aux[0].as_i64(), aux[1].as_i64()), (6, Some(2007), Some(0)));
        let (m, aux) = next(&mut w, reader);
        assert_eq!((m, aux[0].as_i64(), aux[1].as_i64()), (6, Some(113), Some(1)));
        assert_eq!(next(&mut w, reader).0, -1);
    }
}
