//! `simROS2` and `simROS` in the Lua host, on an in-memory network that delivers each
//! write to every subscription of the same DDS topic (the real DDS transport is tested
//! against Cyclone DDS in tests/python/test_ros2.py). Scripts publish, subscribe with
//! callbacks by function and by name (called on the simulation's own step, in the
//! subscribing script), serve and call services with rmw_cyclonedds' request header,
//! and get clear Lua errors for unknown types, wrong fields and bad handles. Endpoints
//! close when the simulation stops.

use crate::util;
use util::Drive;

use std::sync::Arc;

use gantry_lua::{ScriptLimits, ScriptState};
use gantry_sim_core::Value;
use gantry_test_support::assert_contains;
use util::loopback::Loopback;
use util::{Scene, assert_running, int32_signal, script_error, script_state};

const SCENE: &str = r#"
[simulation]
dt = 0.05

[[object]]
name = "talker"
kind = "dummy"
script = "talker.lua"

[[object]]
name = "listener"
kind = "dummy"
script = "listener.lua"
"#;

const TALKER: &str = r#"
local simROS2 = require 'simROS2'
function sysCall_init()
    pub = simROS2.createPublisher('/chatter', 'std_msgs/msg/String')
    twistPub = simROS2.createPublisher('cmd_vel', 'geometry_msgs/msg/Twist', 5)
    n = 0
end
function sysCall_sensing()
    n = n + 1
    simROS2.publish(pub, {data = 'hello ' .. n})
    simROS2.publish(twistPub, {linear = {x = n}, angular = {z = -n}})
end
"#;

const LISTENER: &str = r#"
function onString(msg)
    last = msg.data
    count = (count or 0) + 1
    sim.setInt32Signal('strings', count)
    sim.setStringSignal('last', last)
    sim.setInt32Signal('inListener', sim.getObject('.') == me and 1 or 0)
end
function sysCall_init()
    me = sim.getObject('.')
    sub = simROS2.createSubscription('/chatter', 'std_msgs/msg/String', onString)
    twistSub = simROS2.createSubscription('/cmd_vel', 'geometry_msgs/msg/Twist', 'onTwist')
end
function onTwist(msg)
    sim.setFloatSignal('vx', msg.linear.x)
    sim.setFloatSignal('wz', msg.angular.z)
    sim.setFloatSignal('vy', msg.linear.y)
end
"#;

fn string_signal(sc: &mut Scene, name: &str) -> String {
    match sc.remote("getStringSignal", &[Value::Str(name.into())]).first() {
        Some(Value::Str(s)) => s.clone(),
        Some(Value::Bytes(b)) => String::from_utf8_lossy(b).into_owned(),
        other => panic!("no string signal {name}: {other:?}"),
    }
}

fn float_signal(sc: &mut Scene, name: &str) -> f64 {
    match sc.remote("getFloatSignal", &[Value::Str(name.into())]).first() {
        Some(v) => v.as_f64().unwrap_or_else(|| panic!("{name}: {v:?}")),
        None => panic!("no float signal {name}"),
    }
}

fn scene(tag: &str, files: &[(&str, &str)]) -> (Scene, Arc<Loopback>) {
    let mut sc = Scene::new(tag, SCENE, files, ScriptLimits::default());
    let net = Arc::new(Loopback::default());
    sc.sim.set_ros_network(net.clone());
    (sc, net)
}

#[test]
fn scripts_talk_through_topics_and_callbacks_run_in_the_subscriber() {
    let (mut sc, net) = scene("ros-talk", &[("talker.lua", TALKER), ("listener.lua", LISTENER)]);
    sc.sim.start();
    for f in ["talker.lua", "listener.lua"] {
        assert_running(&sc.sim, f);
    }
    assert_eq!(
        net.open_topics(),
        ["rt/chatter", "rt/chatter", "rt/cmd_vel", "rt/cmd_vel"],
        "relative names resolve against /"
    );
    // Step 1's sensing publishes; step 2 delivers before actuation.
    sc.sim.step();
    sc.sim.step();
    sc.sim.step();
    assert_eq!(int32_signal(&mut sc.sim, "strings"), Some(2));
    assert_eq!(string_signal(&mut sc, "last"), "hello 2");
    assert_eq!(int32_signal(&mut sc.sim, "inListener"), Some(1));
    assert_eq!(float_signal(&mut sc, "vx"), 2.0);
    assert_eq!(float_signal(&mut sc, "wz"), -2.0);
    assert_eq!(float_signal(&mut sc, "vy"), 0.0, "missing fields take ROS's defaults");
    // What went on the wire is plain CDR of std_msgs/String.
    let writes = net.writes.lock().unwrap().clone();
    let (_, first) = writes.iter().find(|(t, _)| t == "rt/chatter").expect("a chatter write");
    assert_eq!(first, &[8, 0, 0, 0, b'h', b'e', b'l', b'l', b'o', b' ', b'1', 0]);
    sc.sim.stop();
    assert!(net.open_topics().is_empty(), "the run's endpoints closed with it");
}

#[test]
fn bad_messages_types_and_handles_are_clear_lua_errors() {
    let probe = r#"
function try(f, ...)
    local ok, err = pcall(f, ...)
    return ok and 'ok' or tostring(err)
end
function sysCall_init()
    local pub = simROS2.createPublisher('/p', 'geometry_msgs/msg/Twist')
    sim.setStringSignal('field', try(simROS2.publish, pub, {linear = {q = 1}}))
    sim.setStringSignal('kind', try(simROS2.publish, pub, {linear = {x = 'fast'}}))
    sim.setStringSignal('type', try(simROS2.createPublisher, '/p', 'foo_msgs/msg/Bar'))
    sim.setStringSignal('range', try(function()
        local p = simROS2.createPublisher('/u', 'std_msgs/msg/UInt8')
        simROS2.publish(p, {data = 300})
    end))
    sim.setStringSignal('handle', try(simROS2.publish, 12345, {}))
    sim.setStringSignal('name', try(simROS2.createPublisher, '/bad//name', 'std_msgs/msg/Bool'))
    sim.setStringSignal('cb', try(simROS2.createSubscription, '/s', 'std_msgs/msg/Bool', 42))
    sim.setStringSignal('qos', try(simROS2.createPublisher, '/q', 'std_msgs/msg/Bool', {reliability = 9}))
end
"#;
    let (mut sc, _net) = scene("ros-errors", &[("talker.lua", probe), ("listener.lua", "")]);
    sc.sim.start();
    assert_running(&sc.sim, "talker.lua");
    let expect: &[(&str, &[&str])] = &[
        ("field", &["geometry_msgs/msg/Twist", "linear.q", "simROS2.publish"]),
        ("kind", &["linear.x", "number", "string"]),
        ("type", &["foo_msgs/msg/Bar", "simROS2.createPublisher"]),
        ("range", &["300", "uint8", "data"]),
        ("handle", &["12345", "not a publisher"]),
        ("name", &["/bad//name"]),
        ("cb", &["callback", "number"]),
        ("qos", &["reliability", "9"]),
    ];
    for (signal, parts) in expect {
        assert_contains(string_signal(&mut sc, signal), parts);
    }
}

#[test]
fn a_script_serves_a_service_and_replies_carry_the_request_header() {
    let server = r#"
function sysCall_init()
    srv = simROS2.createService('/set_flag', 'std_srvs/srv/SetBool', function(req)
        sim.setInt32Signal('flag', req.data and 1 or 0)
        return {success = true, message = 'flag ' .. tostring(req.data)}
    end)
end
"#;
    let (mut sc, net) = scene("ros-service", &[("talker.lua", server), ("listener.lua", "")]);
    sc.sim.start();
    assert_running(&sc.sim, "talker.lua");
    assert_eq!(net.open_topics(), ["rq/set_flagRequest", "rr/set_flagReply"]);
    // A request as rmw_cyclonedds writes it: client id, sequence number, then `data`.
    let mut req = Vec::new();
    req.extend_from_slice(&0xABCD_u64.to_le_bytes());
    req.extend_from_slice(&42_i64.to_le_bytes());
    req.push(1);
    net.inject("rq/set_flagRequest", req);
    sc.sim.step();
    assert_eq!(int32_signal(&mut sc.sim, "flag"), Some(1));
    let writes = net.writes.lock().unwrap().clone();
    let (_, reply) = writes.iter().find(|(t, _)| t == "rr/set_flagReply").expect("a reply");
    assert_eq!(&reply[..8], &0xABCD_u64.to_le_bytes());
    assert_eq!(&reply[8..16], &42_i64.to_le_bytes());
    let resp = gantry_protocol::ros::service_type("std_srvs/srv/SetBool")
        .unwrap()
        .response()
        .decode_body(reply, true, 16)
        .unwrap();
    assert_eq!(resp.get("success"), Some(&Value::Bool(true)));
    assert_eq!(resp.get("message"), Some(&Value::Str("flag true".into())));
    // A malformed request is dropped; the server keeps serving.
    net.inject("rq/set_flagRequest", vec![1, 2, 3]);
    sc.sim.step();
    assert_running(&sc.sim, "talker.lua");
}

#[test]
fn ros1_names_publish_on_the_ros2_graph() {
    let ros1 = r#"
function sysCall_init()
    pub = simROS.advertise('/flag', 'std_msgs/Bool')
    sub = simROS.subscribe('/flag', 'std_msgs/Bool', 'onFlag')
    sim.setFloatSignal('t', simROS.getTime())
end
function sysCall_sensing() simROS.publish(pub, {data = true}) end
function onFlag(msg) sim.setInt32Signal('flag', msg.data and 1 or 0) end
"#;
    let (mut sc, net) = scene("ros-one", &[("talker.lua", ros1), ("listener.lua", "")]);
    sc.sim.start();
    assert_running(&sc.sim, "talker.lua");
    assert_eq!(net.open_topics(), ["rt/flag", "rt/flag"]);
    sc.sim.step();
    sc.sim.step();
    assert_eq!(int32_signal(&mut sc.sim, "flag"), Some(1));
    assert_eq!(
        float_signal(&mut sc, "t"),
        0.0,
        "simROS.getTime is simulation time, a number"
    );
}

#[test]
fn without_a_network_the_functions_say_why_and_require_works() {
    let script = r#"
local r = require 'simROS2'
function sysCall_init()
    sim.setInt32Signal('same', r == simROS2 and 1 or 0)
    local t = simROS2.timeFromFloat(1.25)
    sim.setInt32Signal('sec', t.sec)
    sim.setInt32Signal('nanosec', t.nanosec)
    local m = simROS2.createInterface('geometry_msgs/msg/Pose')
    sim.setFloatSignal('w', m.orientation.w)
    local c = {data = 'x', n = {1, 2}}
    c.self = c
    sim.setStringSignal('tostring', table.tostring(c))
    simROS2.createPublisher('/x', 'std_msgs/msg/Bool')
end
"#;
    let mut sc = Scene::new(
        "ros-none",
        SCENE,
        &[("talker.lua", script), ("listener.lua", "")],
        ScriptLimits::default(),
    );
    sc.sim.start();
    assert_eq!(int32_signal(&mut sc.sim, "same"), Some(1));
    assert_eq!(int32_signal(&mut sc.sim, "sec"), Some(1));
    assert_eq!(int32_signal(&mut sc.sim, "nanosec"), Some(250_000_000));
    assert_eq!(float_signal(&mut sc, "w"), 1.0, "a default quaternion is the identity");
    assert_eq!(
        string_signal(&mut sc, "tostring"),
        r#"{data="x", n={1, 2}, self=<cycle>}"#,
        "CoppeliaSim's table.tostring, which its ROS 2 examples log messages with"
    );
    assert!(matches!(script_state(&sc.sim, "talker.lua"), ScriptState::Errored(_)));
    assert_contains(
        script_error(&sc.sim, "talker.lua"),
        &["simROS2.createPublisher", "no ROS 2 network", "gantry run"],
    );
}

#[test]
fn the_lua_modules_have_exactly_the_registry_functions() {
    let names = r#"
function names(m)
    local t = {}
    for k, v in pairs(_G[m]) do if type(v) == 'function' then t[#t + 1] = k end end
    table.sort(t)
    return table.concat(t, ',')
end
"#;
    let mut sc = Scene::new(
        "ros-names",
        SCENE,
        &[("talker.lua", names), ("listener.lua", "")],
        ScriptLimits::default(),
    );
    sc.sim.start();
    for (module, listed) in [
        ("simROS2", gantry_lua::ros::FUNCTIONS),
        ("simROS", gantry_lua::ros::ROS1_FUNCTIONS),
    ] {
        let seen = sc.call("names", &[Value::Str(module.into())]);
        let registry = gantry_sim_core::api::HOST_MODULES
            .iter()
            .find(|m| m.name == module)
            .expect("in the registry");
        let in_registry: Vec<&str> = registry.functions.iter().map(|f| f.name).collect();
        assert_eq!(seen, [Value::Str(in_registry.join(","))], "{module}");
        assert_eq!(in_registry, listed, "{module}");
    }
}

#[test]
fn image_transport_publishes_rgb8_images_and_checks_their_size() {
    let script = r#"
function sysCall_init()
    pub = simROS2.imageTransportCreatePublisher('/camera/image')
    simROS2.imageTransportPublish(pub, string.rep('\1\2\3', 4 * 2), 4, 2, 'cam')
    local ok, err = pcall(simROS2.imageTransportPublish, pub, 'abc', 4, 2, 'cam')
    sim.setStringSignal('size', tostring(err))
end
"#;
    let (mut sc, net) = scene("ros-image", &[("talker.lua", script), ("listener.lua", "")]);
    sc.sim.start();
    assert_running(&sc.sim, "talker.lua");
    let writes = net.writes.lock().unwrap().clone();
    let (topic, body) = writes.first().expect("an image");
    assert_eq!(topic, "rt/camera/image");
    let img = gantry_protocol::ros::message_type("sensor_msgs/msg/Image")
        .unwrap()
        .decode_body(body, true, 0)
        .unwrap();
    assert_eq!(img.get("encoding"), Some(&Value::Str("rgb8".into())));
    assert_eq!(img.get("width"), Some(&Value::Int(4)));
    assert_eq!(img.get("step"), Some(&Value::Int(12)));
    assert_eq!(img.get("data"), Some(&Value::Bytes([1, 2, 3].repeat(8))));
    assert_eq!(
        img.get("header").and_then(|h| h.get("frame_id")),
        Some(&Value::Str("cam".into()))
    );
    assert_contains(string_signal(&mut sc, "size"), &["4 x 2", "24 bytes", "got 3"]);
}

#[test]
fn ros1_parameters_are_kept_in_the_simulation_across_stops() {
    let setter = r#"
function sysCall_init()
    local _, runs = simROS.getParamInt('/runs', 0)
    simROS.setParamInt('/runs', runs + 1)
    if not simROS.hasParam('/robot/gain') then
        simROS.setParamDouble('/robot/gain', 2.5)
        simROS.setParamInt('robot/count', 3)
        simROS.setParamBool('/robot/enabled', true)
        simROS.setParamString('/robot/name', 'rover')
        simROS.setParamDouble('/tmp', 1)
        simROS.deleteParam('/tmp')
    end
end
"#;
    let getter = r#"
function sysCall_sensing()
    local a, gain = simROS.getParamDouble('/robot/gain', 0)
    local b, count = simROS.getParamInt('/robot/count', 0)
    local c, enabled = simROS.getParamBool('/robot/enabled', false)
    local d, name = simROS.getParamString('robot/name', '')
    local e, missing = simROS.getParamDouble('/tmp', -1)
    local f, wrongKind = simROS.getParamInt('/robot/name', 7)
    local ok, err = pcall(simROS.setParamInt, '/x', 1.5)
    result = table.concat({tostring(a), gain, tostring(b), count, tostring(c), tostring(enabled),
        tostring(d), name, tostring(e), missing, tostring(f), wrongKind,
        tostring(simROS.hasParam('/tmp'))}, ',')
    badInt = err
    local _, r = simROS.getParamInt('/runs', 0)
    runs = r
end
function report() return result, badInt, runs end
"#;
    let (mut sc, _net) = scene("ros-params", &[("talker.lua", setter), ("listener.lua", getter)]);
    for round in 0..2 {
        sc.sim.start();
        sc.sim.step();
        let r = sc.call("report", &[]);
        assert_eq!(
            r[0],
            Value::from("true,2.5,true,3,true,true,true,rover,false,-1,false,7,false"),
            "round {round}"
        );
        assert_contains(
            match &r[1] {
                Value::Str(s) => s,
                other => panic!("{other:?}"),
            },
            &["expected an integer, got 1.5", "simROS.setParamInt"],
        );
        // The second run finds what the first set, as a roscore keeps them.
        assert_eq!(r[2], Value::Int(round + 1), "runs counted across stops");
        sc.sim.stop();
    }
}

#[test]
fn simros2_names_from_before_the_renames_do_what_the_new_names_do() {
    let old = r#"
function cb(msg) sim.setStringSignal('got', msg.data) end
function sysCall_init()
    sub = simROS2.subscribe('/chatter', 'std_msgs/msg/String', 'cb')
    pub = simROS2.advertise('/echo', 'std_msgs/msg/String')
end
function sysCall_sensing() simROS2.publish(pub, {data = 'x'}) end
"#;
    let (mut sc, net) = scene("ros-old-names", &[("talker.lua", old), ("listener.lua", "")]);
    sc.sim.start();
    assert_eq!(net.open_topics(), ["rt/chatter", "rt/echo"]);
    // `hi`: a std_msgs/String body.
    net.inject("rt/chatter", vec![3, 0, 0, 0, b'h', b'i', 0]);
    sc.sim.step();
    assert_eq!(string_signal(&mut sc, "got"), "hi");
}
