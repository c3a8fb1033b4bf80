//! [`RosError`]: why a `simROS2` or `simROS` function failed. Its text is what the
//! script sees: the API's error wrapper (`module.rs`) adds `(in function 'simROS2.x')`
//! and raises it from the caller's line.

use gantry_protocol::ros::{DecodeError, EncodeError, NameError, RosTypeError};
use gantry_ros::NetworkError;

use super::goal::{GoalId, goal_id_string, state_name};
use super::param_store::MAX_PARAMS;

/// Why a `simROS2` or `simROS` call failed (see the module docs). Arguments count from
/// 1, as in Lua.
#[derive(Debug, thiserror::Error)]
pub(crate) enum RosError {
    /// A required argument is nil or absent.
    #[error("argument {arg}: {what} is missing")]
    Missing { arg: usize, what: &'static str },
    /// An argument of the wrong Lua type, named by what it is for.
    #[error("argument {arg}: {what} must be {expected}, got {got}")]
    WrongType {
        arg: usize,
        what: &'static str,
        /// What it takes (`a string`, `a table`, `a function or its name`).
        expected: &'static str,
        /// The Lua type given.
        got: &'static str,
    },
    /// An argument that is not what the function takes (a Lua type, or a value such as
    /// `1.5` for an integer).
    #[error("argument {arg}: expected {expected}, got {got}")]
    Expected {
        arg: usize,
        expected: &'static str,
        got: String,
    },
    /// A string argument that is not UTF-8.
    #[error("argument {arg}: {what} is not UTF-8")]
    NotUtf8 { arg: usize, what: &'static str },
    /// A table argument that cannot become a message value (a function in it, a cycle).
    #[error("argument {arg}: {what}: {source}")]
    NotAMessage {
        arg: usize,
        what: &'static str,
        source: mlua::Error,
    },
    /// A whole-number argument outside its range (a negative image width).
    #[error("argument {arg}: {what} {value} is not valid")]
    OutOfRange { arg: usize, what: &'static str, value: i64 },
    /// A message argument (a goal, a result) that does not fit its ROS type; the codec's
    /// error has the field's path.
    #[error("argument {arg}: {source}")]
    BadField { arg: usize, source: EncodeError },
    /// A callback function that could not be kept in the Lua registry.
    #[error("argument {arg}: {source}")]
    CallbackNotKept { arg: usize, source: mlua::Error },
    /// A handle that is not an open endpoint of the kind the function needs.
    #[error("argument 1: {handle} is not {expected} handle")]
    WrongHandle {
        handle: i64,
        /// The kind with its article (`a publisher`, `an action server`).
        expected: &'static str,
    },
    /// `imageTransportPublish`: the data is not `width` x `height` rgb8 pixels.
    #[error("argument 2: a {width} x {height} rgb8 image has {expected} bytes, got {got}")]
    ImageSize {
        width: u32,
        height: u32,
        expected: u64,
        got: usize,
    },
    /// `sendTransforms` given a table that is not an array.
    #[error("argument 1: the transforms must be an array of geometry_msgs/TransformStamped tables")]
    TransformsNotAnArray,

    /// A queue size (history depth) that does not fit.
    #[error("queue size {0} is not valid")]
    QueueSize(i64),
    /// `qos.depth` that does not fit.
    #[error("qos.depth {0} is not valid")]
    QosDepth(i64),
    /// A QoS table entry that is not an integer.
    #[error("qos.{key} must be an integer, got {got}")]
    QosNotAnInteger { key: &'static str, got: &'static str },
    /// A QoS policy (`history`, `reliability`, `durability`) outside its
    /// `simROS2.qos_*_policy` values.
    #[error("qos.{policy} {value} is not a simROS2.qos_{policy}_policy value")]
    QosPolicy { policy: &'static str, value: i64 },
    /// The QoS argument is neither a number nor a table.
    #[error("the queue size or QoS must be a number or a table, got {got}")]
    QosKind { got: &'static str },

    /// A message, service or action type gantry does not know.
    #[error(transparent)]
    UnknownType(#[from] RosTypeError),
    /// A topic, service or action name that does not map to DDS.
    #[error(transparent)]
    Name(#[from] NameError),
    /// The network refused (or there is none in this embedding).
    #[error(transparent)]
    Network(#[from] NetworkError),
    /// A message that does not fit its type; the codec's error has the field's path.
    #[error(transparent)]
    Encode(#[from] EncodeError),
    /// Lua failed (a value could not be made, a table could not be read).
    #[error(transparent)]
    Lua(#[from] mlua::Error),

    /// `call`: no server matched within `timeout_s` (wall time).
    #[error("no server of service {service} answered within {timeout_s} s")]
    NoServer { service: String, timeout_s: f64 },
    /// `call`: the server matched but sent no reply within `timeout_s`.
    #[error("no reply from service {service} within {timeout_s} s")]
    NoReply { service: String, timeout_s: f64 },
    /// `call`: the reply does not decode as the service's response.
    #[error("the reply is malformed: {0}")]
    MalformedReply(DecodeError),

    /// A goal id argument that is not 32 hex digits.
    #[error("argument 2: goal id {0:?} is not 32 hex digits")]
    GoalIdFormat(String),
    /// A goal id argument the server does not hold.
    #[error("argument 2: goal {} does not exist", goal_id_string(.0))]
    NoSuchGoal(GoalId),
    /// A goal to end that the server does not hold (`actionServerActionSucceed`, ...).
    #[error("goal {} does not exist", goal_id_string(.0))]
    NoGoalToEnd(GoalId),
    /// A goal whose state does not allow the call; `rule` says which states do.
    #[error("goal {} is {}: {rule}", goal_id_string(.id), state_name(*.state))]
    GoalState {
        id: GoalId,
        /// Its state (`goal::status`).
        state: i8,
        rule: &'static str,
    },
    /// `cancelLastGoal` before any `sendGoal`.
    #[error("this action client has sent no goal")]
    NoGoalSent,
    /// An ended goal's result does not fit the action's result type.
    #[error("the result is not valid: {0}")]
    InvalidResult(EncodeError),

    /// `simROS.setParam*` and friends: a name that needs a node namespace.
    #[error("argument 1: parameter name {0:?} is not valid here (no node namespace)")]
    ParamName(String),
    /// `simROS.setParam*`: the parameter server is full.
    #[error("more than {MAX_PARAMS} parameters; delete some with simROS.deleteParam")]
    TooManyParams,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The texts scripts saw when each was built by `format!` where it failed.
    #[test]
    fn texts_are_the_ones_scripts_saw() {
        let id: GoalId = [0xab; 16];
        let cases: Vec<(RosError, String)> = vec![
            (
                RosError::Missing {
                    arg: 2,
                    what: "the message",
                },
                "argument 2: the message is missing".into(),
            ),
            (
                RosError::WrongType {
                    arg: 3,
                    what: "the callback",
                    expected: "a function or its name",
                    got: "number",
                },
                "argument 3: the callback must be a function or its name, got number".into(),
            ),
            (
                RosError::Expected {
                    arg: 2,
                    expected: "an integer",
                    got: 1.5f64.to_string(),
                },
                "argument 2: expected an integer, got 1.5".into(),
            ),
            (
                RosError::OutOfRange {
                    arg: 3,
                    what: "the width",
                    value: -1,
                },
                "argument 3: the width -1 is not valid".into(),
            ),
            (
                RosError::WrongHandle {
                    handle: 12345,
                    expected: "a publisher",
                },
                "argument 1: 12345 is not a publisher handle".into(),
            ),
            (
                RosError::ImageSize {
                    width: 4,
                    height: 2,
                    expected: 24,
                    got: 3,
                },
                "argument 2: a 4 x 2 rgb8 image has 24 bytes, got 3".into(),
            ),
            (
                RosError::QosPolicy {
                    policy: "reliability",
                    value: 9,
                },
                "qos.reliability 9 is not a simROS2.qos_reliability_policy value".into(),
            ),
            (
                RosError::NoServer {
                    service: "std_srvs/srv/SetBool".into(),
                    timeout_s: 5.0,
                },
                "no server of service std_srvs/srv/SetBool answered within 5 s".into(),
            ),
            (
                RosError::GoalIdFormat("xyz".into()),
                "argument 2: goal id \"xyz\" is not 32 hex digits".into(),
            ),
            (
                RosError::NoSuchGoal(id),
                "argument 2: goal abababababababababababababababab does not exist".into(),
            ),
            (
                RosError::NoGoalToEnd(id),
                "goal abababababababababababababababab does not exist".into(),
            ),
            (
                RosError::GoalState {
                    id,
                    state: crate::ros::goal::status::ACCEPTED,
                    rule: "feedback is for executing goals",
                },
                "goal abababababababababababababababab is accepted (deferred): feedback is for executing goals".into(),
            ),
            (
                RosError::ParamName("~x".into()),
                "argument 1: parameter name \"~x\" is not valid here (no node namespace)".into(),
            ),
            (
                RosError::TooManyParams,
                format!("more than {MAX_PARAMS} parameters; delete some with simROS.deleteParam"),
            ),
            (RosError::Network(NetworkError("closed".into())), "closed".into()),
        ];
        for (e, text) in cases {
            assert_eq!(e.to_string(), text);
        }
    }
}
