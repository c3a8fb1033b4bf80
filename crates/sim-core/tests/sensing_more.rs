//! `sim.checkProximitySensor` on BubbleRob's nose sensor, and the CoppeliaSim 4.0-4.5
//! image getters (`sim.getVisionSensorCharImage`, `sim.getVisionSensorImage`) against
//! `sim.getVisionSensorImg`.

use crate::util;

use gantry_sim_core::{Handle, Sim, Value};
use gantry_test_support::int;
use util::call;

fn bubble_rob() -> Sim {
    util::asset_scene("scenes/bubble_rob.toml")
}

fn find(w: &Sim, path: &str, index: usize) -> Handle {
    w.world.find(path, None, index).expect(path)
}

/// Obstacle 0 with its front face 0.1 m ahead of the nose sensor, obstacle 1 behind it
/// (front face 0.14 m ahead, within the 0.15 m range). Returns world, sensor, obstacles.
fn two_obstacles_ahead() -> (Sim, Handle, [Handle; 2]) {
    let mut w = bubble_rob();
    let base = find(&w, "/bubbleRob", 0);
    let nose = find(&w, "/bubbleRob/sensingNose", 0);
    let obstacles = [find(&w, "/obstacle", 0), find(&w, "/obstacle", 1)];
    for (o, ahead) in obstacles.iter().zip([0.1, 0.14]) {
        let mut pose = w.world.object(base).expect("base").world;
        // Sensor 0.1 m in front of the base centre, cylinders of radius 0.05.
        pose.translation.vector.x += 0.1 + ahead + 0.05;
        pose.translation.vector.z = 0.1;
        pose.rotation = nalgebra::UnitQuaternion::identity();
        w.world.set_world_pose(*o, pose).expect("moves");
    }
    (w, nose, obstacles)
}

fn distance(r: &[Value]) -> f64 {
    r[1].as_f64().expect("distance")
}

#[test]
fn check_proximity_sensor_sees_only_the_entity_and_stays_silent() {
    let (mut w, nose, [o0, o1]) = two_obstacles_ahead();

    // Each obstacle on its own: the nearer does not hide the farther.
    let r = call(&mut w, "sim.checkProximitySensor", &[Value::Int(nose), Value::Int(o1)]).expect("check");
    assert_eq!((int(&r[0]), int(&r[3])), (1, o1), "{r:?}");
    assert!((distance(&r) - 0.14).abs() < 0.01, "{r:?}");
    let Value::Array(point) = &r[2] else {
        panic!("point: {r:?}")
    };
    assert_eq!(point.len(), 3);
    let r = call(&mut w, "sim.checkProximitySensor", &[Value::Int(nose), Value::Int(o0)]).expect("check");
    assert_eq!((int(&r[0]), int(&r[3])), (1, o0));
    assert!((distance(&r) - 0.1).abs() < 0.01, "{r:?}");

    // sim.handle_all: the nearest detectable shape, as handleProximitySensor finds it.
    let all = call(&mut w, "sim.checkProximitySensor", &[Value::Int(nose), Value::Int(-2)]).expect("all");
    let handled = call(&mut w, "sim.handleProximitySensor", &[Value::Int(nose)]).expect("handle");
    assert_eq!(int(&all[3]), o0);
    assert_eq!(int(&handled[3]), o0);
    assert!((distance(&all) - distance(&handled)).abs() < 1e-9);

    // A collection holding only obstacle 1.
    let coll = int(&call(&mut w, "sim.createCollection", &[Value::Int(0)]).expect("coll")[0]);
    call(
        &mut w,
        "sim.addItemToCollection",
        &[Value::Int(coll), Value::Int(-8), Value::Int(o1), Value::Int(0)],
    )
    .expect("add");
    let r = call(
        &mut w,
        "sim.checkProximitySensor",
        &[Value::Int(nose), Value::Int(coll)],
    )
    .expect("coll");
    assert_eq!(int(&r[3]), o1);

    // Silent: the reading of the last handling is untouched.
    let before = call(&mut w, "sim.readProximitySensor", &[Value::Int(nose)]).expect("read");
    call(&mut w, "sim.checkProximitySensor", &[Value::Int(nose), Value::Int(o1)]).expect("check");
    let after = call(&mut w, "sim.readProximitySensor", &[Value::Int(nose)]).expect("read");
    assert_eq!(before, after);
}

#[test]
fn check_proximity_sensor_out_of_range_and_bad_arguments() {
    let (mut w, nose, [o0, _]) = two_obstacles_ahead();
    let body = find(&w, "/bubbleRob", 0);
    // Never handled: a check does not make a reading appear.
    let r = call(
        &mut w,
        "sim.checkProximitySensor",
        &[Value::Int(nose), Value::Int(body)],
    )
    .expect("check");
    assert_eq!(r.len(), 5);
    assert_eq!(
        (int(&r[0]), int(&r[3])),
        (0, -1),
        "the sensor's own body is not seen: {r:?}"
    );
    let read = call(&mut w, "sim.readProximitySensor", &[Value::Int(nose)]).expect("read");
    assert_eq!(int(&read[0]), -1);

    let e = call(&mut w, "sim.checkProximitySensor", &[Value::Int(o0), Value::Int(o0)]).expect_err("not a sensor");
    assert!(
        e.contains("not a proximity sensor") && e.contains("sim.checkProximitySensor"),
        "{e}"
    );
    let e = call(
        &mut w,
        "sim.checkProximitySensor",
        &[Value::Int(nose), Value::Int(99_999)],
    )
    .expect_err("no entity");
    assert!(e.contains("sim.checkProximitySensor"), "{e}");
}

fn bytes(v: &Value) -> Vec<u8> {
    match v {
        Value::Bytes(b) => b.clone(),
        other => panic!("expected bytes, got {other:?}"),
    }
}

#[test]
fn legacy_image_getters_match_get_vision_sensor_img() {
    let (mut w, _, _) = two_obstacles_ahead();
    let cam = find(&w, "/bubbleRob/visionSensor", 0);
    call(&mut w, "sim.handleVisionSensor", &[Value::Int(cam)]).expect("render");
    let img = bytes(&call(&mut w, "sim.getVisionSensorImg", &[Value::Int(cam)]).expect("img")[0]);
    assert_eq!(img.len(), 256 * 256 * 3);

    let r = call(&mut w, "sim.getVisionSensorCharImage", &[Value::Int(cam)]).expect("char image");
    assert_eq!(bytes(&r[0]), img);
    assert_eq!((int(&r[1]), int(&r[2])), (256, 256));

    // A portion: columns 10..14, rows 20..23 (from the bottom); resX/resY stay the sensor's.
    let portion: Vec<Value> = [cam, 10, 20, 4, 3].iter().map(|&i| Value::Int(i)).collect();
    let r = call(&mut w, "sim.getVisionSensorCharImage", &portion).expect("portion");
    let expected: Vec<u8> = (20..23)
        .flat_map(|row| img[3 * (row * 256 + 10)..3 * (row * 256 + 14)].to_vec())
        .collect();
    assert_eq!(bytes(&r[0]), expected);
    assert_eq!((int(&r[1]), int(&r[2])), (256, 256));

    // sim.handleflag_greyscale: one byte per pixel, as getVisionSensorImg's option 1.
    let grey_handle = Value::Int(cam | 0x0040_0000);
    let grey = bytes(
        &call(
            &mut w,
            "sim.getVisionSensorCharImage",
            std::slice::from_ref(&grey_handle),
        )
        .expect("grey")[0],
    );
    let grey_img =
        bytes(&call(&mut w, "sim.getVisionSensorImg", &[Value::Int(cam), Value::Int(1)]).expect("grey img")[0]);
    assert_eq!(grey, grey_img);

    // Floats 0..1: RGB per pixel, the bytes divided by 255; packed as f32 with returnType 1.
    let r = call(&mut w, "sim.getVisionSensorImage", &portion).expect("float image");
    let Value::Array(f) = &r[0] else { panic!("table: {r:?}") };
    assert_eq!(f.len(), expected.len());
    for (v, &b) in f.iter().zip(&expected) {
        assert!((v.as_f64().expect("number") - f64::from(b) / 255.0).abs() < 1e-6);
    }
    let mut packed_args = portion.clone();
    packed_args.push(Value::Int(1));
    let packed = bytes(&call(&mut w, "sim.getVisionSensorImage", &packed_args).expect("packed")[0]);
    assert_eq!(packed.len(), 4 * expected.len());
    let g = call(&mut w, "sim.getVisionSensorImage", &[grey_handle]).expect("grey floats");
    let Value::Array(g) = &g[0] else { panic!("table") };
    assert_eq!(g.len(), 256 * 256);

    let e = call(
        &mut w,
        "sim.getVisionSensorCharImage",
        &[
            Value::Int(cam),
            Value::Int(250),
            Value::Int(0),
            Value::Int(10),
            Value::Int(1),
        ],
    )
    .expect_err("outside");
    assert!(
        e.contains("exceeds") && e.contains("sim.getVisionSensorCharImage"),
        "{e}"
    );
}

/// CoppeliaSim's synchronous image transmission example: the image read with
/// `getVisionSensorCharImage` from one sensor is written with `setVisionSensorCharImage`
/// into another, whose readers then get exactly those bytes (grey too, with the flag).
#[test]
fn set_vision_sensor_char_image_writes_what_readers_get() {
    let (mut w, _, _) = two_obstacles_ahead();
    let cam = find(&w, "/bubbleRob/visionSensor", 0);
    call(&mut w, "sim.handleVisionSensor", &[Value::Int(cam)]).expect("render");
    let img = bytes(&call(&mut w, "sim.getVisionSensorCharImage", &[Value::Int(cam)]).expect("get")[0]);
    assert!(img.iter().any(|&b| b != img[0]), "a rendered image, not a flat one");
    // Write it back inverted, so the check cannot pass by reading the render again.
    let inverted: Vec<u8> = img.iter().map(|b| 255 - b).collect();
    let r = call(
        &mut w,
        "sim.setVisionSensorCharImage",
        &[Value::Int(cam), Value::Bytes(inverted.clone())],
    )
    .expect("set");
    assert_eq!(r, vec![Value::Int(1)]);
    let back = bytes(&call(&mut w, "sim.getVisionSensorImg", &[Value::Int(cam)]).expect("img")[0]);
    assert_eq!(back, inverted);

    // Greyscale: one byte per pixel, copied to R, G and B.
    let grey: Vec<u8> = (0..256 * 256).map(|i| (i % 251) as u8).collect();
    let flagged = cam | 0x0040_0000;
    call(
        &mut w,
        "sim.setVisionSensorCharImage",
        &[Value::Int(flagged), Value::Bytes(grey.clone())],
    )
    .expect("grey");
    let rgb = bytes(&call(&mut w, "sim.getVisionSensorImg", &[Value::Int(cam)]).expect("img")[0]);
    assert!(rgb.chunks_exact(3).zip(&grey).all(|(px, &g)| px == [g, g, g]));

    // A short buffer is refused with the expected size.
    let e = call(
        &mut w,
        "sim.setVisionSensorCharImage",
        &[Value::Int(cam), Value::Bytes(vec![0; 10])],
    )
    .expect_err("short");
    assert!(
        e.contains("196608 bytes") && e.contains("sim.setVisionSensorCharImage"),
        "{e}"
    );
}

/// The pyramid, cylinder and disc volumes from a TOML scene: each sees a wall ahead
/// (behind, for the ring) at its distance, and `sim.proxintparam_volume_type` names it.
#[test]
fn pyramid_cylinder_and_disc_sensors_from_toml() {
    let text = r#"
[[object]]
name = "wall"
kind = "shape"
shape = "box"
size = [1.0, 1.0, 0.02]
position = [0.0, 0.0, 0.31]

[[object]]
name = "pyramid"
kind = "proximity_sensor"
sensor = "pyramid"
range = 0.5
size_near = [0.01, 0.01]
size_far = [0.2, 0.1]

[[object]]
name = "cylinder"
kind = "proximity_sensor"
sensor = "cylinder"
offset = 0.05
range = 0.5
radius = 0.02

[[object]]
name = "ring"
kind = "proximity_sensor"
sensor = "disc"
offset = 0.1
range = 0.4
thickness = 0.02
orientation_deg = [0.0, 180.0, 0.0]
"#;
    let path = std::path::Path::new("volumes.toml");
    let opts = gantry_sim_core::scene::LoadOptions::default();
    let mut w = util::text_scene("volumes.toml", text);
    for (name, volume_type) in [("/pyramid", 0), ("/cylinder", 1), ("/ring", 2)] {
        let h = find(&w, name, 0);
        let r = util::ok(&mut w, "sim.handleProximitySensor", &[Value::Int(h)]);
        assert_eq!(r[0], Value::Int(1), "{name} sees the wall: {r:?}");
        assert!((distance(&r) - 0.3).abs() < 1.0e-6, "{name}: {r:?}");
        let t = util::ok(&mut w, "sim.getObjectInt32Param", &[Value::Int(h), Value::Int(4001)]);
        assert_eq!(t, vec![Value::Int(volume_type)], "{name}");
    }

    // Each volume's own parameters are checked, with the object named.
    for (bad, says) in [
        ("sensor = \"pyramid\"", "needs size_far"),
        ("sensor = \"cylinder\"\nradius = 0.0", "radius and radius_far"),
        ("sensor = \"disc\"\nangle_deg = 400.0", "angle_deg in (0, 360]"),
        ("sensor = \"prism\"", "use ray, cone, pyramid, cylinder or disc"),
    ] {
        let text = format!("[[object]]\nname = \"s\"\nkind = \"proximity_sensor\"\n{bad}\n");
        let e = gantry_sim_core::scene::load_scene_text(&gantry_sim_core::scene::DiskFiles, &text, path, &opts)
            .expect_err(bad)
            .to_string();
        assert!(e.contains(says), "{bad}: {e}");
    }
}
