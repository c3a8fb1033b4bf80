//! Custom data blocks (`sim.writeCustomDataBlock`, `sim.readCustomDataBlock`,
//! `sim.readCustomDataBlockTags`) through the API.

use crate::util;

use gantry_sim_core::{Handle, Sim, Value};
use util::call;

/// `sim.handle_scene`.
const SCENE: i64 = -12;

fn world() -> Sim {
    util::asset_scene("scenes/bubble_rob.toml")
}

fn base(w: &Sim) -> Handle {
    w.world.find("/bubbleRob", None, 0).expect("/bubbleRob")
}

fn write(w: &mut Sim, h: i64, tag: &str, data: Value) {
    call(w, "sim.writeCustomDataBlock", &[Value::Int(h), Value::from(tag), data]).expect("write");
}

fn read(w: &mut Sim, h: i64, tag: &str) -> Value {
    let r = call(w, "sim.readCustomDataBlock", &[Value::Int(h), Value::from(tag)]).expect("read");
    assert_eq!(r.len(), 1, "one result");
    r.into_iter().next().unwrap_or(Value::Nil)
}

fn tags(w: &mut Sim, h: i64) -> Vec<String> {
    let r = call(w, "sim.readCustomDataBlockTags", &[Value::Int(h)]).expect("tags");
    let Some(Value::Array(items)) = r.first() else {
        panic!("expected a table, got {r:?}");
    };
    items.iter().map(|v| v.as_str().expect("a string").to_owned()).collect()
}

#[test]
fn blocks_round_trip_as_written() {
    let mut w = world();
    let h = base(&w);
    let bytes = vec![0u8, 1, 2, 255, 0];
    write(&mut w, h, "buffer", Value::Bytes(bytes.clone()));
    write(&mut w, h, "text", Value::from("hello"));
    assert_eq!(read(&mut w, h, "buffer"), Value::Bytes(bytes));
    assert_eq!(read(&mut w, h, "text"), Value::from("hello"));
    // Overwrite.
    write(&mut w, h, "text", Value::from("again"));
    assert_eq!(read(&mut w, h, "text"), Value::from("again"));
    assert_eq!(read(&mut w, h, "absent"), Value::Nil);
}

#[test]
fn empty_or_nil_data_deletes_and_an_empty_tag_clears_all() {
    let mut w = world();
    let h = base(&w);
    for tag in ["a", "b", "c"] {
        write(&mut w, h, tag, Value::from("x"));
    }
    write(&mut w, h, "a", Value::from(""));
    write(&mut w, h, "b", Value::Bytes(Vec::new()));
    assert_eq!(read(&mut w, h, "a"), Value::Nil);
    assert_eq!(read(&mut w, h, "b"), Value::Nil);
    call(&mut w, "sim.writeCustomDataBlock", &[Value::Int(h), Value::from("c")]).expect("nil data");
    assert_eq!(read(&mut w, h, "c"), Value::Nil);

    for tag in ["a", "b"] {
        write(&mut w, h, tag, Value::from("x"));
    }
    write(&mut w, SCENE, "kept", Value::from("x"));
    write(&mut w, h, "", Value::from("ignored"));
    assert!(tags(&mut w, h).is_empty());
    assert_eq!(tags(&mut w, SCENE), vec!["kept"], "other owners keep theirs");
}

#[test]
fn tags_list_only_that_objects_blocks() {
    let mut w = world();
    let h = base(&w);
    let other = w
        .world
        .find("/bubbleRob/sensingNose", None, 0)
        .expect("a second object");
    assert!(tags(&mut w, h).is_empty());
    write(&mut w, h, "zeta", Value::from("1"));
    write(&mut w, h, "alpha", Value::from("2"));
    write(&mut w, other, "other", Value::from("3"));
    assert_eq!(tags(&mut w, h), vec!["alpha", "zeta"]);
    assert_eq!(tags(&mut w, other), vec!["other"]);
}

#[test]
fn scene_blocks_are_their_own() {
    let mut w = world();
    let h = base(&w);
    write(&mut w, SCENE, "settings", Value::from("scene"));
    write(&mut w, h, "settings", Value::from("object"));
    assert_eq!(read(&mut w, SCENE, "settings"), Value::from("scene"));
    assert_eq!(read(&mut w, h, "settings"), Value::from("object"));
    assert_eq!(tags(&mut w, SCENE), vec!["settings"]);
}

#[test]
fn blocks_and_user_parameters_do_not_meet() {
    let mut w = world();
    let h = base(&w);
    write(&mut w, h, "speed", Value::from("block"));
    call(
        &mut w,
        "sim.setUserParameter",
        &[Value::Int(h), Value::from("speed"), Value::Float(2.0)],
    )
    .expect("user parameter");
    assert_eq!(read(&mut w, h, "speed"), Value::from("block"));
    let p = call(&mut w, "sim.getUserParameter", &[Value::Int(h), Value::from("speed")]).expect("get");
    assert_eq!(p, vec![Value::Float(2.0)]);
}

#[test]
fn bad_handles_and_arguments_name_the_function() {
    let mut w = world();
    for name in [
        "sim.writeCustomDataBlock",
        "sim.readCustomDataBlock",
        "sim.readCustomDataBlockTags",
    ] {
        let e = call(&mut w, name, &[Value::Int(9999), Value::from("t"), Value::from("d")]).expect_err(name);
        assert!(e.contains("object does not exist"), "{e}");
        assert!(e.ends_with(&format!("(in function '{name}')")), "{e}");
    }
    let h = base(&w);
    let e = call(
        &mut w,
        "sim.writeCustomDataBlock",
        &[Value::Int(h), Value::from("t"), Value::Int(3)],
    )
    .expect_err("a number is not data");
    assert!(e.contains("argument 3"), "{e}");
    let e = call(&mut w, "sim.readCustomDataBlock", &[Value::Int(h), Value::Int(1)]).expect_err("tag");
    assert!(e.contains("argument 2"), "{e}");
}

#[test]
fn removed_objects_forget_their_blocks() {
    let mut w = world();
    let h = base(&w);
    let other = w
        .world
        .find("/bubbleRob/sensingNose", None, 0)
        .expect("a second object");
    write(&mut w, other, "gone", Value::from("x"));
    write(&mut w, h, "stays", Value::from("y"));
    call(&mut w, "sim.removeObjects", &[Value::Array(vec![Value::Int(other)])]).expect("remove");
    assert!(w.world.custom.block(other, "gone").is_none());
    assert!(
        call(
            &mut w,
            "sim.readCustomDataBlock",
            &[Value::Int(other), Value::from("gone")]
        )
        .is_err()
    );
    assert_eq!(read(&mut w, h, "stays"), Value::from("y"));
}

/// CoppeliaSim 4.7's property spelling of the same blocks, as scripts written for it
/// store data (`sim.setBufferProperty(h, 'customData.Odometry', sim.packTable(...))`).
#[test]
fn buffer_properties_are_custom_data_blocks() {
    let mut w = world();
    let h = base(&w);
    let data = Value::Bytes(vec![1, 2, 3]);
    call(
        &mut w,
        "sim.setBufferProperty",
        &[Value::Int(h), Value::Str("customData.Odometry".into()), data.clone()],
    )
    .unwrap();
    assert_eq!(read(&mut w, h, "Odometry"), data);
    write(&mut w, h, "other", Value::Str("x".into()));
    let got = call(
        &mut w,
        "sim.getBufferProperty",
        &[Value::Int(h), Value::Str("customData.other".into())],
    )
    .unwrap();
    assert_eq!(got, [Value::Str("x".into())]);
    let e = call(
        &mut w,
        "sim.getBufferProperty",
        &[Value::Int(h), Value::Str("customData.none".into())],
    )
    .unwrap_err();
    assert!(
        e.contains("does not exist") && e.contains("sim.getBufferProperty"),
        "{e}"
    );
    let quiet = Value::Map(vec![(Value::Str("noError".into()), Value::Bool(true))]);
    assert_eq!(
        call(
            &mut w,
            "sim.getBufferProperty",
            &[Value::Int(h), Value::Str("customData.none".into()), quiet]
        )
        .unwrap(),
        [Value::Nil]
    );
    let e = call(
        &mut w,
        "sim.setBufferProperty",
        &[Value::Int(h), Value::Str("signal.x".into()), Value::Bytes(vec![])],
    )
    .unwrap_err();
    assert!(e.contains("customData.<tag>") && e.contains("argument 2"), "{e}");
}

/// Referenced handles (4.7+): set, read by tag, listed, and a removed object reads -1.
#[test]
fn referenced_handles_round_trip() {
    let mut w = world();
    let b = base(&w);
    let nose = w.world.find("/bubbleRob/sensingNose", None, 0).expect("nose");
    let obstacle = w.world.find("/obstacle", None, 0).expect("obstacle");
    let ints = |v: &[i64]| Value::Array(v.iter().map(|&h| Value::Int(h)).collect());
    call(
        &mut w,
        "sim.setReferencedHandles",
        &[Value::Int(b), ints(&[nose, obstacle]), Value::from("seen")],
    )
    .expect("set");
    call(&mut w, "sim.setReferencedHandles", &[Value::Int(b), ints(&[nose])]).expect("set the default tag");
    let get = |w: &mut Sim, f: &str, tag: &str| call(w, f, &[Value::Int(b), Value::from(tag)]).expect(f);
    assert_eq!(
        get(&mut w, "sim.getReferencedHandles", "seen"),
        [ints(&[nose, obstacle])]
    );
    assert_eq!(get(&mut w, "sim.getReferencedHandle", "seen"), [Value::Int(nose)]);
    assert_eq!(get(&mut w, "sim.getReferencedHandle", "none"), [Value::Int(-1)]);
    assert_eq!(get(&mut w, "sim.getReferencedHandles", "none"), [ints(&[])]);
    let tags = call(&mut w, "sim.getReferencedHandlesTags", &[Value::Int(b)]).expect("tags");
    assert_eq!(tags, [Value::Array(vec![Value::from(""), Value::from("seen")])]);

    call(&mut w, "sim.removeObjects", &[ints(&[obstacle])]).expect("removed");
    assert_eq!(get(&mut w, "sim.getReferencedHandles", "seen"), [ints(&[nose, -1])]);
    // A handle that names no object is refused, and the list stays.
    let e = call(
        &mut w,
        "sim.setReferencedHandles",
        &[Value::Int(b), ints(&[obstacle]), Value::from("seen")],
    )
    .expect_err("a removed object");
    assert!(!e.is_empty());
    assert_eq!(get(&mut w, "sim.getReferencedHandles", "seen"), [ints(&[nose, -1])]);
    // An empty list removes the tag.
    call(
        &mut w,
        "sim.setReferencedHandles",
        &[Value::Int(b), ints(&[]), Value::from("seen")],
    )
    .expect("cleared");
    let tags = call(&mut w, "sim.getReferencedHandlesTags", &[Value::Int(b)]).expect("tags");
    assert_eq!(tags, [Value::Array(vec![Value::from("")])]);
}
