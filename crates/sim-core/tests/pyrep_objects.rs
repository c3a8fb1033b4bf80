//! What PyRep asks of the scene besides poses: configuration trees, objects created at
//! run time (vision, force and proximity sensors, joints), joint intervals, double
//! signals, engine parameters and a few object queries, through the `sim.*` registry with
//! CoppeliaSim 4.1's argument forms.

use crate::util;

use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene};
use gantry_sim_core::{Sim, Value};
use gantry_test_support::{assert_contains, floats, int, num};
use util::{err, find, ok, step};

/// A floor, a dynamic cube that falls and tumbles, and a kinematic hinge on a stand with
/// a dynamic link.
const SCENE: &str = r#"
[simulation]
dt = 0.05
substeps = 10

[floor]

[[object]]
name = "cube"
kind = "shape"
shape = "box"
size = [0.1, 0.1, 0.1]
position = [0.3, 0.2, 0.6]
orientation_deg = [20, 10, 0]
dynamic = true
mass = 0.5

[[object]]
name = "stand"
kind = "shape"
shape = "box"
size = [0.2, 0.2, 0.2]
position = [-1, 0, 0.1]

[[object]]
name = "hinge"
kind = "joint"
joint = "revolute"
parent = "stand"
position = [0, 0, 0.2]
mode = "kinematic"
limits = [-90, 90]

[[object]]
name = "link"
kind = "shape"
shape = "box"
size = [0.3, 0.05, 0.05]
parent = "hinge"
position = [0.3, 0, 0.1]
"#;

fn sim() -> Sim {
    util::text_scene("tests/pyrep_objects.toml", SCENE)
}

fn h(v: i64) -> Value {
    Value::Int(v)
}

fn position(s: &mut Sim, handle: i64) -> Vec<f64> {
    floats(&ok(s, "getObjectPosition", &[h(handle), h(-1)])[0])
}

fn bytes(v: &Value) -> Vec<u8> {
    match v {
        Value::Bytes(b) => b.clone(),
        other => panic!("expected bytes, got {other:?}"),
    }
}

#[test]
fn configuration_tree_puts_a_fallen_cube_back_at_rest() {
    let mut s = sim();
    let cube = find(&s, "/cube");
    let before = position(&mut s, cube);
    let tree = ok(&mut s, "getConfigurationTree", &[h(cube)]);
    step(&mut s, 10);
    let moved = position(&mut s, cube);
    assert!((moved[2] - before[2]).abs() > 0.05, "the cube fell: {moved:?}");
    ok(&mut s, "setConfigurationTree", &tree);
    let after = position(&mut s, cube);
    gantry_test_support::assert_close(&after, &before, 1e-9);
    // Dynamics restarted at rest: no velocity carried over from the fall.
    let v = ok(&mut s, "getObjectVelocity", &[h(cube)]);
    assert!(floats(&v[0]).iter().all(|x| x.abs() < 1e-9), "{v:?}");
    // And it falls again from there, as a reset task does.
    step(&mut s, 2);
    assert!(position(&mut s, cube)[2] < before[2]);
}

#[test]
fn configuration_tree_of_the_scene_restores_joints_and_what_hangs_from_them() {
    let mut s = sim();
    let (hinge, link, cube) = (
        find(&s, "/stand/hinge"),
        find(&s, "/stand/hinge/link"),
        find(&s, "/cube"),
    );
    let link_before = position(&mut s, link);
    let tree = ok(&mut s, "getConfigurationTree", &[h(-12)]);
    ok(&mut s, "setJointPosition", &[h(hinge), Value::Float(1.0)]);
    ok(
        &mut s,
        "setObjectPosition",
        &[h(cube), h(-1), Value::floats(&[2.0, 2.0, 2.0])],
    );
    assert!((position(&mut s, link)[0] - link_before[0]).abs() > 0.1);
    ok(&mut s, "setConfigurationTree", &tree);
    assert_eq!(num(&ok(&mut s, "getJointPosition", &[h(hinge)])[0]), 0.0);
    gantry_test_support::assert_close(&position(&mut s, link), &link_before, 1e-9);
    gantry_test_support::assert_close(&position(&mut s, cube), &[0.3, 0.2, 0.6], 1e-9);
}

#[test]
fn configuration_tree_refuses_foreign_or_damaged_bytes_and_changes_nothing() {
    let mut s = sim();
    let cube = find(&s, "/cube");
    let tree = bytes(&ok(&mut s, "getConfigurationTree", &[h(cube)])[0]);
    ok(
        &mut s,
        "setObjectPosition",
        &[h(cube), h(-1), Value::floats(&[1.0, 1.0, 1.0])],
    );
    let mut flipped = tree.clone();
    flipped[20] ^= 1;
    for bad in [
        Vec::new(),
        b"not a tree at all, just text".to_vec(),
        tree[..tree.len() - 3].to_vec(),
        flipped,
    ] {
        let e = err(&mut s, "setConfigurationTree", &[Value::Bytes(bad)]);
        assert_contains(&e, &["not a configuration tree", "sim.setConfigurationTree"]);
    }
    assert_eq!(position(&mut s, cube), vec![1.0, 1.0, 1.0]);
    // A tree naming an object removed since is refused too.
    let link = find(&s, "/stand/hinge/link");
    let link_tree = ok(&mut s, "getConfigurationTree", &[h(link)]);
    ok(&mut s, "removeObjects", &[Value::Array(vec![h(link)])]);
    let e = err(&mut s, "setConfigurationTree", &link_tree);
    assert_contains(&e, &[&format!("object {link} does not exist")]);
    assert_contains(err(&mut s, "getConfigurationTree", &[h(999)]), &["999"]);
}

/// `sim.createVisionSensor`'s arguments as PyRep's `VisionSensor.create` passes them.
fn vision_args(options: i64, res: [i64; 2], near: f64, far: f64, angle: f64) -> Vec<Value> {
    vec![
        h(options),
        Value::Array(vec![h(res[0]), h(res[1]), h(0), h(0)]),
        Value::floats(&[near, far, angle, 0.01, 0.01, 0.03, 0.0, 0.0, 0.0, 0.0, 0.0]),
        Value::Nil,
    ]
}

/// Points a sensor (which looks along its +Z) straight down from `at`.
fn look_down(s: &mut Sim, sensor: i64, at: [f64; 3]) {
    ok(s, "setObjectPosition", &[h(sensor), h(-1), Value::floats(&at)]);
    ok(
        s,
        "setObjectOrientation",
        &[h(sensor), h(-1), Value::floats(&[std::f64::consts::PI, 0.0, 0.0])],
    );
}

fn rgb_sum(s: &mut Sim, sensor: i64) -> (u64, usize) {
    let (img, [w, hgt]) = util::image_reply(&ok(s, "getVisionSensorImg", &[h(sensor)]));
    assert_eq!(img.len(), 3 * w * hgt);
    (img.iter().map(|&b| u64::from(b)).sum(), w * hgt)
}

#[test]
fn created_vision_sensor_has_its_settings_and_renders() {
    let mut s = sim();
    let angle = 35f64.to_radians();
    let cam = int(&ok(
        &mut s,
        "createVisionSensor",
        &vision_args(2, [64, 48], 0.25, 5.0, angle),
    )[0]);
    assert_eq!(int(&ok(&mut s, "getObjectType", &[h(cam)])[0]), 9);
    let param = |s: &mut Sim, p: i64, f: &str| num(&ok(s, f, &[h(cam), h(p)])[0]);
    assert_eq!(param(&mut s, 1002, "getObjectInt32Param"), 64.0);
    assert_eq!(param(&mut s, 1003, "getObjectInt32Param"), 48.0);
    assert_eq!(param(&mut s, 1018, "getObjectInt32Param"), 1.0, "perspective");
    assert_eq!(param(&mut s, 1000, "getObjectFloatParam"), 0.25);
    assert_eq!(param(&mut s, 1001, "getObjectFloatParam"), 5.0);
    assert!((param(&mut s, 1004, "getObjectFloatParam") - angle).abs() < 1e-12);
    look_down(&mut s, cam, [0.3, 0.2, 2.0]);
    let (sum, pixels) = rgb_sum(&mut s, cam);
    assert_eq!(pixels, 64 * 48);
    assert_eq!(sum, 0, "blank until handled or stepped, as CoppeliaSim's new sensor");
    s.step();
    let (sum, _) = rgb_sum(&mut s, cam);
    assert!(sum > 0, "the sensor sees the floor and the cube");
    // Orthographic: the third float is the ortho size.
    let ortho = int(&ok(&mut s, "createVisionSensor", &vision_args(0, [16, 16], 0.01, 3.0, 0.7))[0]);
    assert_eq!(num(&ok(&mut s, "getObjectInt32Param", &[h(ortho), h(1018)])[0]), 0.0);
    assert_eq!(num(&ok(&mut s, "getObjectFloatParam", &[h(ortho), h(1005)])[0]), 0.7);
}

#[test]
fn created_explicit_vision_sensor_renders_only_when_handled() {
    let mut s = sim();
    let cam = int(&ok(
        &mut s,
        "createVisionSensor",
        &vision_args(1 | 2, [32, 32], 0.01, 5.0, 1.0),
    )[0]);
    assert_eq!(int(&ok(&mut s, "getExplicitHandling", &[h(cam)])[0]), 1);
    look_down(&mut s, cam, [0.3, 0.2, 2.0]);
    assert_eq!(rgb_sum(&mut s, cam).0, 0, "not handled yet: black");
    ok(&mut s, "handleVisionSensor", &[h(cam)]);
    assert!(rgb_sum(&mut s, cam).0 > 0);
    // PyRep's set_explicit_handling(0): back to rendering when read.
    ok(&mut s, "setExplicitHandling", &[h(cam), h(0)]);
    assert_eq!(int(&ok(&mut s, "getExplicitHandling", &[h(cam)])[0]), 0);
}

#[test]
fn create_vision_sensor_refuses_what_it_cannot_do() {
    let mut s = sim();
    let n = s.world.handles().len();
    let cases: Vec<(Vec<Value>, &[&str])> = vec![
        (vision_args(2, [0, 16], 0.01, 1.0, 1.0), &["resolution 0"]),
        (vision_args(2, [16, 16], 1.0, 0.5, 1.0), &["0 < near < far"]),
        (vision_args(2, [16, 16], 0.01, 1.0, 4.0), &["view angle"]),
        (vision_args(2 | 16, [16, 16], 0.01, 1.0, 1.0), &["passive"]),
        (
            vec![
                h(2),
                Value::Array(vec![h(16)]),
                Value::floats(&[0.01, 1.0, 1.0]),
                Value::Nil,
            ],
            &["at least 2 numbers"],
        ),
    ];
    for (args, parts) in cases {
        let e = err(&mut s, "createVisionSensor", &args);
        assert_contains(&e, parts);
        assert_contains(&e, &["sim.createVisionSensor"]);
    }
    let mut coloured = vision_args(2 | 128, [16, 16], 0.01, 1.0, 1.0);
    coloured[2] = Value::floats(&[0.01, 1.0, 1.0, 0.01, 0.01, 0.01, 0.5, 1.5, 0.5, 0.0, 0.0]);
    assert_contains(
        err(&mut s, "createVisionSensor", &coloured),
        &["null-pixel colour", "0 to 1"],
    );
    coloured[2] = Value::floats(&[0.01, 1.0, 1.0, 0.01, 0.01, 0.01, 0.5]);
    assert_contains(
        err(&mut s, "createVisionSensor", &coloured),
        &["option bit 7", "null-pixel colour"],
    );
    assert_eq!(s.world.handles().len(), n, "nothing created");
}

/// The distinct RGB pixels of a created sensor at `at` looking straight up, into
/// nothing (the scenes have nothing above 1 m).
fn sky_pixels(s: &mut Sim, options: i64, null_colour: [f64; 3]) -> Vec<[u8; 3]> {
    let mut args = vision_args(options, [8, 6], 0.01, 5.0, 1.0);
    args[2] = Value::floats(&[
        0.01,
        5.0,
        1.0,
        0.01,
        0.01,
        0.03,
        null_colour[0],
        null_colour[1],
        null_colour[2],
        0.0,
        0.0,
    ]);
    let cam = int(&ok(s, "createVisionSensor", &args)[0]);
    ok(
        s,
        "setObjectPosition",
        &[h(cam), h(-1), Value::floats(&[0.0, 0.0, 3.0])],
    );
    ok(s, "handleVisionSensor", &[h(cam)]);
    let (img, _) = util::image_reply(&ok(s, "getVisionSensorImg", &[h(cam)]));
    let mut distinct: Vec<[u8; 3]> = img.chunks(3).map(|p| [p[0], p[1], p[2]]).collect();
    distinct.sort_unstable();
    distinct.dedup();
    distinct
}

#[test]
fn created_vision_sensors_show_the_background_where_they_see_nothing() {
    // A scene without a background: black, unless the sensor asks for a colour (bit 7).
    let mut s = sim();
    assert_eq!(
        sky_pixels(&mut s, 2, [0.2, 0.4, 0.6]),
        [[0, 0, 0]],
        "bit 7 unset: colour ignored"
    );
    assert_eq!(sky_pixels(&mut s, 2 | 128, [0.2, 0.4, 0.6]), [[51, 102, 153]]);
    // A scene with one: its colour, unless the sensor asks for its own (black included).
    let mut s = util::text_scene(
        "tests/pyrep_objects.toml",
        &SCENE.replace("substeps = 10\n", "substeps = 10\nbackground = [1, 0.8, 0.2]\n"),
    );
    assert_eq!(s.world.settings().background, Some([1.0, 0.8, 0.2]));
    assert_eq!(sky_pixels(&mut s, 2, [0.0; 3]), [[255, 204, 51]]);
    assert_eq!(sky_pixels(&mut s, 2 | 128, [0.0; 3]), [[0, 0, 0]]);
    assert_eq!(sky_pixels(&mut s, 2 | 128, [0.2, 0.4, 0.6]), [[51, 102, 153]]);
}

#[test]
fn created_force_sensor_weighs_what_hangs_from_it() {
    let mut s = sim();
    let cube = find(&s, "/cube");
    // PyRep's ForceSensor.create: options 0, five zero ints, the size then zeros.
    let args = [
        h(0),
        Value::Array(vec![h(0); 5]),
        Value::floats(&[0.01, 0.0, 0.0, 0.0, 0.0]),
        Value::Nil,
    ];
    let fs = int(&ok(&mut s, "createForceSensor", &args)[0]);
    assert_eq!(int(&ok(&mut s, "getObjectType", &[h(fs)])[0]), 12);
    ok(
        &mut s,
        "setObjectPosition",
        &[h(fs), h(-1), Value::floats(&[0.3, 0.2, 0.8])],
    );
    ok(&mut s, "setObjectParent", &[h(cube), h(fs), Value::Bool(true)]);
    step(&mut s, 20);
    let r = ok(&mut s, "readForceSensor", &[h(fs)]);
    assert_eq!(int(&r[0]) & 1, 1, "a reading: {r:?}");
    let f = floats(&r[1]);
    let magnitude = f.iter().map(|v| v * v).sum::<f64>().sqrt();
    assert!((magnitude - 0.5 * 9.81).abs() < 0.1, "{f:?}");
    ok(&mut s, "removeObjects", &[Value::Array(vec![h(fs)])]);
    // Thresholds and filters gantry does not have are refused.
    let mut thresholds = args.clone();
    thresholds[0] = h(1);
    assert_contains(
        err(&mut s, "createForceSensor", &thresholds),
        &["thresholds", "never break"],
    );
    let mut filtered = args.clone();
    filtered[1] = Value::Array(vec![h(0), h(5), h(0), h(0), h(0)]);
    assert_contains(err(&mut s, "createForceSensor", &filtered), &["5 samples"]);
    assert_contains(err(&mut s, "createForceSensor", &[h(0)]), &["argument 2"]);
}

#[test]
fn joint_interval_set_reads_back_and_clamps_the_position() {
    let mut s = sim();
    let hinge = find(&s, "/stand/hinge");
    ok(&mut s, "setJointPosition", &[h(hinge), Value::Float(1.0)]);
    // PyRep's test: not cyclic, min -2, range 2.
    ok(
        &mut s,
        "setJointInterval",
        &[h(hinge), Value::Bool(false), Value::floats(&[-2.0, 2.0])],
    );
    let r = ok(&mut s, "getJointInterval", &[h(hinge)]);
    assert_eq!(r[0], Value::Bool(false));
    assert_eq!(floats(&r[1]), vec![-2.0, 2.0]);
    assert_eq!(
        num(&ok(&mut s, "getJointPosition", &[h(hinge)])[0]),
        0.0,
        "clamped to the new max"
    );
    ok(&mut s, "setJointPosition", &[h(hinge), Value::Float(-3.0)]);
    assert_eq!(num(&ok(&mut s, "getJointPosition", &[h(hinge)])[0]), -2.0);
    // Cyclic: no limits, positions wrap.
    ok(
        &mut s,
        "setJointInterval",
        &[h(hinge), Value::Bool(true), Value::floats(&[0.0, 0.0])],
    );
    let r = ok(&mut s, "getJointInterval", &[h(hinge)]);
    assert_eq!(r[0], Value::Bool(true));
    ok(&mut s, "setJointPosition", &[h(hinge), Value::Float(4.0)]);
    let q = num(&ok(&mut s, "getJointPosition", &[h(hinge)])[0]);
    assert!((q - (4.0 - 2.0 * std::f64::consts::PI)).abs() < 1e-12, "{q}");
    let cube = find(&s, "/cube");
    assert_contains(
        err(
            &mut s,
            "setJointInterval",
            &[h(cube), Value::Bool(false), Value::floats(&[0.0, 1.0])],
        ),
        &["joint"],
    );
    assert_contains(
        err(
            &mut s,
            "setJointInterval",
            &[h(hinge), Value::Bool(false), Value::floats(&[0.0, -1.0])],
        ),
        &["range >= 0"],
    );
}

#[test]
fn double_signals_have_their_own_names() {
    let mut s = sim();
    let name = || Value::Str("my_signal".into());
    assert_eq!(ok(&mut s, "getDoubleSignal", &[name()])[0], Value::Nil);
    ok(&mut s, "setDoubleSignal", &[name(), Value::Float(22.2)]);
    assert_eq!(num(&ok(&mut s, "getDoubleSignal", &[name()])[0]), 22.2);
    // Apart from the float signal of the same name, as in CoppeliaSim 4.1.
    assert_eq!(ok(&mut s, "getFloatSignal", &[name()])[0], Value::Nil);
    ok(&mut s, "clearDoubleSignal", &[name()]);
    assert_eq!(ok(&mut s, "getDoubleSignal", &[name()])[0], Value::Nil);
    assert_contains(
        err(&mut s, "setDoubleSignal", &[name(), Value::Str("x".into())]),
        &["argument 2"],
    );
}

#[test]
fn engine_friction_and_restitution_reach_the_shape() {
    let mut s = sim();
    let cube = find(&s, "/cube");
    const BULLET_FRICTION: i64 = 6003;
    // PyRep's set_bullet_friction / get_bullet_friction, by their 4.1 names.
    ok(
        &mut s,
        "setEngineFloatParameter",
        &[h(BULLET_FRICTION), h(cube), Value::Float(0.7)],
    );
    assert_eq!(
        num(&ok(&mut s, "getEngineFloatParameter", &[h(BULLET_FRICTION), h(cube)])[0]),
        0.7
    );
    // One coefficient whatever the engine's name for it.
    assert_eq!(num(&ok(&mut s, "getEngineFloatParam", &[h(15001), h(cube)])[0]), 0.7);
    ok(&mut s, "setEngineFloatParam", &[h(6001), h(cube), Value::Float(0.25)]);
    assert_eq!(num(&ok(&mut s, "getEngineFloatParam", &[h(33003), h(cube)])[0]), 0.25);
    assert_eq!(s.world.shape(cube).unwrap().friction, 0.7);
    assert_contains(
        err(&mut s, "getEngineFloatParam", &[h(6004), h(cube)]),
        &["6004", "not one gantry's physics has"],
    );
    assert_contains(
        err(&mut s, "setEngineFloatParam", &[h(6003), h(cube), Value::Float(-1.0)]),
        &["friction"],
    );
    let hinge = find(&s, "/stand/hinge");
    assert_contains(err(&mut s, "getEngineFloatParam", &[h(6003), h(hinge)]), &["shape"]);
}

#[test]
fn model_bounding_box_spans_the_object_and_what_hangs_below() {
    let mut s = sim();
    let stand = find(&s, "/stand");
    let bb: Vec<f64> = (21..=26)
        .map(|p| num(&ok(&mut s, "getObjectFloatParam", &[h(stand), h(p)])[0]))
        .collect();
    // The stand's 0.2 m cube around its origin, and the link (0.3 x 0.05 x 0.05, its
    // centre at x 0.3, z 0.3 in the stand's frame) on the hinge above it.
    gantry_test_support::assert_close(&bb, &[-0.1, -0.1, -0.1, 0.45, 0.1, 0.325], 1e-9);
}

/// The scene above with a script on the stand and the stand flagged as a model base,
/// in a folder of its own (the script is a file beside the scene).
fn scene_on_disk(dir: &gantry_test_support::TempDir) -> Sim {
    dir.write("stand.lua", "function sysCall_init() end\n");
    let text = SCENE.replace(
        "name = \"stand\"\nkind = \"shape\"",
        "name = \"stand\"\nkind = \"shape\"\nmodel_base = true\nscript = \"stand.lua\"",
    );
    let path = dir.write("scene.toml", text);
    let model = load_scene(&DiskFiles, &path, &LoadOptions::default()).expect("scene loads");
    assert_eq!(model.scripts.len(), 1);
    Sim::new(&model)
}

fn load_back(path: &std::path::Path) -> gantry_sim_core::scene::SceneModel {
    load_scene(&DiskFiles, path, &LoadOptions::default()).unwrap_or_else(|e| {
        panic!(
            "{}: {e}\n{}",
            path.display(),
            std::fs::read_to_string(path).unwrap_or_default()
        )
    })
}

#[test]
fn saved_scene_loads_back_as_the_scene_was_when_saved() {
    let dir = gantry_test_support::TempDir::new("pyrep_save_scene");
    let mut s = scene_on_disk(&dir);
    let (cube, hinge) = (find(&s, "/cube"), find(&s, "/stand/hinge"));
    step(&mut s, 5);
    ok(&mut s, "setJointPosition", &[h(hinge), Value::Float(0.5)]);
    ok(&mut s, "setEngineFloatParam", &[h(6003), h(cube), Value::Float(0.9)]);
    let fs = int(&ok(
        &mut s,
        "createForceSensor",
        &[h(0), Value::Array(vec![h(0); 5]), Value::floats(&[0.01]), Value::Nil],
    )[0]);
    let out = dir.path().join("saved/again.toml");
    ok(&mut s, "saveScene", &[Value::Str(out.to_string_lossy().into())]);
    let back = load_back(&out);
    let live: Vec<i64> = s.world.handles().to_vec();
    assert_eq!(back.objects.len(), live.len());
    for (o, &handle) in back.objects.iter().zip(&live) {
        let now = s.world.object(handle).expect("live");
        assert_eq!(o.alias, now.alias);
        assert_eq!(o.parent.map(|p| live[p]), now.parent, "{}", o.alias);
        let (a, b) = (o.local.translation.vector, now.local.translation.vector);
        assert!((a - b).norm() < 1e-12, "{}: {a:?} vs {b:?}", o.alias);
        assert!(o.local.rotation.angle_to(&now.local.rotation) < 1e-9, "{}", o.alias);
        assert_eq!(o.model_base, now.model_base);
    }
    // Joint positions, object settings and the script come back.
    let hinge_model = &back.objects[hinge as usize];
    match &hinge_model.kind {
        gantry_sim_core::scene::ObjectModelKind::Joint(j) => assert!((j.initial - 0.5).abs() < 1e-12),
        other => panic!("{other:?}"),
    }
    match &back.objects[cube as usize].kind {
        gantry_sim_core::scene::ObjectModelKind::Shape(sh) => assert_eq!(sh.friction, 0.9),
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        back.objects[fs as usize].kind,
        gantry_sim_core::scene::ObjectModelKind::ForceSensor
    ));
    assert_eq!(back.scripts.len(), 1);
    assert_eq!(back.scripts[0].object, find(&s, "/stand") as usize);
    assert_eq!(back.scripts[0].source, "function sysCall_init() end\n");
    // The scene it saved runs.
    let mut again = Sim::new(&back);
    step(&mut again, 2);
    let leftovers: Vec<_> = std::fs::read_dir(dir.path().join("saved"))
        .expect("folder")
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("gantry-tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

#[test]
fn saved_model_holds_its_subtree_where_it_stands() {
    let dir = gantry_test_support::TempDir::new("pyrep_save_model");
    let mut s = scene_on_disk(&dir);
    let stand = find(&s, "/stand");
    ok(
        &mut s,
        "setObjectPosition",
        &[h(stand), h(-1), Value::floats(&[2.0, 1.0, 0.1])],
    );
    let out = dir.path().join("stand_model.toml");
    ok(
        &mut s,
        "saveModel",
        &[h(stand), Value::Str(out.to_string_lossy().into())],
    );
    let back = load_back(&out);
    let aliases: Vec<&str> = back.objects.iter().map(|o| o.alias.as_str()).collect();
    assert_eq!(aliases, ["stand", "hinge", "link"]);
    assert_eq!(back.objects[0].parent, None);
    assert_eq!(back.objects[0].local.translation.vector.as_slice(), &[2.0, 1.0, 0.1]);
    assert_eq!(back.scripts.len(), 1);
    assert_eq!(back.scripts[0].object, 0);
    // Not a model base: refused.
    let cube = find(&s, "/cube");
    assert_contains(
        err(
            &mut s,
            "saveModel",
            &[h(cube), Value::Str(out.to_string_lossy().into())],
        ),
        &["not a model base"],
    );
}

#[test]
fn save_refuses_coppelia_formats_and_leaves_them_alone() {
    let dir = gantry_test_support::TempDir::new("pyrep_save_ttt");
    let mut s = scene_on_disk(&dir);
    let ttt = dir.write("scene.ttt", b"CoppeliaSim's bytes");
    let e = err(&mut s, "saveScene", &[Value::Str(ttt.to_string_lossy().into())]);
    assert_contains(&e, &["TOML", "never in CoppeliaSim's formats", "sim.saveScene"]);
    assert_eq!(std::fs::read(&ttt).expect("still there"), b"CoppeliaSim's bytes");
    let stand = find(&s, "/stand");
    let ttm = dir.path().join("stand.ttm");
    assert_contains(
        err(
            &mut s,
            "saveModel",
            &[h(stand), Value::Str(ttm.to_string_lossy().into())],
        ),
        &["TOML"],
    );
    assert!(!ttm.exists());
    assert_contains(
        err(&mut s, "saveScene", &[Value::Str("scene.txt".into())]),
        &["'.toml'"],
    );
}

#[test]
fn object_uids_are_unique_across_scenes_and_read_as_a_string_param() {
    let mut s = sim();
    let cube = find(&s, "/cube");
    let uid = int(&ok(&mut s, "getObjectUid", &[h(cube)])[0]);
    assert_eq!(int(&ok(&mut s, "getObjectUid", &[h(cube)])[0]), uid, "stable");
    let stand = find(&s, "/stand");
    assert_ne!(int(&ok(&mut s, "getObjectUid", &[h(stand)])[0]), uid);
    // A scene loaded later gives the same handle out again, not the same uid.
    let mut other = sim();
    assert_eq!(find(&other, "/cube"), cube);
    assert_ne!(int(&ok(&mut other, "getObjectUid", &[h(cube)])[0]), uid);
    // 4.1's name too.
    let text = ok(&mut s, "getObjectStringParameter", &[h(cube), h(35)]);
    assert_eq!(text[0], Value::Str(uid.to_string()));
    assert_contains(
        err(&mut s, "getObjectStringParam", &[h(cube), h(33)]),
        &["33", "unique_id"],
    );
    assert_contains(err(&mut s, "getObjectUid", &[h(999)]), &["999"]);
}

/// A pendulum: a free (motorless) hinge on a static post, its link sideways so that
/// gravity swings it.
const PENDULUM: &str = r#"
[simulation]
dt = 0.05
substeps = 10

[[object]]
name = "post"
kind = "shape"
shape = "box"
size = [0.05, 0.05, 0.05]
position = [0, 0, 1]

[[object]]
name = "hinge"
kind = "joint"
joint = "revolute"
parent = "post"
orientation_deg = [90, 0, 0]
mode = "free"

[[object]]
name = "bob"
kind = "shape"
shape = "box"
size = [0.3, 0.05, 0.05]
parent = "hinge"
position = [0.2, 0, 0]
dynamic = true
mass = 1.0
"#;

#[test]
fn configuration_tree_restores_a_simulated_joint_that_swung() {
    let mut s = util::text_scene("tests/pendulum.toml", PENDULUM);
    let (hinge, bob) = (find(&s, "/post/hinge"), find(&s, "/post/hinge/bob"));
    let bob_before = position(&mut s, bob);
    let tree = ok(&mut s, "getConfigurationTree", &[h(-12)]);
    step(&mut s, 10);
    let swung = num(&ok(&mut s, "getJointPosition", &[h(hinge)])[0]);
    assert!(swung.abs() > 0.2, "the pendulum swung: {swung}");
    ok(&mut s, "setConfigurationTree", &tree);
    assert_eq!(num(&ok(&mut s, "getJointPosition", &[h(hinge)])[0]), 0.0);
    gantry_test_support::assert_close(&position(&mut s, bob), &bob_before, 1e-9);
    // It starts again from rest there: its next step is a fresh pendulum's first.
    step(&mut s, 1);
    let q = num(&ok(&mut s, "getJointPosition", &[h(hinge)])[0]);
    let mut fresh = util::text_scene("tests/pendulum.toml", PENDULUM);
    step(&mut fresh, 1);
    let q_fresh = num(&ok(&mut fresh, "getJointPosition", &[h(hinge)])[0]);
    assert!(q_fresh.abs() > 0.01, "the pendulum starts falling: {q_fresh}");
    assert!(
        (q - q_fresh).abs() < 1e-3,
        "restarted from rest: {q} vs a fresh pendulum's {q_fresh}"
    );
}

#[test]
fn joint_interval_limits_a_simulated_joint_at_once() {
    let mut s = util::text_scene("tests/pendulum.toml", PENDULUM);
    let hinge = find(&s, "/post/hinge");
    step(&mut s, 2);
    let falling = num(&ok(&mut s, "getJointPosition", &[h(hinge)])[0]);
    // Limits on the side it falls to, ending just past where it is.
    let (lo, hi) = if falling < 0.0 {
        (falling - 0.05, -falling)
    } else {
        (-falling, falling + 0.05)
    };
    ok(
        &mut s,
        "setJointInterval",
        &[h(hinge), Value::Bool(false), Value::floats(&[lo, hi - lo])],
    );
    step(&mut s, 20);
    let q = num(&ok(&mut s, "getJointPosition", &[h(hinge)])[0]);
    assert!(q >= lo - 0.02 && q <= hi + 0.02, "held in [{lo}, {hi}]: {q}");
}

/// PyRep's `test_vision_sensors.py::test_handle_explicitly` on its `test_scene.ttt`
/// (after the ten steps of its `setUp`): a new 640 x 480 sensor at the origin reads
/// blank, then, explicitly handled, sees something (the Panda's base it sits in).
#[test]
fn pyrep_handle_explicitly_reads_blank_then_an_image() {
    let path = gantry_test_support::pyrep_assets().join("test_scene.ttt");
    let model = gantry_sim_core::scene::load_coppelia_file(&gantry_sim_core::scene::DiskFiles, &path)
        .expect("test_scene.ttt imports");
    assert_eq!(model.settings.background, Some([0.0; 3]), "the scene's fog colour");
    let mut s = Sim::new(&model);
    for _ in 0..10 {
        s.step();
    }
    let cam = int(&ok(
        &mut s,
        "createVisionSensor",
        &vision_args(2, [640, 480], 0.01, 10.0, 60f64.to_radians()),
    )[0]);
    assert_eq!(rgb_sum(&mut s, cam).0, 0, "blank image");
    ok(&mut s, "setExplicitHandling", &[h(cam), h(1)]);
    ok(&mut s, "handleVisionSensor", &[h(cam)]);
    assert_ne!(rgb_sum(&mut s, cam).0, 0, "non-blank image");
}
