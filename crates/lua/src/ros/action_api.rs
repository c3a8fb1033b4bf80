//! The action functions of `simROS2` (`createActionServer`, `sendGoal`, ...) over the
//! state of `action.rs`; see there for how goals go.

use std::cell::{Cell, RefCell};

use gantry_protocol::Value;
use gantry_protocol::ros::{ActionType, action_topics, action_type};
use gantry_ros::{Direction, EndpointId, RosNetwork, RosQos};
use mlua::{Lua, MultiValue, Table, Value as LuaValue};

use super::action::{
    ActionClient, ActionServer, CANCEL_ACCEPT, CANCEL_REJECT, GOAL_ACCEPT_AND_DEFER, GOAL_ACCEPT_AND_EXECUTE,
    GOAL_REJECT, Pair, RESULT_ABORTED, RESULT_CANCELED, RESULT_SUCCEEDED, RESULT_UNKNOWN, cancel_service, key,
    status_array_type, status_qos, uuid_value,
};
use super::callback::Callback;
use super::error::RosError;
use super::goal::{GoalId, new_goal_id, parse_goal_id, status};
use super::host::{Endpoint, Kind, RosHost};
use super::lua_api::{
    CALL_TIMEOUT_S, Res, arg, callback_arg, handle_arg, next_guid, open_service_topics, running_object, string_arg,
    table_value, wait_matched,
};
use super::wire::{encode, request_header, time_value};
use crate::app_state::state;

/// Opens an action's endpoints; closes what it opened if one fails.
fn open_action(
    host: &RosHost,
    name: &str,
    ty: &ActionType,
    serving: bool,
) -> Result<(Pair, Pair, Pair, EndpointId, Option<EndpointId>), RosError> {
    let topics = action_topics(name)?;
    let mut opened: Vec<EndpointId> = Vec::new();
    let result = (|| {
        let mut pair = |t: (String, String), srv| -> Result<Pair, RosError> {
            let p = open_service_topics(host, t, srv, serving)?;
            opened.extend([p.0, p.1]);
            Ok(p)
        };
        let send_goal = pair(topics.send_goal, ty.send_goal())?;
        let cancel_goal = pair(topics.cancel_goal, cancel_service())?;
        let get_result = pair(topics.get_result, ty.get_result())?;
        let direction = if serving {
            Direction::Publish
        } else {
            Direction::Subscribe
        };
        let feedback = host.open(
            direction,
            topics.feedback,
            ty.feedback_message().dds_type_name(),
            RosQos::default(),
        )?;
        opened.push(feedback);
        // Only the server writes the status list; gantry's client follows goals through
        // their result requests instead.
        let status = if serving {
            let id = host.open(
                Direction::Publish,
                topics.status,
                status_array_type().dds_type_name(),
                status_qos(),
            )?;
            opened.push(id);
            Some(id)
        } else {
            None
        };
        Ok((send_goal, cancel_goal, get_result, feedback, status))
    })();
    if result.is_err()
        && let Ok(n) = host.network()
    {
        for id in opened {
            n.close(id);
        }
    }
    result
}

fn action_type_arg(args: &MultiValue) -> Result<(String, &'static ActionType), RosError> {
    let name = string_arg(args, 0, "the action name")?;
    let type_name = string_arg(args, 1, "the action type")?;
    let ty = action_type(&type_name)?;
    Ok((name, ty))
}

fn callbacks(lua: &Lua, args: &MultiValue) -> Result<[Callback; 3], RosError> {
    Ok([
        callback_arg(lua, args, 2)?,
        callback_arg(lua, args, 3)?,
        callback_arg(lua, args, 4)?,
    ])
}

/// `simROS2.createActionServer(name, type, handleGoal, handleCancel, handleAccepted)`.
pub(super) fn create_action_server(lua: &Lua, args: &MultiValue) -> Res {
    let (name, ty) = action_type_arg(args)?;
    let [handle_goal, handle_cancel, handle_accepted] = callbacks(lua, args)?;
    let host = state::<RosHost>(lua);
    let (send_goal, cancel_goal, get_result, feedback, status) = open_action(&host, &name, ty, true)?;
    let server = ActionServer {
        ty,
        send_goal,
        cancel_goal,
        get_result,
        feedback,
        status: status.unwrap_or_default(),
        handle_goal,
        handle_cancel,
        handle_accepted,
        goals: RefCell::new(Vec::new()),
    };
    // An empty list at once, so that clients see the server's status topic.
    if let Ok(n) = host.network() {
        server.publish_status(n.as_ref())?;
    }
    let h = host.insert(Endpoint {
        script: running_object(lua),
        kind: Kind::ActionServer(Box::new(server)),
    });
    Ok(vec![LuaValue::Integer(h)])
}

/// `simROS2.createActionClient(name, type, goalResponse, feedback, result)`.
pub(super) fn create_action_client(lua: &Lua, args: &MultiValue) -> Res {
    let (name, ty) = action_type_arg(args)?;
    let [goal_response, on_feedback, on_result] = callbacks(lua, args)?;
    let host = state::<RosHost>(lua);
    let (send_goal, cancel_goal, get_result, feedback, _) = open_action(&host, &name, ty, false)?;
    let h = host.insert(Endpoint {
        script: running_object(lua),
        kind: Kind::ActionClient(Box::new(ActionClient {
            ty,
            send_goal,
            cancel_goal,
            get_result,
            feedback,
            goal_response,
            on_feedback,
            on_result,
            guid: next_guid(),
            seq: Cell::new(0),
            sent: RefCell::new(Vec::new()),
            running: RefCell::new(Vec::new()),
            canceling: RefCell::new(Vec::new()),
            last_goal: Cell::new(None),
        })),
    });
    Ok(vec![LuaValue::Integer(h)])
}

/// Runs `f` on action server `h`, or says why not.
fn with_server<T>(
    lua: &Lua,
    h: i64,
    f: impl FnOnce(&ActionServer, &dyn RosNetwork) -> Result<T, RosError>,
) -> Result<T, RosError> {
    let host = state::<RosHost>(lua);
    host.network()?;
    host.with_action_server(h, f).unwrap_or(Err(RosError::WrongHandle {
        handle: h,
        expected: "an action server",
    }))
}

/// Runs `f` on action client `h`, or says why not.
fn with_client<T>(
    lua: &Lua,
    h: i64,
    f: impl FnOnce(&ActionClient, &dyn RosNetwork) -> Result<T, RosError>,
) -> Result<T, RosError> {
    let host = state::<RosHost>(lua);
    host.network()?;
    host.with_action_client(h, f).unwrap_or(Err(RosError::WrongHandle {
        handle: h,
        expected: "an action client",
    }))
}

fn goal_arg(args: &MultiValue) -> Result<GoalId, RosError> {
    let s = string_arg(args, 1, "the goal id")?;
    parse_goal_id(&s).ok_or(RosError::GoalIdFormat(s))
}

/// The state of goal `id` of a server.
fn goal_status(server: &ActionServer, id: &GoalId) -> Result<i8, RosError> {
    server
        .goals
        .borrow()
        .iter()
        .find(|g| &g.id == id)
        .map(|g| g.status)
        .ok_or(RosError::NoSuchGoal(*id))
}

/// `actionServerPublishFeedback(server, goalId, feedback)`: while the goal runs.
pub(super) fn publish_feedback(lua: &Lua, args: &MultiValue) -> Res {
    let h = handle_arg(args, 0)?;
    let id = goal_arg(args)?;
    let feedback = table_value(args, 2, "the feedback")?;
    with_server(lua, h, |s, net| {
        let st = goal_status(s, &id)?;
        if !matches!(st, status::EXECUTING | status::CANCELING) {
            return Err(RosError::GoalState {
                id,
                state: st,
                rule: "feedback is for executing goals",
            });
        }
        let msg = Value::Map(vec![(key("goal_id"), uuid_value(&id)), (key("feedback"), feedback)]);
        let body = encode(s.ty.feedback_message(), &msg)?;
        Ok(net.write(s.feedback, body)?)
    })?;
    Ok(vec![])
}

fn end_goal(lua: &Lua, args: &MultiValue, end: i8) -> Res {
    let h = handle_arg(args, 0)?;
    let id = goal_arg(args)?;
    let result = match arg(args, 2) {
        None => Value::Nil,
        Some(_) => table_value(args, 2, "the result")?,
    };
    with_server(lua, h, |s, net| s.finish(net, &id, end, result))?;
    Ok(vec![])
}

/// `actionServerActionSucceed(server, goalId, result)`.
pub(super) fn succeed(lua: &Lua, args: &MultiValue) -> Res {
    end_goal(lua, args, status::SUCCEEDED)
}

/// `actionServerActionAbort(server, goalId, result)`.
pub(super) fn abort(lua: &Lua, args: &MultiValue) -> Res {
    end_goal(lua, args, status::ABORTED)
}

/// `actionServerActionCanceled(server, goalId, result)`.
pub(super) fn canceled(lua: &Lua, args: &MultiValue) -> Res {
    end_goal(lua, args, status::CANCELED)
}

/// `actionServerActionExecute(server, goalId)`: a deferred goal starts executing.
pub(super) fn execute(lua: &Lua, args: &MultiValue) -> Res {
    let h = handle_arg(args, 0)?;
    let id = goal_arg(args)?;
    with_server(lua, h, |s, net| {
        {
            let mut goals = s.goals.borrow_mut();
            let g = goals.iter_mut().find(|g| g.id == id).ok_or(RosError::NoSuchGoal(id))?;
            if g.status != status::ACCEPTED {
                return Err(RosError::GoalState {
                    id,
                    state: g.status,
                    rule: "only a deferred goal can be executed",
                });
            }
            g.status = status::EXECUTING;
        }
        s.publish_status(net)
    })?;
    Ok(vec![])
}

fn is_in(lua: &Lua, args: &MultiValue, states: &[i8]) -> Res {
    let h = handle_arg(args, 0)?;
    let id = goal_arg(args)?;
    let st = with_server(lua, h, |s, _| goal_status(s, &id))?;
    Ok(vec![LuaValue::Boolean(states.contains(&st))])
}

/// `actionServerActionIsActive(server, goalId)`: accepted and not ended.
pub(super) fn is_active(lua: &Lua, args: &MultiValue) -> Res {
    is_in(lua, args, &[status::ACCEPTED, status::EXECUTING, status::CANCELING])
}

/// `actionServerActionIsCanceling(server, goalId)`.
pub(super) fn is_canceling(lua: &Lua, args: &MultiValue) -> Res {
    is_in(lua, args, &[status::CANCELING])
}

/// `actionServerActionIsExecuting(server, goalId)`.
pub(super) fn is_executing(lua: &Lua, args: &MultiValue) -> Res {
    is_in(lua, args, &[status::EXECUTING])
}

/// Waits (wall time, at most [`CALL_TIMEOUT_S`]) until an action client's server is
/// on the graph both ways for the services it uses.
fn server_ready(c: &ActionClient, net: &dyn RosNetwork) -> bool {
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs_f64(CALL_TIMEOUT_S);
    [c.send_goal, c.get_result, c.cancel_goal]
        .iter()
        .all(|(rq, rr)| wait_matched(net, *rq, deadline) && wait_matched(net, *rr, deadline))
}

/// `sendGoal(client, goal)`: sends a goal; whether it was sent (see the module docs).
pub(super) fn send_goal(lua: &Lua, args: &MultiValue) -> Res {
    let h = handle_arg(args, 0)?;
    let goal = table_value(args, 1, "the goal")?;
    let sent = with_client(lua, h, |c, net| {
        let id = new_goal_id();
        let seq = c.next_seq();
        let mut body = request_header(c.guid, seq);
        let msg = Value::Map(vec![(key("goal_id"), uuid_value(&id)), (key("goal"), goal)]);
        c.ty.send_goal()
            .request()
            .encode_into(&msg, &mut body, 0)
            .map_err(|source| RosError::BadField { arg: 2, source })?;
        if !server_ready(c, net) {
            tracing::warn!(
                "simROS2.sendGoal: no server of action {} answered within {CALL_TIMEOUT_S} s",
                c.ty.name()
            );
            return Ok(false);
        }
        net.write(c.send_goal.0, body)?;
        c.sent.borrow_mut().push((seq, id));
        c.last_goal.set(Some(id));
        Ok(true)
    })?;
    Ok(vec![LuaValue::Boolean(sent)])
}

/// `cancelLastGoal(client)`: asks the server to cancel the last goal sent; whether the
/// request was sent. The goal's result callback reports how it ended.
pub(super) fn cancel_last_goal(lua: &Lua, args: &MultiValue) -> Res {
    let h = handle_arg(args, 0)?;
    let sent = with_client(lua, h, |c, net| {
        let Some(id) = c.last_goal.get() else {
            return Err(RosError::NoGoalSent);
        };
        let seq = c.next_seq();
        let mut body = request_header(c.guid, seq);
        let msg = Value::Map(vec![(
            key("goal_info"),
            Value::Map(vec![(key("goal_id"), uuid_value(&id)), (key("stamp"), time_value(0.0))]),
        )]);
        cancel_service().request().encode_into(&msg, &mut body, 0)?;
        net.write(c.cancel_goal.0, body)?;
        c.canceling.borrow_mut().push(seq);
        Ok(true)
    })?;
    Ok(vec![LuaValue::Boolean(sent)])
}

/// Adds the `goal_response`, `cancel_response` and `action_result_code` constants.
pub(super) fn add_constants(lua: &Lua, t: &Table) -> mlua::Result<()> {
    let table = |entries: &[(&str, i64)]| -> mlua::Result<Table> {
        let t = lua.create_table()?;
        for (k, v) in entries {
            t.set(*k, *v)?;
        }
        Ok(t)
    };
    t.set(
        "goal_response",
        table(&[
            ("reject", GOAL_REJECT),
            ("accept_and_execute", GOAL_ACCEPT_AND_EXECUTE),
            ("accept_and_defer", GOAL_ACCEPT_AND_DEFER),
        ])?,
    )?;
    t.set(
        "cancel_response",
        table(&[("reject", CANCEL_REJECT), ("accept", CANCEL_ACCEPT)])?,
    )?;
    t.set(
        "action_result_code",
        table(&[
            ("succeeded", RESULT_SUCCEEDED),
            ("aborted", RESULT_ABORTED),
            ("canceled", RESULT_CANCELED),
            ("unknown", RESULT_UNKNOWN),
        ])?,
    )
}
