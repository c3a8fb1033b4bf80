//! [`ActionType`]: one known ROS 2 action type and the messages and services rcl_action
//! carries it on (its accessors, which read the registry, are in `codec.rs`).

/// A ROS 2 action type known to gantry (`example_interfaces/action/Fibonacci`).
///
/// An action `/name` travels as three services and two topics (rcl_action's layout):
/// `/name/_action/send_goal` ([`send_goal`](Self::send_goal)),
/// `/name/_action/get_result` ([`get_result`](Self::get_result)),
/// `/name/_action/cancel_goal` (`action_msgs/srv/CancelGoal`, the same for every action),
/// `/name/_action/feedback` ([`feedback_message`](Self::feedback_message)) and
/// `/name/_action/status` (`action_msgs/msg/GoalStatusArray`).
#[derive(Debug)]
pub struct ActionType {
    /// `pkg/action/Type`.
    name: String,
    /// Indices of the goal, result, feedback and feedback message types in the registry.
    goal: usize,
    result: usize,
    feedback: usize,
    feedback_message: usize,
    /// Indices of the send-goal and get-result services among the registry's services.
    send_goal: usize,
    get_result: usize,
}

/// Where an action type's parts are in the registry.
pub(crate) struct ActionParts {
    pub(crate) goal: usize,
    pub(crate) result: usize,
    pub(crate) feedback: usize,
    pub(crate) feedback_message: usize,
    pub(crate) send_goal: usize,
    pub(crate) get_result: usize,
}

impl ActionType {
    pub(crate) fn new(name: String, parts: ActionParts) -> ActionType {
        ActionType {
            name,
            goal: parts.goal,
            result: parts.result,
            feedback: parts.feedback,
            feedback_message: parts.feedback_message,
            send_goal: parts.send_goal,
            get_result: parts.get_result,
        }
    }

    /// The canonical name, `example_interfaces/action/Fibonacci`.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Registry indices: goal, result, feedback, feedback message types; send-goal and
    /// get-result services.
    pub(crate) fn parts(&self) -> (usize, usize, usize, usize, usize, usize) {
        (
            self.goal,
            self.result,
            self.feedback,
            self.feedback_message,
            self.send_goal,
            self.get_result,
        )
    }
}
