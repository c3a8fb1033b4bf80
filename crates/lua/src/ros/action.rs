//! ROS 2 actions in `simROS2`: what an action server and an action client keep, over
//! rcl_action's layout (three services and two topics under `/name/_action/`, see
//! [`ActionType`]). The Lua functions are in `action_api.rs`.
//!
//! The server keeps each goal's state as rcl_action's state machine has it (accepted,
//! executing, canceling, then succeeded, canceled or aborted), publishes the status list
//! (transient local, so late clients see it) after every change, and answers result
//! requests when a goal ends. The client sends goals and turns replies, feedback and
//! results into the script's callbacks.
//!
//! Goal ids are 32 lowercase hex digits, as simROS2 writes them. Callbacks run on the
//! simulation thread, once per step before actuation (`ros_action_dispatch.rs`).
//! One difference from CoppeliaSim, on purpose: `sendGoal` does not block until the
//! server replies (it waits for the server to be discovered, at most
//! [`CALL_TIMEOUT_S`], then sends), and the goal response callback runs at the next
//! step. A blocking wait could never be answered by a server in the same simulation,
//! whose callbacks run on the same thread.

use std::cell::{Cell, RefCell};

use gantry_protocol::Value;
use gantry_protocol::ros::{ActionType, MsgType, message_type, service_type};
use gantry_ros::{EndpointId, RosNetwork, RosQos};

use super::callback::Callback;
use super::error::RosError;
use super::goal::{GoalId, status};
use super::wire::{encode, request_header, time_value};

/// simROS2's `goal_response` values (CoppeliaSim's enum numbers).
pub(crate) const GOAL_REJECT: i64 = 12856;
pub(crate) const GOAL_ACCEPT_AND_EXECUTE: i64 = 12857;
pub(crate) const GOAL_ACCEPT_AND_DEFER: i64 = 12858;
/// simROS2's `cancel_response` values.
pub(crate) const CANCEL_REJECT: i64 = 16099;
pub(crate) const CANCEL_ACCEPT: i64 = 16100;
/// simROS2's `action_result_code` values.
pub(crate) const RESULT_SUCCEEDED: i64 = 8564;
pub(crate) const RESULT_ABORTED: i64 = 8565;
pub(crate) const RESULT_CANCELED: i64 = 8566;
pub(crate) const RESULT_UNKNOWN: i64 = 8567;

/// `action_msgs/srv/CancelGoal` return codes.
pub(crate) mod cancel_code {
    pub(crate) const NONE: i64 = 0;
    pub(crate) const REJECTED: i64 = 1;
    pub(crate) const UNKNOWN_GOAL_ID: i64 = 2;
    pub(crate) const GOAL_TERMINATED: i64 = 3;
}

/// Ended goals a server keeps for late result requests (rcl_action keeps them for a
/// timeout; a count bounds memory and the status message instead).
pub(crate) const MAX_ENDED_GOALS: usize = 100;
/// Result requests held per unfinished goal; more are dropped (a client repeating
/// itself is answered through the ones kept).
pub(crate) const MAX_WAITING: usize = 64;

/// The simROS2 result code of an ended goal's status.
pub(crate) fn result_code(s: i8) -> i64 {
    match s {
        status::SUCCEEDED => RESULT_SUCCEEDED,
        status::ABORTED => RESULT_ABORTED,
        status::CANCELED => RESULT_CANCELED,
        _ => RESULT_UNKNOWN,
    }
}

pub(crate) fn key(k: &str) -> Value {
    Value::Str(k.to_owned())
}

/// `unique_identifier_msgs/UUID` of `id`.
pub(crate) fn uuid_value(id: &GoalId) -> Value {
    Value::Map(vec![(key("uuid"), Value::Bytes(id.to_vec()))])
}

/// The goal id in a decoded message's `field` (a `UUID`).
pub(crate) fn goal_id_of(msg: &Value, field: &str) -> Option<GoalId> {
    match msg.get(field)?.get("uuid")? {
        Value::Bytes(b) => b.as_slice().try_into().ok(),
        Value::Array(a) => {
            let v: Option<Vec<u8>> = a
                .iter()
                .map(|x| match x {
                    Value::Int(i) => u8::try_from(*i).ok(),
                    _ => None,
                })
                .collect();
            v?.as_slice().try_into().ok()
        }
        _ => None,
    }
}

/// Seconds of a decoded `builtin_interfaces/Time`.
pub(crate) fn time_of(v: Option<&Value>) -> f64 {
    let int = |k: &str| match v.and_then(|t| t.get(k)) {
        Some(Value::Int(i)) => *i as f64,
        _ => 0.0,
    };
    int("sec") + int("nanosec") * 1e-9
}

/// A service pair: `(requests, replies)` endpoints.
pub(crate) type Pair = (EndpointId, EndpointId);

/// One goal an action server holds.
pub(crate) struct ServerGoal {
    pub(crate) id: GoalId,
    /// The goal message, for the cancel callback.
    pub(crate) goal: Value,
    /// When it was accepted, s of simulation time.
    pub(crate) accepted_at: f64,
    pub(crate) status: i8,
    /// The result, once ended.
    pub(crate) result: Option<Value>,
    /// Result requests waiting for the end: their request headers.
    pub(crate) waiting: Vec<(u64, i64)>,
}

/// `createActionServer`'s state.
pub(crate) struct ActionServer {
    pub(crate) ty: &'static ActionType,
    pub(crate) send_goal: Pair,
    pub(crate) cancel_goal: Pair,
    pub(crate) get_result: Pair,
    pub(crate) feedback: EndpointId,
    pub(crate) status: EndpointId,
    pub(crate) handle_goal: Callback,
    pub(crate) handle_cancel: Callback,
    pub(crate) handle_accepted: Callback,
    /// Goals in the order they were accepted.
    pub(crate) goals: RefCell<Vec<ServerGoal>>,
}

/// `createActionClient`'s state.
pub(crate) struct ActionClient {
    pub(crate) ty: &'static ActionType,
    pub(crate) send_goal: Pair,
    pub(crate) cancel_goal: Pair,
    pub(crate) get_result: Pair,
    pub(crate) feedback: EndpointId,
    pub(crate) goal_response: Callback,
    pub(crate) on_feedback: Callback,
    pub(crate) on_result: Callback,
    /// This client's id in request headers, and its last sequence number.
    pub(crate) guid: u64,
    pub(crate) seq: Cell<i64>,
    /// Goals sent and not answered: `(sequence number, goal id)`.
    pub(crate) sent: RefCell<Vec<(i64, GoalId)>>,
    /// Goals accepted and not ended: `(sequence number of the result request, goal id)`.
    pub(crate) running: RefCell<Vec<(i64, GoalId)>>,
    /// Cancel requests not answered: their sequence numbers.
    pub(crate) canceling: RefCell<Vec<i64>>,
    /// The goal `cancelLastGoal` cancels.
    pub(crate) last_goal: Cell<Option<GoalId>>,
}

impl ActionServer {
    pub(crate) fn network_ids(&self) -> Vec<EndpointId> {
        let (a, b, c) = (self.send_goal, self.cancel_goal, self.get_result);
        vec![a.0, a.1, b.0, b.1, c.0, c.1, self.feedback, self.status]
    }

    /// Publishes every held goal's status (`action_msgs/msg/GoalStatusArray`).
    pub(crate) fn publish_status(&self, net: &dyn RosNetwork) -> Result<(), RosError> {
        let list = self
            .goals
            .borrow()
            .iter()
            .map(|g| {
                Value::Map(vec![
                    (
                        key("goal_info"),
                        Value::Map(vec![
                            (key("goal_id"), uuid_value(&g.id)),
                            (key("stamp"), time_value(g.accepted_at)),
                        ]),
                    ),
                    (key("status"), Value::Int(i64::from(g.status))),
                ])
            })
            .collect();
        let msg = Value::Map(vec![(key("status_list"), Value::Array(list))]);
        let body = encode(status_array_type(), &msg)?;
        Ok(net.write(self.status, body)?)
    }

    /// Replies to result request `header` for a goal in state `st` with `result`.
    pub(crate) fn send_result(
        &self,
        net: &dyn RosNetwork,
        header: (u64, i64),
        st: i8,
        result: Option<&Value>,
    ) -> Result<(), RosError> {
        let srv = self.ty.get_result();
        let mut body = request_header(header.0, header.1);
        let msg = Value::Map(vec![
            (key("status"), Value::Int(i64::from(st))),
            (key("result"), result.cloned().unwrap_or(Value::Nil)),
        ]);
        srv.response()
            .encode_into(&msg, &mut body, 0)
            .map_err(RosError::InvalidResult)?;
        Ok(net.write(self.get_result.1, body)?)
    }

    /// Ends goal `id` in state `end` with `result`: answers its waiting result requests,
    /// forgets the oldest ended goals beyond [`MAX_ENDED_GOALS`], publishes the status.
    pub(crate) fn finish(&self, net: &dyn RosNetwork, id: &GoalId, end: i8, result: Value) -> Result<(), RosError> {
        let mut body = Vec::new();
        self.ty
            .result()
            .encode_into(&result, &mut body, 0)
            .map_err(|source| RosError::BadField { arg: 3, source })?;
        let waiting = {
            let mut goals = self.goals.borrow_mut();
            let g = goals
                .iter_mut()
                .find(|g| &g.id == id)
                .ok_or(RosError::NoGoalToEnd(*id))?;
            let allowed = match end {
                status::CANCELED => g.status == status::CANCELING,
                _ => matches!(g.status, status::EXECUTING | status::CANCELING),
            };
            if !allowed {
                return Err(RosError::GoalState {
                    id: *id,
                    state: g.status,
                    rule: match end {
                        status::CANCELED => "only a goal being canceled can be marked canceled",
                        _ if g.status == status::ACCEPTED => {
                            "it was deferred; call simROS2.actionServerActionExecute first"
                        }
                        _ => "only an executing goal can succeed or abort",
                    },
                });
            }
            g.status = end;
            g.result = Some(result.clone());
            std::mem::take(&mut g.waiting)
        };
        for header in waiting {
            self.send_result(net, header, end, Some(&result))?;
        }
        let mut goals = self.goals.borrow_mut();
        let ended = goals.iter().filter(|g| status::terminal(g.status)).count();
        if ended > MAX_ENDED_GOALS {
            let mut excess = ended - MAX_ENDED_GOALS;
            goals.retain(|g| {
                let drop = excess > 0 && status::terminal(g.status);
                excess -= usize::from(drop);
                !drop
            });
        }
        drop(goals);
        self.publish_status(net)
    }
}

impl ActionClient {
    pub(crate) fn network_ids(&self) -> Vec<EndpointId> {
        let (a, b, c) = (self.send_goal, self.cancel_goal, self.get_result);
        vec![a.0, a.1, b.0, b.1, c.0, c.1, self.feedback]
    }

    /// The next request sequence number.
    pub(crate) fn next_seq(&self) -> i64 {
        self.seq.set(self.seq.get() + 1);
        self.seq.get()
    }
}

pub(crate) fn status_array_type() -> &'static MsgType {
    // Known to the codec: a missing entry is a bug caught by the tests.
    message_type("action_msgs/msg/GoalStatusArray").expect("action_msgs/msg/GoalStatusArray is a known type")
}

/// `action_msgs/srv/CancelGoal`, every action's cancel service.
pub(crate) fn cancel_service() -> &'static gantry_protocol::ros::SrvType {
    service_type("action_msgs/srv/CancelGoal").expect("action_msgs/srv/CancelGoal is a known type")
}

/// The action server status topic's QoS: reliable, transient local, keep last 1, so a
/// client that joins late sees the goals' states (rcl_action's status profile).
pub(crate) fn status_qos() -> RosQos {
    RosQos {
        reliable: true,
        transient_local: true,
        depth: 1,
    }
}
