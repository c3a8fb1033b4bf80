//! A goal of a ROS 2 action, as `simROS2` names it: its id (16 bytes, written as 32
//! lowercase hex digits, as simROS2 writes them) and rcl_action's states. The servers and
//! clients that hold goals are in `action.rs`.

use std::sync::atomic::{AtomicU64, Ordering};

/// A goal's id: 16 bytes, `unique_identifier_msgs/UUID`.
pub(crate) type GoalId = [u8; 16];

/// rcl_action's goal states (`action_msgs/msg/GoalStatus`).
pub(crate) mod status {
    pub(crate) const UNKNOWN: i8 = 0;
    pub(crate) const ACCEPTED: i8 = 1;
    pub(crate) const EXECUTING: i8 = 2;
    pub(crate) const CANCELING: i8 = 3;
    pub(crate) const SUCCEEDED: i8 = 4;
    pub(crate) const CANCELED: i8 = 5;
    pub(crate) const ABORTED: i8 = 6;

    /// Whether a goal in state `s` has ended.
    pub(crate) fn terminal(s: i8) -> bool {
        s >= SUCCEEDED
    }
}

/// A goal state's name, for errors.
pub(crate) fn state_name(s: i8) -> &'static str {
    match s {
        status::ACCEPTED => "accepted (deferred)",
        status::EXECUTING => "executing",
        status::CANCELING => "canceling",
        status::SUCCEEDED => "succeeded",
        status::CANCELED => "canceled",
        status::ABORTED => "aborted",
        _ => "unknown",
    }
}

/// `goal_id` as simROS2 writes it: 32 lowercase hex digits.
pub(crate) fn goal_id_string(id: &GoalId) -> String {
    id.iter().map(|b| format!("{b:02x}")).collect()
}

/// A goal id from its 32 hex digits; `None` if `s` is not that.
pub(crate) fn parse_goal_id(s: &str) -> Option<GoalId> {
    if s.len() != 32 || !s.chars().all(|c| c.is_ascii_hexdigit()) {
        return None;
    }
    let mut id = [0u8; 16];
    for (i, b) in id.iter_mut().enumerate() {
        *b = u8::from_str_radix(&s[2 * i..2 * i + 2], 16).ok()?;
    }
    Some(id)
}

/// A fresh goal id: unique in this process, random across processes (ids only need to
/// differ, not to be secret).
pub(crate) fn new_goal_id() -> GoalId {
    use std::hash::{BuildHasher, Hasher};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let mut id = [0u8; 16];
    for half in id.chunks_mut(8) {
        let mut h = std::collections::hash_map::RandomState::new().build_hasher();
        h.write_u64(COUNTER.fetch_add(1, Ordering::Relaxed));
        h.write_u32(std::process::id());
        half.copy_from_slice(&h.finish().to_le_bytes());
    }
    id
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn goal_ids_print_as_simros2_does_and_parse_back() {
        let id: GoalId = [0, 1, 2, 0xab, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 0xff];
        let s = goal_id_string(&id);
        assert_eq!(s, "000102ab0405060708090a0b0c0d0eff");
        assert_eq!(parse_goal_id(&s), Some(id));
        assert_eq!(parse_goal_id(&s.to_uppercase()), Some(id));
        assert_eq!(parse_goal_id("00"), None);
        assert_eq!(parse_goal_id(&"zz".repeat(16)), None);
        assert_ne!(new_goal_id(), new_goal_id());
    }
}
