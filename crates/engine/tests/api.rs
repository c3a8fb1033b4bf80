//! Lua snippets against each `sim.*` function of issue 3, with exact expectations and
//! the error cases, plus parity between Lua and remote calls through `Engine::call`.

use crate::util;
use util::Drive;

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use gantry_lua::ScriptLimits;
use gantry_sim_core::Value;
use gantry_test_support::{assert_close, assert_contains, floats, int, ints, num, text};
use util::{LUA_ERR, Scene, world_position};

/// A probe script that also defines `err(f, ...)`, `lua_call(name, ...)` (calls
/// `sim[name]`) and `lua_err(name, ...)` (the error message of that call).
fn probe(body: &str) -> String {
    format!(
        "{body}\n{LUA_ERR}\nfunction lua_call(name, ...) return sim[name](...) end\n\
         function lua_err(name, ...) return err(sim[name], ...) end\n"
    )
}

fn s(v: &str) -> Value {
    Value::Str(v.to_owned())
}

fn i(v: i64) -> Value {
    Value::Int(v)
}

fn f(v: f64) -> Value {
    Value::Float(v)
}

fn arr(v: &[f64]) -> Value {
    Value::floats(v)
}

/// Two dummies: `frame` at (1, 2, 3) turned 90° about Z, `child` 1 m along its X.
const POSES: &str = r#"
[[object]]
name = "frame"
kind = "dummy"
position = [1, 2, 3]
orientation_deg = [0, 0, 90]
script = "probe.lua"

[[object]]
name = "child"
kind = "dummy"
parent = "frame"
position = [1, 0, 0]

[[object]]
name = "free"
kind = "dummy"
"#;

fn poses(tag: &str, body: &str) -> Scene {
    let mut sc = Scene::new(tag, POSES, &[("probe.lua", &probe(body))], ScriptLimits::default());
    sc.sim.start();
    sc
}

/// Kinematic joints: limited revolute with a tip 1 m out, cyclic, prismatic, unlimited.
const JOINTS: &str = r#"
[[object]]
name = "base"
kind = "dummy"
script = "probe.lua"

[[object]]
name = "limited"
kind = "joint"
joint = "revolute"
parent = "base"
limits = [-90, 45]

[[object]]
name = "tip"
kind = "dummy"
parent = "limited"
position = [1, 0, 0]

[[object]]
name = "cyclic"
kind = "joint"
joint = "revolute"
cyclic = true
parent = "base"

[[object]]
name = "slider"
kind = "joint"
joint = "prismatic"
limits = [0, 0.2]
parent = "base"

[[object]]
name = "free"
kind = "joint"
joint = "revolute"
parent = "base"
"#;

fn joints(tag: &str, body: &str) -> Scene {
    let mut sc = Scene::new(tag, JOINTS, &[("probe.lua", &probe(body))], ScriptLimits::default());
    sc.sim.start();
    sc
}

/// Static proximity sensors at (0, 0, 0.1) looking along world +X (their local +Z), a
/// box whose near face is at x = 0.45 and a small ball off the axis.
const SENSORS: &str = r#"
[[object]]
name = "ray"
kind = "proximity_sensor"
sensor = "ray"
position = [0, 0, 0.1]
orientation_deg = [0, 90, 0]
range = 1.0
script = "probe.lua"

[[object]]
name = "cone"
kind = "proximity_sensor"
sensor = "cone"
position = [0, 0, 0.1]
orientation_deg = [0, 90, 0]
range = 1.0
angle_deg = 60

[[object]]
name = "shortRay"
kind = "proximity_sensor"
sensor = "ray"
position = [0, 0, 0.1]
orientation_deg = [0, 90, 0]
range = 0.4

[[object]]
name = "offsetRay"
kind = "proximity_sensor"
sensor = "ray"
position = [0, 0, 0.1]
orientation_deg = [0, 90, 0]
range = 1.0
offset = 0.6

[[object]]
name = "wall"
kind = "shape"
shape = "box"
size = [0.1, 0.4, 0.2]
position = [0.5, 0, 0.1]

[[object]]
name = "ball"
kind = "shape"
shape = "sphere"
radius = 0.02
position = [0.3, 0.1, 0.1]
"#;

fn sensors(tag: &str, body: &str) -> Scene {
    let mut sc = Scene::new(tag, SENSORS, &[("probe.lua", &probe(body))], ScriptLimits::default());
    sc.sim.start();
    sc
}

/// Static spheres of radius 0.1 at z = 0.5 on the X axis: probe `p1` at x = -0.5, the
/// chain `a` (x = 3) > `b` (x = 2) > `c` (x = 1), probe `p2` at x = 4.5, and a touching
/// pair far away along Y.
const COLLECTIONS: &str = r#"
[[object]]
name = "holder"
kind = "dummy"
script = "probe.lua"

[[object]]
name = "p1"
kind = "shape"
shape = "sphere"
radius = 0.1
position = [-0.5, 0, 0.5]

[[object]]
name = "a"
kind = "shape"
shape = "sphere"
radius = 0.1
position = [3, 0, 0.5]

[[object]]
name = "b"
kind = "shape"
shape = "sphere"
radius = 0.1
parent = "a"
position = [-1, 0, 0]

[[object]]
name = "c"
kind = "shape"
shape = "sphere"
radius = 0.1
parent = "b"
position = [-1, 0, 0]

[[object]]
name = "p2"
kind = "shape"
shape = "sphere"
radius = 0.1
position = [4.5, 0, 0.5]

[[object]]
name = "touchA"
kind = "shape"
shape = "sphere"
radius = 0.1
position = [0, 10, 0.5]

[[object]]
name = "touchB"
kind = "shape"
shape = "sphere"
radius = 0.1
position = [0.15, 10, 0.5]
"#;

// ---------------------------------------------------------------------------------------
// Object lookup and hierarchy

#[test]
fn get_object_resolves_paths_relative_to_the_script() {
    let mut sc = Scene::rover(
        "getobject",
        &probe(
            "function t()
                return sim.getObject('.'), sim.getObject('./leftMotor'),
                    sim.getObject('/bubbleRob/leftMotor'), sim.getObject('./sensingNose'),
                    sim.getObject('/nothing', {noError = true}),
                    sim.getObject('/obstacle', {index = 2}), sim.getObject('..', {noError = true})
            end
            function e() return err(sim.getObject, '/nothing'), err(sim.getObject, 42) end",
        ),
    );
    let r = sc.call("t", &[]);
    let rob = sc.find("/bubbleRob");
    let left = sc.find("/bubbleRob/leftMotor");
    assert_eq!(int(&r[0]), rob);
    assert_eq!(int(&r[1]), left);
    assert_eq!(int(&r[2]), left);
    assert_eq!(int(&r[3]), sc.find("/bubbleRob/sensingNose"));
    assert_eq!(int(&r[4]), -1, "noError returns -1");
    // index = 2 skips two matches of the shared alias: the third obstacle of the file.
    let third = int(&r[5]);
    assert_close(&world_position(&sc.sim, third), &[0.2, 1.3, 0.1], 1e-9);
    assert_eq!(int(&r[6]), -1, "the rover is a root: '..' is nothing");
    let e = sc.call("e", &[]);
    assert_contains(text(&e[0]), &["object does not exist", "(in function 'sim.getObject')"]);
    assert_contains(text(&e[1]), &["argument 1", "(in function 'sim.getObject')"]);
}

#[test]
fn get_object_alias_parent_and_type() {
    let mut sc = Scene::rover(
        "alias",
        &probe(
            "function t()
                local m = sim.getObject('./leftMotor')
                local w = sim.getObject('./leftWheel')
                local o = sim.getObject('/obstacle', {index = 2})
                return sim.getObjectAlias(m), sim.getObjectAlias(m, -1), sim.getObjectAlias(m, 1),
                    sim.getObjectAlias(w, 1), sim.getObjectAlias(o), sim.getObjectAlias(o, 1),
                    sim.getObjectParent(w), sim.getObjectParent(m), sim.getObjectParent(sim.getObject('.'))
            end
            function types()
                local h = function(p) return sim.getObjectType(sim.getObject(p)) end
                return h('.'), h('./leftMotor'), h('./sensingNose'), h('./connection'),
                    h('./visionSensor'), h('./graph')
            end
            function e() return err(sim.getObjectType, 99999), err(sim.getObjectParent, 'x'),
                err(sim.getObjectAlias, 99999) end",
        ),
    );
    let r = sc.call("t", &[]);
    assert_eq!(text(&r[0]), "leftMotor");
    assert_eq!(text(&r[1]), "leftMotor");
    // Option 1 is the shortest path that resolves back to the object.
    for (k, path) in [(2, "/bubbleRob/leftMotor"), (3, "/bubbleRob/leftWheel")] {
        let p = text(&r[k]);
        assert!(p.starts_with('/'), "{p}");
        assert_eq!(sc.find(p), sc.find(path), "option 1 gave {p}");
    }
    assert_eq!(text(&r[4]), "obstacle");
    let third = text(&r[5]);
    assert_eq!(third, "/obstacle[2]", "shortest path of the third 'obstacle' root");
    assert_eq!(int(&r[6]), sc.find("/bubbleRob/leftMotor"));
    assert_eq!(int(&r[7]), sc.find("/bubbleRob"));
    assert_eq!(int(&r[8]), -1);

    let t = ints(&Value::Array(sc.call("types", &[])));
    assert_eq!(t, vec![0, 1, 5, 12, 9, 2]);
    // And the constants name them.
    let c = sc.remote("getObjectType", &[i(sc.find("/bubbleRob/leftMotor"))]);
    assert_eq!(c, vec![i(1)]);

    let e = sc.call("e", &[]);
    assert_contains(
        text(&e[0]),
        &["object does not exist", "(in function 'sim.getObjectType')"],
    );
    assert_contains(text(&e[1]), &["argument 1", "(in function 'sim.getObjectParent')"]);
    assert_contains(
        text(&e[2]),
        &["object does not exist", "(in function 'sim.getObjectAlias')"],
    );
}

#[test]
fn get_objects_in_tree_lists_in_hierarchy_order_with_filter_and_options() {
    let mut sc = Scene::rover(
        "tree",
        &probe(
            "function t()
                local b = sim.getObject('.')
                return sim.getObjectsInTree(b), sim.getObjectsInTree(b, sim.object_joint_type),
                    sim.getObjectsInTree(b, sim.handle_all, 1), sim.getObjectsInTree(b, sim.handle_all, 2),
                    sim.getObjectsInTree(b, sim.handle_all, 3), sim.getObjectsInTree(sim.handle_scene),
                    sim.getObjectsInTree(sim.handle_scene, sim.object_proximitysensor_type)
            end",
        ),
    );
    let r = sc.call("t", &[]);
    let h = |p: &str| sc.find(&format!("/bubbleRob{p}"));
    let all = vec![
        h(""),
        h("/leftMotor"),
        h("/leftWheel"),
        h("/rightMotor"),
        h("/rightWheel"),
        h("/connection"),
        h("/slider"),
        h("/sensingNose"),
        h("/visionSensor"),
        h("/graph"),
    ];
    assert_eq!(ints(&r[0]), all);
    assert_eq!(ints(&r[1]), vec![h("/leftMotor"), h("/rightMotor")]);
    assert_eq!(ints(&r[2]), all[1..].to_vec(), "option 1 leaves the base out");
    let firsts = vec![
        h("/leftMotor"),
        h("/rightMotor"),
        h("/connection"),
        h("/sensingNose"),
        h("/graph"),
    ];
    let mut with_base = vec![h("")];
    with_base.extend(&firsts);
    assert_eq!(ints(&r[3]), with_base, "option 2: only the first children");
    assert_eq!(ints(&r[4]), firsts);
    let scene = ints(&r[5]);
    assert_eq!(scene.len(), sc.sim.world().len());
    let mut sorted = scene.clone();
    sorted.sort_unstable();
    sorted.dedup();
    assert_eq!(sorted.len(), scene.len(), "no duplicates");
    assert_eq!(ints(&r[6]), vec![h("/sensingNose")]);
}

#[test]

fn api_errors_reach_lua_as_strings() {
    let mut sc = Scene::rover(
        "errstring",
        &probe(
            "function t()
                local ok, e = pcall(sim.getObject, '/nothing')
                local kind = type(e)
                local ok2, joined = pcall(function() return 'missing: ' .. e end)
                local found = ok2 and string.find(joined, 'object does not exist', 1, true) ~= nil
                return ok, kind, ok2, found, ok2 and joined or tostring(joined)
            end",
        ),
    );
    let r = sc.call("t", &[]);
    assert_eq!(r[0], Value::Bool(false));
    assert_eq!(r[1], s("string"), "type of the error value: {r:?}");
    assert_eq!(r[2], Value::Bool(true), "concatenating the error: {r:?}");
    assert_eq!(r[3], Value::Bool(true));
    assert!(
        !text(&r[4]).contains("runtime error:"),
        "mlua's prefix leaks into the message: {r:?}"
    );
}

// ---------------------------------------------------------------------------------------
// Poses

#[test]
fn object_position_both_argument_orders_and_relative_frames() {
    let mut sc = poses(
        "position",
        "function t()
            local frame, child, free = sim.getObject('/frame'), sim.getObject('/frame/child'), sim.getObject('/free')
            local r = {}
            r[1] = sim.getObjectPosition(child)
            r[2] = sim.getObjectPosition(child, frame)
            r[3] = sim.getObjectPosition(child, sim.handle_parent)
            r[4] = sim.getObjectPosition(child, sim.handle_world)
            sim.setObjectPosition(free, {4, 5, 6})
            r[5] = sim.getObjectPosition(free)
            sim.setObjectPosition(free, -1, {7, 8, 9})
            r[6] = sim.getObjectPosition(free)
            sim.setObjectPosition(free, {0, 1, 0}, frame)
            r[7] = sim.getObjectPosition(free)
            sim.setObjectPosition(free, frame, {2, 0, 0})
            r[8] = sim.getObjectPosition(free)
            sim.setObjectPosition(child, {0, 0, 1}, sim.handle_parent)
            r[9] = sim.getObjectPosition(child)
            return r
        end
        function e()
            return err(sim.setObjectPosition, sim.getObject('/free'), {1, 2}),
                err(sim.setObjectPosition, sim.getObject('/free'), {1, 2, 0/0}),
                err(sim.getObjectPosition, 99999),
                err(sim.setObjectPosition, 'free', {1, 2, 3})
        end",
    );
    let r = sc.call("t", &[]);
    let Value::Array(r) = &r[0] else { panic!("{r:?}") };
    let tol = 1e-12;
    assert_close(&floats(&r[0]), &[1.0, 3.0, 3.0], tol);
    assert_close(&floats(&r[1]), &[1.0, 0.0, 0.0], tol);
    assert_close(&floats(&r[2]), &[1.0, 0.0, 0.0], tol);
    assert_close(&floats(&r[3]), &[1.0, 3.0, 3.0], tol);
    assert_close(&floats(&r[4]), &[4.0, 5.0, 6.0], tol);
    assert_close(&floats(&r[5]), &[7.0, 8.0, 9.0], tol);
    // (0, 1, 0) in the frame turned 90° about Z is (-1, 0, 0) from (1, 2, 3).
    assert_close(&floats(&r[6]), &[0.0, 2.0, 3.0], tol);
    // Legacy order: (h, relativeTo, position).
    assert_close(&floats(&r[7]), &[1.0, 4.0, 3.0], tol);
    assert_close(&floats(&r[8]), &[1.0, 2.0, 4.0], tol);

    let e = sc.call("e", &[]);
    for m in &e {
        assert_contains(text(m), &["(in function 'sim.", "Position')"]);
    }
    assert_contains(text(&e[0]), &["(in function 'sim.setObjectPosition')"]);
    assert_contains(text(&e[1]), &["finite"]);
    assert_contains(text(&e[2]), &["object does not exist"]);
    assert_contains(text(&e[3]), &["argument 1"]);
}

/// `R = Rx(a) Ry(b) Rz(g)`, row-major.
fn coppelia_rotation([a, b, g]: [f64; 3]) -> [[f64; 3]; 3] {
    let rx = [[1.0, 0.0, 0.0], [0.0, a.cos(), -a.sin()], [0.0, a.sin(), a.cos()]];
    let ry = [[b.cos(), 0.0, b.sin()], [0.0, 1.0, 0.0], [-b.sin(), 0.0, b.cos()]];
    let rz = [[g.cos(), -g.sin(), 0.0], [g.sin(), g.cos(), 0.0], [0.0, 0.0, 1.0]];
    let mul = |x: [[f64; 3]; 3], y: [[f64; 3]; 3]| {
        let mut m = [[0.0; 3]; 3];
        for (r, row) in m.iter_mut().enumerate() {
            for (c, cell) in row.iter_mut().enumerate() {
                *cell = (0..3).map(|k| x[r][k] * y[k][c]).sum();
            }
        }
        m
    };
    mul(mul(rx, ry), rz)
}

#[test]
fn object_orientation_uses_coppeliasim_euler_angles() {
    let mut sc = poses(
        "orientation",
        "function t(a, b, g)
            local free = sim.getObject('/free')
            sim.setObjectOrientation(free, {a, b, g})
            local e1 = sim.getObjectOrientation(free)
            local m = sim.getObjectMatrix(free)
            sim.setObjectOrientation(free, {0, 0, 0})
            sim.setObjectOrientation(free, -1, {a, b, g})
            local e2 = sim.getObjectOrientation(free, sim.handle_world)
            return e1, m, e2
        end
        function rel()
            local frame, free = sim.getObject('/frame'), sim.getObject('/free')
            sim.setObjectOrientation(free, {0, 0, 0.5}, frame)
            return sim.getObjectOrientation(free), sim.getObjectOrientation(free, frame),
                sim.getObjectOrientation(sim.getObject('/frame/child'), sim.handle_parent)
        end
        function e() return err(sim.setObjectOrientation, sim.getObject('/free'), {1, 2}) end",
    );
    let angles = [0.3, -0.4, 1.1];
    let r = sc.call("t", &angles.map(f));
    assert_close(&floats(&r[0]), &angles, 1e-12);
    assert_close(&floats(&r[2]), &angles, 1e-12);
    let m = floats(&r[1]);
    let expected = coppelia_rotation(angles);
    assert_eq!(m.len(), 12);
    for row in 0..3 {
        assert_close(&m[row * 4..row * 4 + 3], &expected[row], 1e-12);
    }
    let r = sc.call("rel", &[]);
    // The frame is turned 90° about Z: 0.5 more about Z relative to it.
    assert_close(&floats(&r[0]), &[0.0, 0.0, FRAC_PI_2 + 0.5], 1e-12);
    assert_close(&floats(&r[1]), &[0.0, 0.0, 0.5], 1e-12);
    assert_close(&floats(&r[2]), &[0.0, 0.0, 0.0], 1e-12);
    let e = sc.call("e", &[]);
    assert_contains(text(&e[0]), &["argument 2", "(in function 'sim.setObjectOrientation')"]);
}

#[test]
fn scene_orientation_matches_the_euler_convention() {
    // sensingNose has orientation_deg = [0, 90, 90]: its detection axis (+Z) is the
    // body's +X, which only holds with R = Rx(a) Ry(b) Rz(g).
    let mut sc = Scene::rover(
        "nose",
        &probe(
            "function t()
                local n = sim.getObject('./sensingNose')
                return sim.getObjectMatrix(n, sim.getObject('.')), sim.getObjectOrientation(n, sim.handle_parent)
            end",
        ),
    );
    let r = sc.call("t", &[]);
    let m = floats(&r[0]);
    let z_axis = [m[2], m[6], m[10]];
    assert_close(&z_axis, &[1.0, 0.0, 0.0], 1e-9);
    assert_close(&[m[3], m[7], m[11]], &[0.1, 0.0, 0.0], 1e-9);
    assert_close(&floats(&r[1]), &[0.0, FRAC_PI_2, FRAC_PI_2], 1e-6);
}

#[test]
fn object_quaternion_is_xyzw_in_both_argument_orders() {
    let mut sc = poses(
        "quaternion",
        "function t()
            local free, frame = sim.getObject('/free'), sim.getObject('/frame')
            local s, c = math.sin(0.35), math.cos(0.35)
            sim.setObjectQuaternion(free, {s, 0, 0, c})
            local e1, q1 = sim.getObjectOrientation(free), sim.getObjectQuaternion(free)
            sim.setObjectQuaternion(free, -1, {0, 0, s, c})
            local e2 = sim.getObjectOrientation(free)
            sim.setObjectQuaternion(free, {0, 0, 0, 1}, frame)
            local q3 = sim.getObjectQuaternion(free)
            return e1, q1, e2, q3, sim.getObjectQuaternion(sim.getObject('/frame/child'), frame)
        end
        function e() return err(sim.setObjectQuaternion, sim.getObject('/free'), {0, 0, 0, 0}),
            err(sim.setObjectQuaternion, sim.getObject('/free'), {0, 0, 1}) end",
    );
    let r = sc.call("t", &[]);
    assert_close(&floats(&r[0]), &[0.7, 0.0, 0.0], 1e-12);
    let (s, c) = (0.35f64.sin(), 0.35f64.cos());
    let q1 = floats(&r[1]);
    let sign = q1[3].signum();
    assert_close(
        &q1.iter().map(|v| v * sign).collect::<Vec<_>>(),
        &[s, 0.0, 0.0, c],
        1e-12,
    );
    assert_close(&floats(&r[2]), &[0.0, 0.0, 0.7], 1e-12);
    // Identity relative to the frame = the frame's own rotation, 90° about Z.
    let q3 = floats(&r[3]);
    let sign = q3[3].signum();
    let h = FRAC_PI_4;
    assert_close(
        &q3.iter().map(|v| v * sign).collect::<Vec<_>>(),
        &[0.0, 0.0, h.sin(), h.cos()],
        1e-12,
    );
    let q4 = floats(&r[4]);
    assert_close(&[q4[0], q4[1], q4[2], q4[3].abs()], &[0.0, 0.0, 0.0, 1.0], 1e-12);
    let e = sc.call("e", &[]);
    for m in &e {
        assert_contains(text(m), &["(in function 'sim.setObjectQuaternion')"]);
    }
}

#[test]
fn object_pose_and_matrix() {
    let mut sc = poses(
        "pose",
        "function t()
            local free, frame, child = sim.getObject('/free'), sim.getObject('/frame'), sim.getObject('/frame/child')
            local s, c = math.sin(0.25), math.cos(0.25)
            sim.setObjectPose(free, {1, 2, 3, 0, s, 0, c})
            local p1, e1 = sim.getObjectPosition(free), sim.getObjectOrientation(free)
            local pose1 = sim.getObjectPose(free)
            sim.setObjectPose(free, frame, {1, 0, 0, 0, 0, 0, 1})
            local p2 = sim.getObjectPosition(free)
            return p1, e1, pose1, p2, sim.getObjectPose(child, frame), sim.getObjectMatrix(frame),
                sim.getObjectMatrix(child, frame)
        end
        function e() return err(sim.setObjectPose, sim.getObject('/free'), {1, 2, 3}) end",
    );
    let r = sc.call("t", &[]);
    assert_close(&floats(&r[0]), &[1.0, 2.0, 3.0], 1e-12);
    assert_close(&floats(&r[1]), &[0.0, 0.5, 0.0], 1e-12);
    let pose = floats(&r[2]);
    let sign = pose[6].signum();
    assert_close(
        &[
            pose[0],
            pose[1],
            pose[2],
            pose[3] * sign,
            pose[4] * sign,
            pose[5] * sign,
            pose[6] * sign,
        ],
        &[1.0, 2.0, 3.0, 0.0, 0.25f64.sin(), 0.0, 0.25f64.cos()],
        1e-12,
    );
    // Legacy order, relative to the frame: 1 m along its X (= world +Y).
    assert_close(&floats(&r[3]), &[1.0, 3.0, 3.0], 1e-12);
    let cp = floats(&r[4]);
    assert_close(&cp[..3], &[1.0, 0.0, 0.0], 1e-12);
    assert_close(&[cp[3], cp[4], cp[5], cp[6].abs()], &[0.0, 0.0, 0.0, 1.0], 1e-12);
    // Row-major 3x4 with the translation at Lua indices 4, 8, 12.
    assert_close(
        &floats(&r[5]),
        &[
            0.0, -1.0, 0.0, 1.0, //
            1.0, 0.0, 0.0, 2.0, //
            0.0, 0.0, 1.0, 3.0,
        ],
        1e-12,
    );
    assert_close(
        &floats(&r[6]),
        &[
            1.0, 0.0, 0.0, 1.0, //
            0.0, 1.0, 0.0, 0.0, //
            0.0, 0.0, 1.0, 0.0,
        ],
        1e-12,
    );
    let e = sc.call("e", &[]);
    assert_contains(text(&e[0]), &["(in function 'sim.setObjectPose')"]);
}

#[test]
fn object_velocity_of_the_moving_rover() {
    let mut sc = Scene::rover(
        "velocity",
        &probe(
            "function sysCall_init()
                sim.setJointTargetVelocity(sim.getObject('./leftMotor'), 4)
                sim.setJointTargetVelocity(sim.getObject('./rightMotor'), 4)
            end
            function t()
                local v, w = sim.getObjectVelocity(sim.getObject('.'))
                local sv, sw = sim.getObjectVelocity(sim.getObject('/obstacle'))
                return v, w, sv, sw
            end",
        ),
    );
    let r = sc.call("t", &[]);
    assert_close(&floats(&r[0]), &[0.0; 3], 1e-6);
    for _ in 0..30 {
        sc.sim.step();
    }
    let r = sc.call("t", &[]);
    let v = floats(&r[0]);
    assert_eq!(v.len(), 3);
    assert_eq!(floats(&r[1]).len(), 3);
    let speed = v[0].hypot(v[1]);
    // 4 rad/s on wheels of radius 0.04 m: 0.16 m/s.
    assert!((speed - 0.16).abs() < 0.04, "planar speed {speed} m/s, velocity {v:?}");
    assert_close(&floats(&r[2]), &[0.0; 3], 1e-9);
    assert_close(&floats(&r[3]), &[0.0; 3], 1e-9);
}

// ---------------------------------------------------------------------------------------
// Joints

#[test]
fn joint_position_is_clamped_wrapped_and_moves_children() {
    let mut sc = joints(
        "jointpos",
        "function set(path, q)
            local h = sim.getObject(path)
            sim.setJointPosition(h, q)
            return sim.getJointPosition(h)
        end
        function tip() return sim.getObjectPosition(sim.getObject('/base/tip')) end",
    );
    let mut set = |p: &str, q: f64| num(&sc.call("set", &[s(p), f(q)])[0]);
    assert_eq!(set("/base/limited", 0.5), 0.5);
    assert!((set("/base/limited", 3.0) - FRAC_PI_4).abs() < 1e-12);
    assert!((set("/base/limited", -3.0) + FRAC_PI_2).abs() < 1e-12);
    assert!((set("/base/cyclic", 1.5 * PI) + FRAC_PI_2).abs() < 1e-12);
    assert!((set("/base/cyclic", 7.0) - (7.0 - 2.0 * PI)).abs() < 1e-12);
    assert!((set("/base/cyclic", -PI) - PI).abs() < 1e-12, "(-pi, pi]");
    assert_eq!(set("/base/slider", 0.5), 0.2);
    assert_eq!(set("/base/slider", -1.0), 0.0);
    assert_eq!(set("/base/slider", 0.1), 0.1);
    assert_eq!(set("/base/free", 10.0), 10.0);
    // The tip 1 m along the joint's X turns with it, at once.
    set("/base/limited", 0.5);
    let tip = floats(&sc.call("tip", &[])[0]);
    assert_close(&tip, &[0.5f64.cos(), 0.5f64.sin(), 0.0], 1e-12);
}

#[test]
fn joint_interval_type_and_targets() {
    let mut sc = joints(
        "jointinfo",
        "function t()
            local l, c, p, u = sim.getObject('/base/limited'), sim.getObject('/base/cyclic'),
                sim.getObject('/base/slider'), sim.getObject('/base/free')
            local lc, li = sim.getJointInterval(l)
            local cc, ci = sim.getJointInterval(c)
            local pc, pi_ = sim.getJointInterval(p)
            sim.setJointTargetPosition(l, 0.3)
            local tp, pos = sim.getJointTargetPosition(l), sim.getJointPosition(l)
            sim.setJointTargetPosition(p, 5)
            local tp2 = sim.getJointTargetPosition(p)
            sim.setJointTargetVelocity(u, -1.25)
            return lc, li, cc, ci, pc, pi_, sim.getJointType(l), sim.getJointType(p),
                sim.joint_revolute_subtype, sim.joint_prismatic_subtype, tp, pos, tp2,
                sim.getJointTargetVelocity(u)
        end",
    );
    let r = sc.call("t", &[]);
    assert_eq!(r[0], Value::Bool(false));
    assert_close(&floats(&r[1]), &[-FRAC_PI_2, 0.75 * PI], 1e-12);
    assert_eq!(r[2], Value::Bool(true));
    assert_close(&floats(&r[3]), &[-PI, 2.0 * PI], 1e-12);
    assert_eq!(r[4], Value::Bool(false));
    assert_close(&floats(&r[5]), &[0.0, 0.2], 1e-12);
    assert_eq!((int(&r[6]), int(&r[7])), (10, 11));
    assert_eq!((int(&r[8]), int(&r[9])), (10, 11));
    assert_eq!(num(&r[10]), 0.3);
    // A kinematic joint moves to its target over the following steps, as CoppeliaSim's
    // (crates/sim-core/tests/kinematic_motion.rs), not at once.
    assert_eq!(num(&r[11]), 0.0, "kinematic joints move at the next steps");
    assert_eq!(num(&r[12]), 0.2, "target clamped to the limits");
    assert_eq!(num(&r[13]), -1.25);
}

#[test]
fn joint_errors_name_the_function() {
    let mut sc = joints(
        "jointerr",
        "function e()
            local j, base = sim.getObject('/base/limited'), sim.getObject('/base')
            return err(sim.setJointPosition, 'x', 1), err(sim.setJointPosition, base, 1),
                err(sim.setJointTargetVelocity, j, 0/0), err(sim.setJointPosition, j, 0/0),
                err(sim.getJointPosition, 99999), err(sim.setJointTargetPosition, j, math.huge),
                err(sim.getJointInterval, base), err(sim.getJointType, base),
                err(sim.setJointTargetForce, j, 'strong'), err(sim.getJointForce, base),
                err(sim.getJointVelocity, base), err(sim.getJointTargetVelocity, base),
                err(sim.getJointTargetPosition, base), err(sim.setJointPosition, j)
        end",
    );
    let e = sc.call("e", &[]);
    let e: Vec<&str> = e.iter().map(text).collect();
    assert_contains(e[0], &["argument 1", "(in function 'sim.setJointPosition')"]);
    assert_contains(e[1], &["not a joint", "(in function 'sim.setJointPosition')"]);
    assert_contains(e[2], &["finite", "(in function 'sim.setJointTargetVelocity')"]);
    assert_contains(e[3], &["finite", "(in function 'sim.setJointPosition')"]);
    assert_contains(e[4], &["object does not exist", "(in function 'sim.getJointPosition')"]);
    assert_contains(e[5], &["finite", "(in function 'sim.setJointTargetPosition')"]);
    assert_contains(e[6], &["not a joint", "(in function 'sim.getJointInterval')"]);
    assert_contains(e[7], &["not a joint", "(in function 'sim.getJointType')"]);
    assert_contains(e[8], &["argument 2", "(in function 'sim.setJointTargetForce')"]);
    assert_contains(e[9], &["not a joint", "(in function 'sim.getJointForce')"]);
    assert_contains(e[10], &["not a joint", "(in function 'sim.getJointVelocity')"]);
    assert_contains(e[11], &["not a joint", "(in function 'sim.getJointTargetVelocity')"]);
    assert_contains(e[12], &["not a joint", "(in function 'sim.getJointTargetPosition')"]);
    assert_contains(e[13], &["argument 2", "(in function 'sim.setJointPosition')"]);
    // The joint kept its position through the failed calls.
    let q = sc.remote("getJointPosition", &[i(sc.find("/base/limited"))]);
    assert_eq!(q, vec![f(0.0)]);
}

#[test]
fn joint_velocity_force_and_force_limit_on_the_rover() {
    let mut sc = Scene::rover(
        "jointdyn",
        &probe(
            "function sysCall_init()
                left, right = sim.getObject('./leftMotor'), sim.getObject('./rightMotor')
            end
            function drive(v, maxForce)
                sim.setJointTargetVelocity(left, v)
                sim.setJointTargetVelocity(right, v)
                if maxForce then
                    sim.setJointTargetForce(left, maxForce)
                    sim.setJointTargetForce(right, maxForce)
                end
            end
            function read()
                return sim.getJointVelocity(left), sim.getJointForce(left),
                    sim.getJointTargetVelocity(left), sim.getJointPosition(left)
            end",
        ),
    );
    sc.call("drive", &[f(2.0)]);
    for _ in 0..40 {
        sc.sim.step();
    }
    let r = sc.call("read", &[]);
    let (vel, force, target, pos) = (num(&r[0]), num(&r[1]), num(&r[2]), num(&r[3]));
    assert_eq!(target, 2.0);
    assert!((vel - 2.0).abs() < 0.2, "wheel speed {vel} rad/s, target 2");
    assert!(force.abs() <= 2.5 + 1e-9, "force {force} within max_force");
    assert!(pos.abs() > 1.0, "the wheel turned: position {pos}");

    // A far target saturates the motor at the force limit.
    sc.call("drive", &[f(50.0), f(0.5)]);
    sc.sim.step();
    let force = num(&sc.call("read", &[])[1]);
    assert!((force.abs() - 0.5).abs() < 1e-9, "saturated force {force}, limit 0.5");

    // Without motor force the motor cannot drive: a rover brought to rest stays there
    // whatever speed it is asked for.
    let rob = sc.find("/bubbleRob");
    sc.call("drive", &[f(0.0), f(2.5)]);
    for _ in 0..40 {
        sc.sim.step();
    }
    sc.call("drive", &[f(6.0), f(0.0)]);
    let before = world_position(&sc.sim, rob);
    for _ in 0..40 {
        sc.sim.step();
    }
    let after = world_position(&sc.sim, rob);
    let moved = (after[0] - before[0]).hypot(after[1] - before[1]);
    assert!(moved < 0.01, "moved {moved} m with zero motor force");
    assert!(num(&sc.call("read", &[])[1]).abs() < 1e-9);
}

// ---------------------------------------------------------------------------------------
// Time, state, log

#[test]
fn simulation_time_is_constant_within_a_step_and_advances_by_dt() {
    let toml = "[simulation]\ndt = 0.01\n[[object]]\nname = \"d\"\nkind = \"dummy\"\nscript = \"probe.lua\"\n";
    let body = "times = {}
        function sysCall_init() times[#times + 1] = sim.getSimulationTime() end
        function sysCall_actuation() times[#times + 1] = sim.getSimulationTime() end
        function sysCall_sensing()
            times[#times + 1] = sim.getSimulationTime()
            dt, state = sim.getSimulationTimeStep(), sim.getSimulationState()
        end
        function t() return times, dt, state, sim.simulation_advancing_running end";
    let mut sc = Scene::new("time", toml, &[("probe.lua", &probe(body))], ScriptLimits::default());
    assert_eq!(sc.remote("getSimulationState", &[]), vec![i(0)]);
    for _ in 0..3 {
        sc.sim.step();
    }
    let r = sc.call("t", &[]);
    assert_close(&floats(&r[0]), &[0.0, 0.0, 0.0, 0.01, 0.01, 0.02, 0.02], 1e-12);
    assert_eq!(num(&r[1]), 0.01);
    assert_eq!(int(&r[2]), 17);
    assert_eq!(int(&r[3]), 17);
    assert_close(&[num(&sc.remote("getSimulationTime", &[])[0])], &[0.03], 1e-12);
    sc.sim.pause();
    assert_eq!(sc.remote("getSimulationState", &[]), vec![i(8)]);
    sc.sim.step();
    assert_close(&[num(&sc.remote("getSimulationTime", &[])[0])], &[0.03], 1e-12);
    sc.sim.stop();
    assert_eq!(sc.remote("getSimulationState", &[]), vec![i(0)]);
    assert_eq!(sc.remote("getSimulationTime", &[]), vec![f(0.0)]);
}

#[test]
fn system_time_is_wall_clock_seconds() {
    let mut sc = Scene::rover("systime", &probe("function t() return sim.getSystemTime() end"));
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .expect("after 1970")
        .as_secs_f64();
    let t1 = num(&sc.call("t", &[])[0]);
    std::thread::sleep(std::time::Duration::from_millis(60));
    let t2 = num(&sc.call("t", &[])[0]);
    assert!((t1 - now).abs() < 5.0, "{t1} vs now {now}");
    assert!(t2 - t1 >= 0.05 && t2 - t1 < 5.0, "{t1} then {t2}");
}

#[test]
fn add_log_reaches_the_world_log_with_the_script_name() {
    let mut sc = Scene::rover(
        "addlog",
        &probe(
            "function t()
                sim.addLog(sim.verbosity_scriptinfos, 'hello from the rover')
                sim.addLog(sim.verbosity_scriptwarnings, 'careful')
                return err(sim.addLog, 'loud', 'x'), err(sim.addLog, sim.verbosity_scriptinfos)
            end",
        ),
    );
    let e = sc.call("t", &[]);
    sc.remote("addLog", &[i(500), s("from afar")]);
    let lines = util::log_lines(&sc.sim);
    assert!(
        lines.contains(&("probe.lua".into(), 450, "hello from the rover".into())),
        "{lines:?}"
    );
    assert!(lines.contains(&("probe.lua".into(), 420, "careful".into())));
    assert!(lines.contains(&("remote".into(), 500, "from afar".into())));
    assert_contains(text(&e[0]), &["argument 1", "(in function 'sim.addLog')"]);
    assert_contains(text(&e[1]), &["argument 2", "(in function 'sim.addLog')"]);
}

// ---------------------------------------------------------------------------------------
// Proximity sensors

#[test]
fn read_proximity_sensor_always_returns_five_values() {
    let mut sc = sensors(
        "readprox",
        "function sysCall_init() first = {sim.readProximitySensor(sim.getObject('/ray'))} end
        function t() return first end
        function read(p) return sim.readProximitySensor(sim.getObject(p)) end
        function handle(p) return sim.handleProximitySensor(sim.getObject(p)) end
        function e() return err(sim.readProximitySensor, sim.getObject('/wall')),
            err(sim.handleProximitySensor, 'ray'), err(sim.readProximitySensor, 99999) end",
    );
    // Never handled: -1, and still five values.
    let Value::Array(first) = &sc.call("t", &[])[0] else {
        panic!()
    };
    assert_eq!(first.len(), 5);
    assert_eq!(int(&first[0]), -1);
    let before = sc.call("read", &[s("/cone")]);
    assert_eq!(before.len(), 5);
    assert_eq!(int(&before[0]), -1);
    assert_eq!(int(&before[3]), -1);
    assert_eq!(floats(&before[2]).len(), 3);
    assert_eq!(floats(&before[4]).len(), 3);

    // handleProximitySensor senses now and returns what read returns afterwards. (One
    // step first: see `handle_proximity_sensor_works_before_the_first_step`.)
    sc.sim.step();
    let wall = sc.find("/wall");
    let ball = sc.find("/ball");
    let h = sc.call("handle", &[s("/ray")]);
    assert_eq!(h, sc.call("read", &[s("/ray")]));
    assert_eq!(int(&h[0]), 1);
    assert!((num(&h[1]) - 0.45).abs() < 1e-5, "ray distance {:?}", h[1]);
    assert_close(&floats(&h[2]), &[0.0, 0.0, 0.45], 1e-5);
    assert_eq!(int(&h[3]), wall);
    let n = floats(&h[4]);
    assert!((n.iter().map(|v| v * v).sum::<f64>().sqrt() - 1.0).abs() < 1e-6);
    assert!(n[2].abs() > 0.999, "normal along the ray: {n:?}");

    // The cone sees the nearer, off-axis ball: its exact nearest point.
    let c = sc.call("handle", &[s("/cone")]);
    assert_eq!(int(&c[0]), 1);
    assert_eq!(int(&c[3]), ball);
    let d = 0.1f64.sqrt() - 0.02;
    assert!((num(&c[1]) - d).abs() < 1e-4, "cone distance {:?}", c[1]);
    let k = 1.0 - 0.02 / 0.1f64.sqrt();
    // Sensor frame: local Z is world +X, local Y is world +Y.
    assert_close(&floats(&c[2]), &[0.0, 0.1 * k, 0.3 * k], 1e-4);

    // Too short, or starting beyond the box: nothing, still five values.
    for p in ["/shortRay", "/offsetRay"] {
        let r = sc.call("handle", &[s(p)]);
        assert_eq!(r.len(), 5);
        assert_eq!(int(&r[0]), 0, "{p}: {r:?}");
        assert_eq!(int(&r[3]), -1);
    }
    // Moving the ball out of the cone: the cone sees the box.
    sc.remote("setObjectPosition", &[i(ball), arr(&[-1.0, 0.0, 0.1]), i(-1)]);
    sc.sim.step();
    let c = sc.call("read", &[s("/cone")]);
    assert_eq!(int(&c[0]), 1);
    assert_eq!(int(&c[3]), wall);
    assert!((num(&c[1]) - 0.45).abs() < 1e-4, "{c:?}");

    let e = sc.call("e", &[]);
    assert_contains(
        text(&e[0]),
        &["not a proximity sensor", "(in function 'sim.readProximitySensor')"],
    );
    assert_contains(
        text(&e[1]),
        &["argument 1", "(in function 'sim.handleProximitySensor')"],
    );
    assert_contains(
        text(&e[2]),
        &["object does not exist", "(in function 'sim.readProximitySensor')"],
    );
}

#[test]

fn handle_proximity_sensor_works_before_the_first_step() {
    let mut sc = sensors(
        "proxinit",
        "function sysCall_init() atInit = sim.handleProximitySensor(sim.getObject('/ray')) end
        function t() return atInit, sim.handleProximitySensor(sim.getObject('/cone')) end",
    );
    // The box is 0.45 m in front of both sensors from the start.
    let r = sc.call("t", &[]);
    assert_eq!(int(&r[0]), 1, "handled in sysCall_init: {r:?}");
    assert_eq!(int(&r[1]), 1, "handled before any step: {r:?}");
    let wall = sc.find("/wall");
    let h = sc.remote("handleProximitySensor", &[i(sc.find("/ray"))]);
    assert_eq!(int(&h[3]), wall);
}

#[test]
fn the_step_handles_proximity_sensors_between_actuation_and_sensing() {
    let mut sc = sensors(
        "stepprox",
        "seen = {}
        function sysCall_actuation() seen[#seen + 1] = sim.readProximitySensor(sim.getObject('/ray')) end
        function sysCall_sensing() seen[#seen + 1] = sim.readProximitySensor(sim.getObject('/ray')) end
        function t() return seen end",
    );
    sc.sim.step();
    sc.sim.step();
    assert_eq!(ints(&sc.call("t", &[])[0]), vec![-1, 1, 1, 1]);
}

// ---------------------------------------------------------------------------------------
// Distance, collision, collections

fn collections(tag: &str) -> Scene {
    let body = "function dist(items, other, threshold)
            local c = sim.createCollection(0)
            for _, it in ipairs(items) do
                local h = it[1] == sim.handle_all and -1 or sim.getObject(it[2])
                sim.addItemToCollection(c, it[1], h, it[3] or 0)
            end
            local o = type(other) == 'string' and sim.getObject(other) or other
            return sim.checkDistance(c, o, threshold)
        end
        function pair(a, b)
            local h = function(x) return type(x) == 'string' and sim.getObject(x) or x end
            return sim.checkDistance(h(a), h(b))
        end
        function collide(a, b)
            local h = function(x) return type(x) == 'string' and sim.getObject(x) or x end
            return sim.checkCollision(h(a), h(b))
        end
        function e()
            return err(sim.checkDistance, 99999, sim.handle_all), err(sim.checkCollision, 'a', 1),
                err(sim.addItemToCollection, 12345678, sim.handle_single, sim.getObject('/a'), 0),
                err(sim.addItemToCollection, sim.createCollection(0), 3, sim.getObject('/a'), 0),
                err(sim.checkDistance, sim.getObject('/a'), 7654321),
                err(sim.checkDistance, sim.getObject('/a'), sim.handle_all, 0/0)
        end";
    let mut sc = Scene::new(
        tag,
        COLLECTIONS,
        &[("probe.lua", &probe(body))],
        ScriptLimits::default(),
    );
    sc.sim.start();
    sc
}

/// A collection item for `dist`: `{what, path, options}`.
fn item(what: i64, path: &str, options: i64) -> Value {
    Value::Array(vec![i(what), s(path), i(options)])
}

const SINGLE: i64 = -8;
const TREE: i64 = -6;
const CHAIN: i64 = -7;
const ALL: i64 = -2;

#[test]
fn check_distance_between_objects_returns_world_points() {
    let mut sc = collections("distance");
    let r = sc.call("pair", &[s("/a/b/c"), i(ALL)]);
    assert_eq!(int(&r[0]), 1);
    let d = floats(&r[1]);
    assert_eq!(d.len(), 7);
    // c (x = 1) to b (x = 2), radii 0.1: 0.8 m between (1.1, 0, 0.5) and (1.9, 0, 0.5).
    assert_close(&d, &[1.1, 0.0, 0.5, 1.9, 0.0, 0.5, 0.8], 1e-5);
    let gap = ((d[3] - d[0]).powi(2) + (d[4] - d[1]).powi(2) + (d[5] - d[2]).powi(2)).sqrt();
    assert!((gap - d[6]).abs() < 1e-6);
    assert_eq!(ints(&r[2]), vec![sc.find("/a/b/c"), sc.find("/a/b")]);

    let r = sc.call("pair", &[s("/p1"), s("/p2")]);
    assert_close(&floats(&r[1])[6..], &[4.8], 1e-5);
    assert_eq!(ints(&r[2]), vec![sc.find("/p1"), sc.find("/p2")]);

    // A threshold below the distance: result 0, zeros, -1 pair.
    let r = sc.call("dist", &[Value::Array(vec![item(SINGLE, "/a/b/c", 0)]), i(ALL), f(0.5)]);
    assert_eq!(int(&r[0]), 0);
    assert_eq!(ints(&r[2]), vec![-1, -1]);
    let r = sc.call("dist", &[Value::Array(vec![item(SINGLE, "/a/b/c", 0)]), i(ALL), f(1.0)]);
    assert_eq!(int(&r[0]), 1);
    assert_close(&floats(&r[1])[6..], &[0.8], 1e-5);
}

#[test]
fn collections_with_single_tree_chain_all_exclude_and_remove() {
    let mut sc = collections("collections");
    let (a, b, c, p2) = (sc.find("/a"), sc.find("/a/b"), sc.find("/a/b/c"), sc.find("/p2"));
    let mut nearest = |items: Vec<Value>, other: &str| {
        let r = sc.call("dist", &[Value::Array(items), s(other)]);
        assert_eq!(int(&r[0]), 1, "{r:?}");
        (ints(&r[2])[0], floats(&r[1])[6])
    };

    // Chain of c: c, b, a. With the tip excluded (bit 1): b, a.
    let r1 = nearest(vec![item(CHAIN, "/a/b/c", 0)], "/p1");
    let r2 = nearest(vec![item(CHAIN, "/a/b/c", 2)], "/p1");
    // Tree of a: a, b, c. With the base excluded: b, c.
    let r3 = nearest(vec![item(TREE, "/a", 0)], "/p2");
    let r4 = nearest(vec![item(TREE, "/a", 2)], "/p2");
    // Single.
    let r5 = nearest(vec![item(SINGLE, "/a/b", 0)], "/p1");
    // Remove (bit 0): tree of a without c.
    let r6 = nearest(vec![item(TREE, "/a", 0), item(SINGLE, "/a/b/c", 1)], "/p1");
    // Everything, minus p1 and the tree of a: p2 and the far pair.
    let r7 = nearest(
        vec![item(ALL, "", 0), item(SINGLE, "/p1", 1), item(TREE, "/a", 1)],
        "/p1",
    );
    assert_eq!(r1.0, c);
    assert!((r1.1 - 1.3).abs() < 1e-5);
    assert_eq!(r2.0, b);
    assert!((r2.1 - 2.3).abs() < 1e-5);
    assert_eq!(r3.0, a);
    assert!((r3.1 - 1.3).abs() < 1e-5);
    assert_eq!(r4.0, b);
    assert!((r4.1 - 2.3).abs() < 1e-5);
    assert_eq!(r5.0, b);
    assert_eq!(r6.0, b);
    assert_eq!(r7.0, p2);
    assert!((r7.1 - 4.8).abs() < 1e-5);
}

#[test]
fn check_collision_between_objects_and_collections() {
    let mut sc = collections("collision");
    let (ta, tb) = (sc.find("/touchA"), sc.find("/touchB"));
    let r = sc.call("collide", &[s("/touchA"), s("/touchB")]);
    assert_eq!(int(&r[0]), 1);
    assert_eq!(ints(&r[1]), vec![ta, tb]);
    let r = sc.call("collide", &[s("/touchA"), i(ALL)]);
    assert_eq!(int(&r[0]), 1);
    assert_eq!(ints(&r[1]), vec![ta, tb]);
    let r = sc.call("collide", &[s("/a"), s("/a/b")]);
    assert_eq!(int(&r[0]), 0);
    assert_eq!(ints(&r[1]), vec![-1, -1]);
    let r = sc.call("collide", &[s("/a/b/c"), i(ALL)]);
    assert_eq!(int(&r[0]), 0);

    let e = sc.call("e", &[]);
    let e: Vec<&str> = e.iter().map(text).collect();
    assert_contains(e[0], &["(in function 'sim.checkDistance')"]);
    assert_contains(e[1], &["argument 1", "(in function 'sim.checkCollision')"]);
    assert_contains(e[2], &["collection", "(in function 'sim.addItemToCollection')"]);
    assert_contains(e[3], &["argument 2", "(in function 'sim.addItemToCollection')"]);
    assert_contains(e[4], &["(in function 'sim.checkDistance')"]);
    // Issue #9: a NaN threshold used to be read as "no threshold".
    assert_contains(
        e[5],
        &[
            "argument 3: the threshold must be a number, got NaN",
            "(in function 'sim.checkDistance')",
        ],
    );
}

// ---------------------------------------------------------------------------------------
// Force sensor

#[test]

fn force_sensor_carries_the_weight_below_it() {
    // A 2 kg ball hanging from a static beam through a force sensor.
    let toml = r#"
[[object]]
name = "beam"
kind = "shape"
shape = "box"
size = [0.2, 0.2, 0.05]
position = [0, 0, 1]
script = "probe.lua"

[[object]]
name = "sensor"
kind = "force_sensor"
parent = "beam"
position = [0, 0, -0.1]

[[object]]
name = "ball"
kind = "shape"
shape = "sphere"
radius = 0.05
mass = 2.0
dynamic = true
parent = "sensor"
position = [0, 0, -0.1]
"#;
    let body = "function t() return sim.readForceSensor(sim.getObject('/beam/sensor')) end
        function e() return err(sim.readForceSensor, sim.getObject('/beam')) end";
    let mut sc = Scene::new(
        "forcehang",
        toml,
        &[("probe.lua", &probe(body))],
        ScriptLimits::default(),
    );
    sc.sim.start();
    let r = sc.call("t", &[]);
    assert_eq!(r.len(), 3);
    assert_eq!(int(&r[0]) & 1, 0, "no reading before the first step");
    for _ in 0..20 {
        sc.sim.step();
    }
    let r = sc.call("t", &[]);
    assert_eq!(int(&r[0]) & 1, 1);
    let force = floats(&r[1]);
    let magnitude = force.iter().map(|v| v * v).sum::<f64>().sqrt();
    assert!(
        (magnitude - 2.0 * 9.81).abs() < 0.2,
        "force {force:?}, |F| = {magnitude}, expected 19.62 N"
    );
    assert!(force[2].abs() > 0.99 * magnitude, "vertical: {force:?}");
    let torque = floats(&r[2]);
    assert!(torque.iter().all(|t| t.abs() < 0.05), "torque {torque:?}");
    let e = sc.call("e", &[]);
    assert_contains(
        text(&e[0]),
        &["not a force sensor", "(in function 'sim.readForceSensor')"],
    );
}

#[test]

fn bubble_rob_connection_force_sensor_reads_the_caster_load() {
    let mut sc = Scene::rover(
        "forcerob",
        &probe("function t() return sim.readForceSensor(sim.getObject('./connection')) end"),
    );
    for _ in 0..40 {
        sc.sim.step();
    }
    let r = sc.call("t", &[]);
    assert_eq!(int(&r[0]) & 1, 1);
    let force = floats(&r[1]);
    let magnitude = force.iter().map(|v| v * v).sum::<f64>().sqrt();
    // Statics of the rover at rest: body 1 kg at x = 0, wheels 2 x 0.8 kg touching the
    // floor at x = 0.05, slider 0.5 kg touching it at x = -0.07. Moments about the wheel
    // contacts give the floor's push on the slider, N = W (0.05 - x_com) / 0.12 = 8.99 N;
    // the connection carries N minus the slider's own weight (4.905 N): 4.09 N, upwards.
    let g = 9.81;
    let x_com = (0.8 * 2.0 * 0.05 - 0.5 * 0.07) / 3.1;
    let expected = 3.1 * g * (0.05 - x_com) / 0.12 - 0.5 * g;
    eprintln!(
        "bubbleRob connection: force {force:?}, |F| = {magnitude:.3} N, statics {expected:.3} N, slider weight {:.3} N",
        0.5 * g
    );
    assert!(force[2].abs() > 0.9 * magnitude, "vertical: {force:?}");
    assert!(
        (magnitude - expected).abs() < 0.15 * expected,
        "|F| = {magnitude} N, statics give {expected} N"
    );
}

// ---------------------------------------------------------------------------------------
// Signals

#[test]
fn int32_float_and_string_signals() {
    let mut sc = Scene::rover(
        "signals",
        &probe(
            "function t()
                local r = {}
                r[1] = sim.getInt32Signal('i') == nil and sim.getFloatSignal('f') == nil
                    and sim.getStringSignal('s') == nil
                sim.setInt32Signal('i', 42)
                sim.setFloatSignal('f', 2.5)
                sim.setStringSignal('s', 'text')
                sim.setStringSignal('bin', '\\0\\255\\1')
                r[2] = sim.getInt32Signal('i')
                r[3] = sim.getFloatSignal('f')
                r[4] = sim.getStringSignal('s')
                r[5] = sim.getStringSignal('bin') == '\\0\\255\\1'
                r[6] = math.type(sim.getInt32Signal('i'))
                return r
            end
            function clear()
                sim.clearInt32Signal('i')
                sim.clearFloatSignal('f')
                sim.clearStringSignal('s')
                return sim.getInt32Signal('i') == nil, sim.getFloatSignal('f') == nil,
                    sim.getStringSignal('s') == nil, sim.getStringSignal('bin') ~= nil
            end
            function e() return err(sim.setInt32Signal, 'i', 2^31), err(sim.setInt32Signal, 'i', 1.5),
                err(sim.setFloatSignal, 5, 1), err(sim.getStringSignal) end",
        ),
    );
    let Value::Array(r) = &sc.call("t", &[])[0] else {
        panic!()
    };
    assert_eq!(r[0], Value::Bool(true), "unset signals are nil");
    assert_eq!(r[1], i(42));
    assert_eq!(r[2], f(2.5));
    assert_eq!(r[3], s("text"));
    assert_eq!(r[4], Value::Bool(true), "bytes survive");
    assert_eq!(r[5], s("integer"));
    // Remote clients see the same signals.
    assert_eq!(sc.remote("getInt32Signal", &[s("i")]), vec![i(42)]);
    assert_eq!(sc.remote("getFloatSignal", &[s("f")]), vec![f(2.5)]);
    assert_eq!(
        sc.remote("getStringSignal", &[s("bin")]),
        vec![Value::Bytes(vec![0, 255, 1])]
    );
    sc.remote("setInt32Signal", &[s("fromRemote"), i(-7)]);
    assert_eq!(sc.remote("getInt32Signal", &[s("fromRemote")]), vec![i(-7)]);
    let c = sc.call("clear", &[]);
    assert_eq!(c, vec![Value::Bool(true); 4]);
    assert_eq!(sc.remote("getInt32Signal", &[s("i")]), vec![Value::Nil]);
    // No name: clear them all.
    sc.remote("clearStringSignal", &[]);
    assert_eq!(sc.remote("getStringSignal", &[s("bin")]), vec![Value::Nil]);

    let e = sc.call("e", &[]);
    assert_contains(text(&e[0]), &["(in function 'sim.setInt32Signal')"]);
    assert_contains(text(&e[1]), &["argument 2", "(in function 'sim.setInt32Signal')"]);
    assert_contains(text(&e[2]), &["argument 1", "(in function 'sim.setFloatSignal')"]);
    assert_contains(text(&e[3]), &["argument 1", "(in function 'sim.getStringSignal')"]);
}

// ---------------------------------------------------------------------------------------
// callScriptFunction

#[test]
fn call_script_function_between_two_scripts() {
    let toml = format!(
        "{}\n[[script]]\nobject = \"leftMotor\"\nfile = \"caller.lua\"\n",
        util::bubble_rob_toml(Some("callee.lua"))
    );
    let callee = "function add(a, b) calls = (calls or 0) + 1; return a + b, sim.getObject('.') end
        function count() return calls end";
    let caller = probe(
        "function t()
            local rob = sim.getObject('..')
            local s1, h1 = sim.callScriptFunction('add', rob, 2, 3)
            local s2 = sim.callScriptFunction('add@bubbleRob', sim.getScript(sim.scripttype_childscript, rob), 10, 20)
            return s1, h1, s2, sim.getObject('.'), add == nil
        end
        function e()
            local rob = sim.getObject('..')
            return err(sim.callScriptFunction, 'nope', rob), err(sim.callScriptFunction, 'add', sim.getObject('./leftWheel')),
                err(sim.callScriptFunction, 'add', rob, 'x', 1)
        end",
    );
    let mut sc = Scene::new(
        "callscript",
        &toml,
        &[("callee.lua", callee), ("caller.lua", &caller)],
        ScriptLimits::default(),
    );
    sc.sim.start();
    let (rob, left) = (sc.find("/bubbleRob"), sc.find("/bubbleRob/leftMotor"));
    let r = sc.call("t", &[]);
    assert_eq!(r, vec![i(5), i(rob), i(30), i(left), Value::Bool(true)]);
    // The same call remotely.
    assert_eq!(
        sc.remote("callScriptFunction", &[s("add"), i(rob), i(1), i(1)]),
        vec![i(2), i(rob)]
    );
    assert_eq!(sc.call("count", &[]), vec![i(3)]);
    let e = sc.call("e", &[]);
    for m in &e {
        assert_contains(text(m), &["(in function 'sim.callScriptFunction')"]);
    }
    assert!(sc.sim.call("callScriptFunction", &[s("nope"), i(rob)]).is_err());
}

// ---------------------------------------------------------------------------------------
// Constants

#[test]
fn constants_have_coppeliasim_values() {
    let mut sc = Scene::rover("constants", &probe("function c(name) return sim[name] end"));
    let expected: &[(&str, i64)] = &[
        ("handle_world", -1),
        ("handle_all", -2),
        ("handle_all_except_explicit", -3),
        ("handle_self", -4),
        ("handle_tree", -6),
        ("handle_chain", -7),
        ("handle_single", -8),
        ("handle_parent", -11),
        ("handle_scene", -12),
        ("handle_inverse", -14),
        ("object_shape_type", 0),
        ("object_joint_type", 1),
        ("object_graph_type", 2),
        ("object_dummy_type", 4),
        ("object_proximitysensor_type", 5),
        ("object_visionsensor_type", 9),
        ("object_forcesensor_type", 12),
        ("joint_revolute_subtype", 10),
        ("joint_prismatic_subtype", 11),
        ("joint_spherical_subtype", 12),
        ("proximitysensor_cone_subtype", 33),
        ("proximitysensor_ray_subtype", 34),
        ("simulation_stopped", 0),
        ("simulation_paused", 8),
        ("simulation_advancing_running", 17),
        ("verbosity_errors", 200),
        ("verbosity_warnings", 300),
        ("verbosity_scriptinfos", 450),
        ("scripttype_childscript", 1),
    ];
    for (name, value) in expected {
        assert_eq!(
            sc.call("c", &[s(name)]),
            vec![i(*value)],
            "sim.{name} should be {value}"
        );
    }
}

// ---------------------------------------------------------------------------------------
// Remote calls

#[test]
fn remote_calls_return_what_lua_returns() {
    let mut sc = Scene::rover("remote", &probe(""));
    for _ in 0..5 {
        sc.sim.step();
    }
    let rob = sc.find("/bubbleRob");
    let left = sc.find("/bubbleRob/leftMotor");
    let nose = sc.find("/bubbleRob/sensingNose");
    let force = sc.find("/bubbleRob/connection");
    let calls: Vec<(&str, Vec<Value>)> = vec![
        ("getObject", vec![s("/bubbleRob/leftMotor")]),
        ("getObject", vec![s("/obstacle"), Value::Map(vec![(s("index"), i(3))])]),
        ("getObjectAlias", vec![i(left), i(1)]),
        ("getObjectParent", vec![i(left)]),
        ("getObjectsInTree", vec![i(rob)]),
        ("getObjectType", vec![i(nose)]),
        ("getObjectPosition", vec![i(left)]),
        ("getObjectPosition", vec![i(left), i(rob)]),
        ("getObjectOrientation", vec![i(nose), i(-1)]),
        ("getObjectQuaternion", vec![i(nose)]),
        ("getObjectPose", vec![i(rob)]),
        ("getObjectMatrix", vec![i(nose), i(rob)]),
        ("getObjectVelocity", vec![i(rob)]),
        ("getJointPosition", vec![i(left)]),
        ("getJointInterval", vec![i(left)]),
        ("getJointType", vec![i(left)]),
        ("getJointTargetVelocity", vec![i(left)]),
        ("getJointForce", vec![i(left)]),
        ("getJointVelocity", vec![i(left)]),
        ("getSimulationTime", vec![]),
        ("getSimulationTimeStep", vec![]),
        ("getSimulationState", vec![]),
        ("readProximitySensor", vec![i(nose)]),
        ("readForceSensor", vec![i(force)]),
        ("checkDistance", vec![i(rob), i(-2)]),
        ("checkCollision", vec![i(rob), i(-2)]),
        ("getInt32Signal", vec![s("none")]),
    ];
    for (name, args) in calls {
        let mut lua_args = vec![s(name)];
        lua_args.extend(args.iter().cloned());
        let from_lua = sc.call("lua_call", &lua_args);
        let remote = sc.remote(name, &args);
        assert_eq!(from_lua, remote, "sim.{name}{args:?}");
        assert!(!remote.is_empty(), "sim.{name} returns something");
    }
    // Errors carry the same text.
    for (name, args) in [
        ("getObject", vec![s("/nothing")]),
        ("setJointPosition", vec![s("x"), i(1)]),
        ("setJointPosition", vec![i(rob), i(1)]),
        ("getJointPosition", vec![i(99999)]),
    ] {
        let mut lua_args = vec![s(name)];
        lua_args.extend(args.iter().cloned());
        let from_lua = sc.call("lua_err", &lua_args);
        let remote = sc.sim.call(name, &args).expect_err("remote call fails").to_string();
        assert_contains(text(&from_lua[0]), &[&remote]);
        assert_contains(&remote, &[&format!("(in function 'sim.{name}')")]);
    }
    // A remote client has no emitting object: '.' is nothing.
    assert!(sc.sim.call("getObject", &[s(".")]).is_err());
    assert_eq!(
        sc.remote(
            "getObject",
            &[s("."), Value::Map(vec![(s("noError"), Value::Bool(true))])]
        ),
        vec![i(-1)]
    );
    assert!(sc.sim.call("noSuchFunction", &[]).is_err());
}
