//! ROS 2 actions in `simROS2`: a script's action server and another script's action
//! client talk through the in-memory network with rcl_action's topics and wire types.
//! Goals are accepted or rejected by the server's callback, feedback reaches the
//! client's callback, results come back with simROS2's result codes, a cancel goes
//! through the cancel callback, the status list follows every change, and misuse is a
//! clear Lua error. (The real DDS transport is tested against Cyclone DDS, which plays
//! the other side of each, in tests/python/test_ros2.py.)

use crate::util;
use util::Drive;

use std::sync::Arc;

use gantry_lua::ScriptLimits;
use gantry_protocol::ros::message_type;
use gantry_sim_core::Value;
use gantry_test_support::assert_contains;
use util::loopback::Loopback;
use util::{Scene, assert_running};

const SCENE: &str = r#"
[simulation]
dt = 0.05

[[object]]
name = "server"
kind = "dummy"
script = "server.lua"

[[object]]
name = "client"
kind = "dummy"
script = "client.lua"
"#;

/// A Fibonacci server as CoppeliaSim's example writes one, one element per step.
const SERVER: &str = r#"
local simROS2 = require 'simROS2'
function handle_goal(id, goal)
    if goal.order > 20 then return simROS2.goal_response.reject end
    return simROS2.goal_response.accept_and_execute
end
function handle_cancel(id, goal)
    cancels = (cancels or 0) + 1
    return simROS2.cancel_response.accept
end
function handle_accepted(id, goal)
    current = {id = id, order = goal.order, seq = {0, 1}}
end
function sysCall_init()
    srv = simROS2.createActionServer('/fibonacci', 'example_interfaces/action/Fibonacci',
        handle_goal, 'handle_cancel', handle_accepted)
end
function sysCall_actuation()
    if not current then return end
    if simROS2.actionServerActionIsCanceling(srv, current.id) then
        simROS2.actionServerActionCanceled(srv, current.id, {sequence = current.seq})
        current = nil
        return
    end
    local n = #current.seq
    current.seq[n + 1] = current.seq[n] + current.seq[n - 1]
    simROS2.actionServerPublishFeedback(srv, current.id, {sequence = current.seq})
    if n + 1 >= current.order then
        local id = current.id
        simROS2.actionServerActionSucceed(srv, id, {sequence = current.seq})
        current = nil
        local ok, e = pcall(simROS2.actionServerActionSucceed, srv, id, {})
        again = e
        active = simROS2.actionServerActionIsActive(srv, id)
    end
end
function check()
    return again, active, cancels
end
"#;

/// A client that sends three goals in turn: one that succeeds, one the server rejects,
/// and one it cancels after two feedback messages.
const CLIENT: &str = r#"
local simROS2 = require 'simROS2'
responses, results, feedbacks, phase = {}, {}, 0, 1
function on_response(id, accepted)
    responses[#responses + 1] = #id .. (accepted and 'A' or 'R')
    if phase == 2 and not accepted then
        phase = 3
        simROS2.sendGoal(cli, {order = 15})
        feedbacks = 0
    end
end
function on_feedback(id, fb)
    feedbacks = feedbacks + 1
    if phase == 3 and feedbacks == 2 then
        phase = 4
        cancelSent = simROS2.cancelLastGoal(cli)
    end
end
function on_result(id, code, result)
    results[#results + 1] = code .. ':' .. table.concat(result.sequence, ',')
    if phase == 1 then
        phase = 2
        simROS2.sendGoal(cli, simROS2.createInterface('example_interfaces/action/FibonacciGoal'))
        simROS2.sendGoal(cli, {order = 99})
    end
end
function sysCall_init()
    cli = simROS2.createActionClient('/fibonacci', 'example_interfaces/action/Fibonacci',
        on_response, on_feedback, 'on_result')
    sent = simROS2.sendGoal(cli, {order = 6})
end
function report()
    return table.concat(responses, ';'), table.concat(results, ';'), sent, cancelSent or false
end
"#;

fn scene(tag: &str, server: &str, client: &str) -> (Scene, Arc<Loopback>) {
    let mut sc = Scene::new(
        tag,
        SCENE,
        &[("server.lua", server), ("client.lua", client)],
        ScriptLimits::default(),
    );
    let net = Arc::new(Loopback::default());
    sc.sim.set_ros_network(net.clone());
    (sc, net)
}

/// A decoded `GoalStatusArray` as `(goal id in hex, status)` pairs.
fn status_list(v: &Value) -> Vec<(String, i64)> {
    let Some(Value::Array(list)) = v.get("status_list") else {
        panic!("no status list in {v:?}")
    };
    list.iter()
        .map(|s| {
            let id = match s
                .get("goal_info")
                .and_then(|i| i.get("goal_id"))
                .and_then(|g| g.get("uuid"))
            {
                Some(Value::Bytes(b)) => b.iter().map(|x| format!("{x:02x}")).collect(),
                other => panic!("uuid {other:?}"),
            };
            let Some(Value::Int(st)) = s.get("status") else {
                panic!("no status in {s:?}")
            };
            (id, *st)
        })
        .collect()
}

/// The status lists the `/fibonacci` server published, in order.
fn status_lists(net: &Loopback) -> Vec<Vec<(String, i64)>> {
    status_lists_on(net, "rt/fibonacci/_action/status")
}

#[test]
fn a_script_serves_an_action_that_another_script_calls() {
    let (mut sc, net) = scene("ros-action", SERVER, CLIENT);
    sc.sim.start();
    for f in ["server.lua", "client.lua"] {
        assert_running(&sc.sim, f);
    }
    let topics = net.open_topics();
    for t in [
        "rq/fibonacci/_action/send_goalRequest",
        "rr/fibonacci/_action/send_goalReply",
        "rq/fibonacci/_action/cancel_goalRequest",
        "rr/fibonacci/_action/cancel_goalReply",
        "rq/fibonacci/_action/get_resultRequest",
        "rr/fibonacci/_action/get_resultReply",
        "rt/fibonacci/_action/feedback",
        "rt/fibonacci/_action/status",
    ] {
        assert!(topics.iter().any(|x| x == t), "{t} not in {topics:?}");
    }
    for _ in 0..60 {
        sc.sim.step();
    }
    for f in ["server.lua", "client.lua"] {
        assert_running(&sc.sim, f);
    }
    let report = sc.call("report", &[]);
    // Goal ids are 32 hex digits; the order-0 goal (a default FibonacciGoal) is
    // accepted and ends at once with {0, 1}; 99 is rejected; 15 is canceled.
    assert_eq!(report[0], Value::Str("32A;32A;32R;32A".into()), "goal responses");
    let Value::Str(results) = &report[1] else {
        panic!("{report:?}")
    };
    let results: Vec<&str> = results.split(';').collect();
    assert_eq!(results[0], "8564:0,1,1,2,3,5", "succeeded, with simROS2's result code");
    assert_eq!(results[1], "8564:0,1,1", "the default goal");
    assert!(results[2].starts_with("8566:0,1,1,2"), "canceled: {results:?}");
    assert_eq!(results.len(), 3);
    assert_eq!(report[2], Value::Bool(true), "sendGoal reports the goal sent");
    assert_eq!(report[3], Value::Bool(true), "cancelLastGoal reports the request sent");

    // Ending a goal twice is an error naming its state; it is no longer active.
    let check = sc.call("check", &[]);
    assert_contains(
        match &check[0] {
            Value::Str(s) => s,
            other => panic!("{other:?}"),
        },
        &[
            "goal",
            "is succeeded",
            "only an executing goal",
            "actionServerActionSucceed",
        ],
    );
    assert_eq!(check[1], Value::Bool(false), "an ended goal is not active");
    assert_eq!(check[2], Value::Int(1), "the cancel went through the cancel callback");
    let lists = status_lists(&net);
    let last = lists.last().expect("status published");
    let states: Vec<i64> = last.iter().map(|(_, s)| *s).collect();
    assert_eq!(
        states,
        [4, 4, 5],
        "succeeded, succeeded, canceled (the rejected goal is not held)"
    );
    assert!(
        lists.iter().any(|l| l.iter().any(|(_, s)| *s == 3)),
        "the canceled goal went through canceling"
    );
    assert!(last.iter().all(|(id, _)| id.len() == 32));
    sc.sim.stop();
    assert!(net.open_topics().is_empty(), "the run's endpoints closed with it");
}

/// A request as rmw_cyclonedds writes it: client id, sequence number, then the body.
fn request(guid: u64, seq: i64, body: &[u8]) -> Vec<u8> {
    let mut r = guid.to_le_bytes().to_vec();
    r.extend(seq.to_le_bytes());
    r.extend(body);
    r
}

/// The replies on `topic` to request `seq` of client `guid`, decoded with `decode`.
fn replies(net: &Loopback, topic: &str, guid: u64, seq: i64) -> Vec<Vec<u8>> {
    net.writes
        .lock()
        .unwrap()
        .iter()
        .filter(|(t, b)| t == topic && b[..8] == guid.to_le_bytes() && b[8..16] == seq.to_le_bytes())
        .map(|(_, b)| b.clone())
        .collect()
}

#[test]
fn deferred_goals_wire_replies_and_misuse() {
    let server = r#"
local simROS2 = require 'simROS2'
function sysCall_init()
    srv = simROS2.createActionServer('/fib', 'example_interfaces/Fibonacci',
        function(id, goal) return simROS2.goal_response.accept_and_defer end,
        function(id, goal) return simROS2.cancel_response.reject end,
        function(id, goal) deferred = id end)
end
function try(f, ...)
    local ok, e = pcall(f, ...)
    return e
end
function misuse()
    return try(simROS2.createActionServer, '/x', 'example_interfaces/action/Fibonaci', print, print, print),
        try(simROS2.actionServerActionSucceed, srv, 'xyz', {}),
        try(simROS2.actionServerActionSucceed, srv, string.rep('ab', 16), {}),
        try(simROS2.actionServerPublishFeedback, srv, deferred, {sequence = {1}}),
        try(simROS2.actionServerActionSucceed, srv, deferred, {}),
        try(simROS2.sendGoal, srv, {}),
        try(simROS2.actionServerActionSucceed, srv, deferred, {sequence = 'no'})
end
function run()
    simROS2.actionServerActionExecute(srv, deferred)
    simROS2.actionServerPublishFeedback(srv, deferred, {sequence = {7}})
    simROS2.actionServerActionAbort(srv, deferred, {sequence = {1, 2}})
    return simROS2.actionServerActionIsActive(srv, deferred)
end
"#;
    let (mut sc, net) = scene("ros-action-wire", server, "");
    sc.sim.start();
    assert_running(&sc.sim, "server.lua");
    let ty = gantry_protocol::ros::action_type("example_interfaces/action/Fibonacci").unwrap();
    let id: Vec<u8> = (1..=16).collect();
    let guid = 0x5EED_u64;
    // A goal from a remote client: 16 id bytes and `order`.
    let mut goal = id.clone();
    goal.extend(5i32.to_le_bytes());
    net.inject("rq/fib/_action/send_goalRequest", request(guid, 1, &goal));
    // Its result, asked for before it ends, is held.
    net.inject("rq/fib/_action/get_resultRequest", request(guid, 2, &id));
    // A cancel the server's callback refuses.
    let mut cancel = id.clone();
    cancel.extend([0; 8]);
    net.inject("rq/fib/_action/cancel_goalRequest", request(guid, 3, &cancel));
    // A result and a cancel for a goal nobody sent.
    net.inject("rq/fib/_action/get_resultRequest", request(guid, 4, &[9; 16]));
    let mut unknown = vec![9; 16];
    unknown.extend([0; 8]);
    net.inject("rq/fib/_action/cancel_goalRequest", request(guid, 5, &unknown));
    // Garbage is dropped.
    net.inject("rq/fib/_action/send_goalRequest", vec![1, 2, 3]);
    sc.sim.step();
    assert_running(&sc.sim, "server.lua");

    let accepted = replies(&net, "rr/fib/_action/send_goalReply", guid, 1);
    assert_eq!(accepted.len(), 1);
    let v = ty.send_goal().response().decode_body(&accepted[0], true, 16).unwrap();
    assert_eq!(v.get("accepted"), Some(&Value::Bool(true)));
    assert!(
        replies(&net, "rr/fib/_action/get_resultReply", guid, 2).is_empty(),
        "held"
    );
    let cancel_srv = gantry_protocol::ros::service_type("action_msgs/srv/CancelGoal").unwrap();
    let code = |seq| {
        let r = replies(&net, "rr/fib/_action/cancel_goalReply", guid, seq);
        let v = cancel_srv.response().decode_body(&r[0], true, 16).unwrap();
        v.get("return_code").cloned()
    };
    assert_eq!(code(3), Some(Value::Int(1)), "ERROR_REJECTED");
    assert_eq!(code(5), Some(Value::Int(2)), "ERROR_UNKNOWN_GOAL_ID");
    let unknown_result = replies(&net, "rr/fib/_action/get_resultReply", guid, 4);
    let v = ty
        .get_result()
        .response()
        .decode_body(&unknown_result[0], true, 16)
        .unwrap();
    assert_eq!(v.get("status"), Some(&Value::Int(0)), "STATUS_UNKNOWN");
    assert_eq!(
        status_lists_on(&net, "rt/fib/_action/status").last().unwrap(),
        &[("0102030405060708090a0b0c0d0e0f10".to_owned(), 1)],
        "deferred: accepted, not executing"
    );

    let errors = sc.call("misuse", &[]);
    let texts: Vec<String> = errors
        .iter()
        .map(|e| match e {
            Value::Str(s) => s.clone(),
            other => panic!("expected an error text, got {other:?}"),
        })
        .collect();
    assert_contains(
        &texts[0],
        &["unknown action type", "example_interfaces/action/Fibonacci"],
    );
    assert_contains(&texts[1], &["argument 2", "not 32 hex digits"]);
    assert_contains(&texts[2], &["abababababababababababababababab", "does not exist"]);
    assert_contains(&texts[3], &["accepted (deferred)", "feedback is for executing goals"]);
    assert_contains(&texts[4], &["actionServerActionExecute first"]);
    assert_contains(&texts[5], &["not an action client handle"]);
    assert_contains(&texts[6], &["sequence"]);

    assert_eq!(sc.call("run", &[]), [Value::Bool(false)]);
    let held = replies(&net, "rr/fib/_action/get_resultReply", guid, 2);
    assert_eq!(held.len(), 1, "the held result request is answered when the goal ends");
    let v = ty.get_result().response().decode_body(&held[0], true, 16).unwrap();
    assert_eq!(v.get("status"), Some(&Value::Int(6)), "STATUS_ABORTED");
    let fb = net
        .writes
        .lock()
        .unwrap()
        .iter()
        .filter(|(t, _)| t == "rt/fib/_action/feedback")
        .count();
    assert_eq!(fb, 1);
    // Asked again after the end, the result comes at once.
    net.inject("rq/fib/_action/get_resultRequest", request(guid, 6, &id));
    sc.sim.step();
    assert_eq!(replies(&net, "rr/fib/_action/get_resultReply", guid, 6).len(), 1);
}

fn status_lists_on(net: &Loopback, topic: &str) -> Vec<Vec<(String, i64)>> {
    let ty = message_type("action_msgs/msg/GoalStatusArray").unwrap();
    net.writes
        .lock()
        .unwrap()
        .iter()
        .filter(|(t, _)| t == topic)
        .map(|(_, body)| status_list(&ty.decode_body(body, true, 0).unwrap()))
        .collect()
}
