//! Delivers what the ROS 2 graph sent to the scripts' action servers and clients
//! (`ros/action.rs`): once per step, after topic and service callbacks, on the
//! simulation thread.
//!
//! A server's goal and cancel requests go through the script's callbacks, whose answers
//! decide the reply and the goal's state; result requests are answered from the goals'
//! states without a callback (held until the goal ends). A client's replies, feedback
//! and results become its goal response, feedback and result callbacks; an accepted
//! goal's result is asked for at once, as rclcpp_action does.

use gantry_protocol::Value;
use gantry_protocol::ros::MsgType;
use gantry_ros::{RosNetwork, RosSample};
use gantry_sim_core::Handle;
use mlua::Value as LuaValue;

use crate::app_state::state;
use crate::host::LuaHost;
use crate::ros::action::{
    ActionClient, ActionServer, CANCEL_ACCEPT, GOAL_ACCEPT_AND_DEFER, GOAL_ACCEPT_AND_EXECUTE, GOAL_REJECT,
    MAX_WAITING, ServerGoal, cancel_code, cancel_service, goal_id_of, key, result_code, time_of, uuid_value,
};
use crate::ros::goal::{GoalId, goal_id_string, status};
use crate::ros::host::{Kind, RosHost};
use crate::ros::lua_api::sim_time;
use crate::ros::wire::{read_header, request_header, time_value};
use crate::ros_dispatch::{MAX_PER_STEP, Resolved, resolve};

/// One thing for a script to handle.
enum Event {
    /// A goal request to a server.
    Goal {
        server: i64,
        script: Option<Handle>,
        handle_goal: mlua::Result<Resolved>,
        handle_accepted: mlua::Result<Resolved>,
        header: (u64, i64),
        id: GoalId,
        goal: Value,
    },
    /// A cancel request to a server.
    Cancel {
        server: i64,
        script: Option<Handle>,
        handle_cancel: mlua::Result<Resolved>,
        header: (u64, i64),
        id: GoalId,
        stamp: f64,
    },
    /// A client callback with its arguments.
    Client {
        script: Option<Handle>,
        callback: mlua::Result<Resolved>,
        args: Vec<Value>,
    },
}

/// The requests received on `id`, each with its request header, decoded as `ty`.
fn requests(net: &dyn RosNetwork, id: u64, ty: &MsgType, what: &str) -> Vec<((u64, i64), Value)> {
    let mut out = Vec::new();
    for s in net.take(id, MAX_PER_STEP) {
        let Some(header) = read_header(&s.body, s.little_endian) else {
            continue;
        };
        match ty.decode_body(&s.body, s.little_endian, 16) {
            Ok(v) => out.push((header, v)),
            Err(e) => tracing::warn!("simROS2: dropped a malformed {what}: {e}"),
        }
    }
    out
}

/// A server's goal and cancel requests, as events.
fn server_events(
    lua: &mlua::Lua,
    h: i64,
    script: Option<Handle>,
    s: &ActionServer,
    net: &dyn RosNetwork,
    out: &mut Vec<Event>,
) {
    for (header, v) in requests(net, s.send_goal.0, s.ty.send_goal().request(), "goal request") {
        let Some(id) = goal_id_of(&v, "goal_id") else { continue };
        out.push(Event::Goal {
            server: h,
            script,
            handle_goal: resolve(lua, &s.handle_goal),
            handle_accepted: resolve(lua, &s.handle_accepted),
            header,
            id,
            goal: v.get("goal").cloned().unwrap_or(Value::Nil),
        });
    }
    for (header, v) in requests(net, s.cancel_goal.0, cancel_service().request(), "cancel request") {
        let info = v.get("goal_info");
        let id = info.and_then(|i| goal_id_of(i, "goal_id")).unwrap_or_default();
        out.push(Event::Cancel {
            server: h,
            script,
            handle_cancel: resolve(lua, &s.handle_cancel),
            header,
            id,
            stamp: time_of(info.and_then(|i| i.get("stamp"))),
        });
    }
}

/// Answers a server's result requests: at once for an ended goal (or one it does not
/// know), later for a running one. Called after the step's goal requests are handled,
/// so that a result request never overtakes its own goal.
fn answer_result_requests(s: &ActionServer, net: &dyn RosNetwork) {
    for (header, v) in requests(net, s.get_result.0, s.ty.get_result().request(), "result request") {
        let Some(id) = goal_id_of(&v, "goal_id") else { continue };
        let answer = {
            let mut goals = s.goals.borrow_mut();
            match goals.iter_mut().find(|g| g.id == id) {
                Some(g) if status::terminal(g.status) => Some((g.status, g.result.clone())),
                Some(g) => {
                    if g.waiting.len() < MAX_WAITING {
                        g.waiting.push(header);
                    }
                    None
                }
                None => Some((status::UNKNOWN, None)),
            }
        };
        if let Some((st, result)) = answer
            && let Err(e) = s.send_result(net, header, st, result.as_ref())
        {
            tracing::warn!("simROS2: action {}: result not sent: {e}", s.ty.name());
        }
    }
}

/// A client's replies, feedback and results, as callbacks to call.
fn client_events(
    lua: &mlua::Lua,
    script: Option<Handle>,
    c: &ActionClient,
    net: &dyn RosNetwork,
    out: &mut Vec<Event>,
) {
    let ours = |x: &RosSample| read_header(&x.body, x.little_endian).filter(|(g, _)| *g == c.guid);
    let srv = c.ty.send_goal();
    for s in net.take(c.send_goal.1, MAX_PER_STEP) {
        let Some((_, seq)) = ours(&s) else { continue };
        let Some(id) = take_pending(&c.sent, seq) else { continue };
        let accepted = match srv.response().decode_body(&s.body, s.little_endian, 16) {
            Ok(v) => v.get("accepted") == Some(&Value::Bool(true)),
            Err(e) => {
                tracing::warn!("simROS2: dropped a malformed goal response: {e}");
                continue;
            }
        };
        if accepted {
            let seq = c.next_seq();
            let mut body = request_header(c.guid, seq);
            let msg = Value::Map(vec![(key("goal_id"), uuid_value(&id))]);
            match c.ty.get_result().request().encode_into(&msg, &mut body, 0) {
                Ok(()) => match net.write(c.get_result.0, body) {
                    Ok(()) => c.running.borrow_mut().push((seq, id)),
                    Err(e) => tracing::warn!("simROS2: result request not sent: {e}"),
                },
                Err(e) => tracing::warn!("simROS2: result request not encoded: {e}"),
            }
        }
        out.push(Event::Client {
            script,
            callback: resolve(lua, &c.goal_response),
            args: vec![Value::Str(goal_id_string(&id)), Value::Bool(accepted)],
        });
    }
    let fb = c.ty.feedback_message();
    for s in net.take(c.feedback, MAX_PER_STEP) {
        let v = match fb.decode_body(&s.body, s.little_endian, 0) {
            Ok(v) => v,
            Err(e) => {
                tracing::warn!("simROS2: dropped a malformed feedback message: {e}");
                continue;
            }
        };
        let Some(id) = goal_id_of(&v, "goal_id") else { continue };
        // The feedback topic carries every client's goals: only this client's count.
        let mine = c.running.borrow().iter().any(|(_, g)| *g == id) || c.sent.borrow().iter().any(|(_, g)| *g == id);
        if mine {
            out.push(Event::Client {
                script,
                callback: resolve(lua, &c.on_feedback),
                args: vec![
                    Value::Str(goal_id_string(&id)),
                    v.get("feedback").cloned().unwrap_or(Value::Nil),
                ],
            });
        }
    }
    let get = c.ty.get_result();
    for s in net.take(c.get_result.1, MAX_PER_STEP) {
        let Some((_, seq)) = ours(&s) else { continue };
        let Some(id) = take_pending(&c.running, seq) else {
            continue;
        };
        match get.response().decode_body(&s.body, s.little_endian, 16) {
            Ok(v) => {
                let st = match v.get("status") {
                    Some(Value::Int(i)) => i8::try_from(*i).unwrap_or(status::UNKNOWN),
                    _ => status::UNKNOWN,
                };
                out.push(Event::Client {
                    script,
                    callback: resolve(lua, &c.on_result),
                    args: vec![
                        Value::Str(goal_id_string(&id)),
                        Value::Int(result_code(st)),
                        v.get("result").cloned().unwrap_or(Value::Nil),
                    ],
                });
            }
            Err(e) => tracing::warn!("simROS2: dropped a malformed result: {e}"),
        }
    }
    let cancel = cancel_service();
    for s in net.take(c.cancel_goal.1, MAX_PER_STEP) {
        let Some((_, seq)) = ours(&s) else { continue };
        let mut canceling = c.canceling.borrow_mut();
        let Some(i) = canceling.iter().position(|q| *q == seq) else {
            continue;
        };
        canceling.remove(i);
        if let Ok(v) = cancel.response().decode_body(&s.body, s.little_endian, 16)
            && let Some(Value::Int(code)) = v.get("return_code")
            && *code != cancel_code::NONE
        {
            tracing::warn!(
                "simROS2: action {}: the server refused to cancel (code {code})",
                c.ty.name()
            );
        }
    }
}

/// Removes and returns the goal of pending request `seq`.
fn take_pending(pending: &std::cell::RefCell<Vec<(i64, GoalId)>>, seq: i64) -> Option<GoalId> {
    let mut p = pending.borrow_mut();
    let i = p.iter().position(|(q, _)| *q == seq)?;
    Some(p.remove(i).1)
}

impl LuaHost {
    /// Handles every action request, reply and feedback received (see the module docs).
    pub(crate) fn dispatch_ros_actions(&mut self) {
        let events = {
            let host = state::<RosHost>(&self.lua);
            let Ok(net) = host.network() else { return };
            let mut out = Vec::new();
            for (h, e) in host.endpoints.borrow().iter() {
                match &e.kind {
                    Kind::ActionServer(s) => server_events(&self.lua, *h, e.script, s, net.as_ref(), &mut out),
                    Kind::ActionClient(c) => client_events(&self.lua, e.script, c, net.as_ref(), &mut out),
                    _ => {}
                }
            }
            out
        };
        for event in events {
            match event {
                Event::Goal {
                    server,
                    script,
                    handle_goal,
                    handle_accepted,
                    header,
                    id,
                    goal,
                } => self.goal_request(server, script, (handle_goal, handle_accepted), header, id, goal),
                Event::Cancel {
                    server,
                    script,
                    handle_cancel,
                    header,
                    id,
                    stamp,
                } => self.cancel_request(server, script, handle_cancel, header, id, stamp),
                Event::Client { script, callback, args } => {
                    self.call_ros_callback(script, callback, &args);
                }
            }
        }
        let host = state::<RosHost>(&self.lua);
        let Ok(net) = host.network() else { return };
        for e in host.endpoints.borrow().values() {
            if let Kind::ActionServer(s) = &e.kind {
                answer_result_requests(s, net.as_ref());
            }
        }
    }

    fn goal_request(
        &mut self,
        server: i64,
        script: Option<Handle>,
        (handle_goal, handle_accepted): (mlua::Result<Resolved>, mlua::Result<Resolved>),
        header: (u64, i64),
        id: GoalId,
        goal: Value,
    ) {
        let id_str = Value::Str(goal_id_string(&id));
        let answer = self.call_ros_callback(script, handle_goal, &[id_str.clone(), goal.clone()]);
        let initial = match &answer {
            Some((LuaValue::Integer(GOAL_ACCEPT_AND_EXECUTE), _)) => Some(status::EXECUTING),
            Some((LuaValue::Integer(GOAL_ACCEPT_AND_DEFER), _)) => Some(status::ACCEPTED),
            Some((LuaValue::Integer(GOAL_REJECT), _)) | None => None,
            Some((other, name)) => {
                let msg = format!(
                    "simROS2: the goal callback returned {other:?}, not a simROS2.goal_response value: goal rejected"
                );
                self.core.log(300, name, &msg);
                None
            }
        };
        let now = sim_time(&self.lua);
        let accepted = state::<RosHost>(&self.lua).with_action_server(server, |s, net| {
            let duplicate = s.goals.borrow().iter().any(|g| g.id == id);
            let accepted = initial.is_some() && !duplicate;
            let mut body = request_header(header.0, header.1);
            let reply = Value::Map(vec![
                (key("accepted"), Value::Bool(accepted)),
                (key("stamp"), time_value(now)),
            ]);
            if let Err(e) = s.ty.send_goal().response().encode_into(&reply, &mut body, 0) {
                tracing::warn!("simROS2: goal reply not encoded: {e}");
            } else if let Err(e) = net.write(s.send_goal.1, body) {
                tracing::warn!("simROS2: goal reply not sent: {e}");
            }
            if let (true, Some(st)) = (accepted, initial) {
                s.goals.borrow_mut().push(ServerGoal {
                    id,
                    goal: goal.clone(),
                    accepted_at: now,
                    status: st,
                    result: None,
                    waiting: Vec::new(),
                });
                if let Err(e) = s.publish_status(net) {
                    tracing::warn!("simROS2: goal status not sent: {e}");
                }
            }
            accepted
        });
        if accepted == Some(true) {
            self.call_ros_callback(script, handle_accepted, &[id_str, goal]);
        }
    }

    fn cancel_request(
        &mut self,
        server: i64,
        script: Option<Handle>,
        handle_cancel: mlua::Result<Resolved>,
        header: (u64, i64),
        id: GoalId,
        stamp: f64,
    ) {
        // rcl_action's rules: a zero id and zero stamp cancel every goal; a stamp cancels
        // the goals accepted at or before it; an id cancels that goal.
        let any_id = id == GoalId::default();
        let (candidates, known_ended) = state::<RosHost>(&self.lua)
            .with_action_server(server, |s, _| {
                let goals = s.goals.borrow();
                let matches = |g: &&ServerGoal| {
                    (any_id && stamp == 0.0) || (!any_id && g.id == id) || (stamp > 0.0 && g.accepted_at <= stamp)
                };
                let candidates: Vec<(GoalId, Value)> = goals
                    .iter()
                    .filter(matches)
                    .filter(|g| !status::terminal(g.status))
                    .map(|g| (g.id, g.goal.clone()))
                    .collect();
                let ended = goals.iter().filter(matches).any(|g| status::terminal(g.status));
                (candidates, ended)
            })
            .unwrap_or_default();
        let mut canceling = Vec::new();
        for (gid, goal) in &candidates {
            let answer = self.call_ros_callback(
                script,
                handle_cancel.clone(),
                &[Value::Str(goal_id_string(gid)), goal.clone()],
            );
            if matches!(answer, Some((LuaValue::Integer(CANCEL_ACCEPT), _))) {
                canceling.push(*gid);
            }
        }
        let code = if !canceling.is_empty() {
            cancel_code::NONE
        } else if !candidates.is_empty() {
            cancel_code::REJECTED
        } else if known_ended {
            cancel_code::GOAL_TERMINATED
        } else if !any_id {
            cancel_code::UNKNOWN_GOAL_ID
        } else {
            cancel_code::NONE
        };
        state::<RosHost>(&self.lua).with_action_server(server, |s, net| {
            let mut infos = Vec::new();
            for g in s.goals.borrow_mut().iter_mut() {
                if canceling.contains(&g.id) && matches!(g.status, status::ACCEPTED | status::EXECUTING) {
                    g.status = status::CANCELING;
                    infos.push(Value::Map(vec![
                        (key("goal_id"), uuid_value(&g.id)),
                        (key("stamp"), time_value(g.accepted_at)),
                    ]));
                }
            }
            let changed = !infos.is_empty();
            let reply = Value::Map(vec![
                (key("return_code"), Value::Int(code)),
                (key("goals_canceling"), Value::Array(infos)),
            ]);
            let mut body = request_header(header.0, header.1);
            let cancel = cancel_service();
            if let Err(e) = cancel.response().encode_into(&reply, &mut body, 0) {
                tracing::warn!("simROS2: cancel reply not encoded: {e}");
            } else if let Err(e) = net.write(s.cancel_goal.1, body) {
                tracing::warn!("simROS2: cancel reply not sent: {e}");
            }
            if changed && let Err(e) = s.publish_status(net) {
                tracing::warn!("simROS2: goal status not sent: {e}");
            }
        });
    }
}
