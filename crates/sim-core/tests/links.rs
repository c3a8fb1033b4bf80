//! Dummy links (`sim.setLinkDummy`): a suction pad's dummy linked to a dummy on a box
//! holds the box against gravity; unlinking drops it.

use crate::util;

use gantry_sim_core::{Handle, Sim, Value};
use util::{call, find};

/// A fixed holder at 1 m with a pad dummy under it, and a free 10 cm box below whose
/// grip dummy sits 5 cm under the pad.
const SCENE: &str = r#"
[simulation]
dt = 0.05
substeps = 10

[floor]

[[object]]
name = "holder"
kind = "shape"
shape = "box"
size = [0.1, 0.1, 0.1]
position = [0, 0, 1.0]

[[object]]
name = "pad"
kind = "dummy"
parent = "holder"
position = [0, 0, -0.05]

[[object]]
name = "box"
kind = "shape"
shape = "box"
size = [0.1, 0.1, 0.1]
position = [0, 0, 0.85]
dynamic = true
mass = 0.5

[[object]]
name = "grip"
kind = "dummy"
parent = "box"
position = [0, 0, 0.05]
"#;

fn world() -> Sim {
    util::text_scene("links.toml", SCENE)
}

fn height(w: &mut Sim, h: Handle) -> f64 {
    match &call(w, "getObjectPosition", &[Value::Int(h), Value::Int(-1)]).expect("position")[0] {
        Value::Array(p) => p[2].as_f64().expect("z"),
        other => panic!("{other:?}"),
    }
}

fn steps(w: &mut Sim, n: usize) {
    for _ in 0..n {
        w.step();
    }
}

#[test]
fn a_linked_dummy_holds_the_box_and_unlinking_drops_it() {
    let mut w = world();
    let (pad, grip, bx) = (find(&w, "/holder/pad"), find(&w, "/box/grip"), find(&w, "/box"));
    assert_eq!(
        call(&mut w, "getLinkDummy", &[Value::Int(pad)]).unwrap(),
        [Value::Int(-1)]
    );
    call(&mut w, "setLinkDummy", &[Value::Int(pad), Value::Int(grip)]).expect("link");
    // The link is symmetric.
    assert_eq!(
        call(&mut w, "getLinkDummy", &[Value::Int(pad)]).unwrap(),
        [Value::Int(grip)]
    );
    assert_eq!(
        call(&mut w, "getLinkDummy", &[Value::Int(grip)]).unwrap(),
        [Value::Int(pad)]
    );
    steps(&mut w, 40);
    // The grip was pulled onto the pad: the box hangs with its centre 10 cm under the
    // holder's, 5 cm above where it started, instead of falling to the floor.
    let z = height(&mut w, bx);
    assert!((z - 0.90).abs() < 0.01, "held at z = {z}");
    call(&mut w, "setLinkDummy", &[Value::Int(grip), Value::Int(-1)]).expect("unlink");
    assert_eq!(
        call(&mut w, "getLinkDummy", &[Value::Int(pad)]).unwrap(),
        [Value::Int(-1)]
    );
    steps(&mut w, 40);
    let z = height(&mut w, bx);
    assert!((z - 0.05).abs() < 0.01, "dropped to the floor: z = {z}");
}

#[test]
fn only_dummies_can_be_linked() {
    let mut w = world();
    let (pad, bx) = (find(&w, "/holder/pad"), find(&w, "/box"));
    let e = call(&mut w, "setLinkDummy", &[Value::Int(pad), Value::Int(bx)]).unwrap_err();
    assert!(
        e.contains("not a dummy") && e.ends_with("(in function 'sim.setLinkDummy')"),
        "{e}"
    );
    let e = call(&mut w, "setLinkDummy", &[Value::Int(pad), Value::Int(9999)]).unwrap_err();
    assert!(e.contains("does not exist"), "{e}");
    // Removing a linked dummy removes the link.
    let grip = find(&w, "/box/grip");
    call(&mut w, "setLinkDummy", &[Value::Int(pad), Value::Int(grip)]).expect("link");
    call(&mut w, "removeObjects", &[Value::Array(vec![Value::Int(grip)])]).expect("remove");
    assert_eq!(
        call(&mut w, "getLinkDummy", &[Value::Int(pad)]).unwrap(),
        [Value::Int(-1)]
    );
}
