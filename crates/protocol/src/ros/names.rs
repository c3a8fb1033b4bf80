//! ROS 2 topic and service names to DDS topic names, as the rmw layer maps them:
//! `/cmd_vel` is `rt/cmd_vel`, service `/set_flag` is `rq/set_flagRequest` and
//! `rr/set_flagReply`.
//!
//! Names are checked against ROS 2's rules first (those of `rmw_validate_full_topic_name`):
//! letters, digits, `_` and `/` only, no empty token (`//`), no trailing `/`, no token
//! starting with a digit. Relative names are taken in the root namespace, as a node
//! without a namespace would. `~` and `{substitution}` need a node's name and
//! namespace to expand, so they are refused rather than guessed.

use super::NameError;

/// The DDS topic of ROS 2 topic `ros_name`: `/cmd_vel` or `cmd_vel` -> `rt/cmd_vel`,
/// `/a/b` -> `rt/a/b`.
///
/// # Errors
/// The name breaks the ROS 2 name rules, or uses `~` or `{}` substitution.
pub fn topic_name(ros_name: &str) -> Result<String, NameError> {
    Ok(format!("rt/{}", validate(ros_name)?))
}

/// A ROS topic name from parts, for topics named after objects and streams
/// (`/graph/<graph>/<stream>`): `/a/b/c`, with every character other than ASCII
/// letters, digits and `_` replaced by `_` inside a part, and an empty part as `_`.
pub fn topic_from_parts(parts: &[&str]) -> String {
    let mut out = String::new();
    for p in parts {
        out.push('/');
        if p.is_empty() {
            out.push('_');
        }
        out.extend(
            p.chars()
                .map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '_' }),
        );
    }
    out
}

/// The DDS topic a service's requests travel on: `/set_flag` -> `rq/set_flagRequest`.
///
/// # Errors
/// As [`topic_name`].
pub fn service_request_topic(ros_name: &str) -> Result<String, NameError> {
    Ok(format!("rq/{}Request", validate(ros_name)?))
}

/// The DDS topic a service's replies travel on: `/set_flag` -> `rr/set_flagReply`.
///
/// # Errors
/// As [`topic_name`].
pub fn service_reply_topic(ros_name: &str) -> Result<String, NameError> {
    Ok(format!("rr/{}Reply", validate(ros_name)?))
}

/// The DDS topics of ROS 2 action `/name` (rcl_action's layout under `/name/_action/`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ActionTopics {
    /// `rq/name/_action/send_goalRequest` and `rr/name/_action/send_goalReply`.
    pub send_goal: (String, String),
    /// `rq/name/_action/cancel_goalRequest` and its reply topic.
    pub cancel_goal: (String, String),
    /// `rq/name/_action/get_resultRequest` and its reply topic.
    pub get_result: (String, String),
    /// `rt/name/_action/feedback`.
    pub feedback: String,
    /// `rt/name/_action/status`.
    pub status: String,
}

/// The DDS topics of ROS 2 action `ros_name`.
///
/// # Errors
/// As [`topic_name`].
pub fn action_topics(ros_name: &str) -> Result<ActionTopics, NameError> {
    let base = validate(ros_name)?;
    let service = |s: &str| {
        (
            format!("rq/{base}/_action/{s}Request"),
            format!("rr/{base}/_action/{s}Reply"),
        )
    };
    Ok(ActionTopics {
        send_goal: service("send_goal"),
        cancel_goal: service("cancel_goal"),
        get_result: service("get_result"),
        feedback: format!("rt/{base}/_action/feedback"),
        status: format!("rt/{base}/_action/status"),
    })
}

/// The ROS 2 name of a DDS topic, for display: `rt/cmd_vel` -> `/cmd_vel`, and a
/// service's `rq/xRequest` or `rr/xReply` -> `/x`. `None` for DDS topics that are not
/// ROS 2 topics or services (discovery topics, `rp/` parameters' internals, other
/// prefixes) or whose rest is not a valid name.
pub fn ros_topic_name(dds_name: &str) -> Option<String> {
    let rest = if let Some(rest) = dds_name.strip_prefix("rt/") {
        rest
    } else if let Some(rest) = dds_name.strip_prefix("rq/") {
        rest.strip_suffix("Request")?
    } else {
        dds_name.strip_prefix("rr/")?.strip_suffix("Reply")?
    };
    validate(rest).ok().map(|name| format!("/{name}"))
}

/// Checks a ROS 2 name and returns it without its leading `/`.
fn validate(name: &str) -> Result<&str, NameError> {
    let invalid = |reason| NameError::Invalid {
        name: name.to_owned(),
        reason,
    };
    if name.contains('~') {
        return Err(NameError::Unsupported {
            name: name.to_owned(),
            feature: "`~` (the node's private namespace)",
        });
    }
    if name.contains(['{', '}']) {
        return Err(NameError::Unsupported {
            name: name.to_owned(),
            feature: "`{}` substitution",
        });
    }
    if name.is_empty() {
        return Err(invalid("the name is empty"));
    }
    let rest = name.strip_prefix('/').unwrap_or(name);
    if rest.is_empty() {
        return Err(invalid("`/` alone is a namespace, not a topic; add a name after it"));
    }
    if let Some(c) = rest
        .chars()
        .find(|c| !(c.is_ascii_alphanumeric() || *c == '_' || *c == '/'))
    {
        return Err(if c.is_whitespace() {
            invalid("spaces are not allowed; use letters, digits, '_' and '/'")
        } else {
            invalid("only letters, digits, '_' and '/' are allowed")
        });
    }
    if rest.ends_with('/') {
        return Err(invalid("it must not end with '/'"));
    }
    if rest.starts_with('/') || rest.contains("//") {
        return Err(invalid("it must not contain '//' (an empty token)"));
    }
    if rest
        .split('/')
        .any(|token| token.starts_with(|c: char| c.is_ascii_digit()))
    {
        return Err(invalid("a token must not start with a digit"));
    }
    Ok(rest)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn topic_names_from_parts_keep_to_ros_characters() {
        assert_eq!(
            topic_from_parts(&["graph", "robot/graph[1]", "speed (m/s)"]),
            "/graph/robot_graph_1_/speed__m_s_"
        );
        assert_eq!(topic_from_parts(&["proximity", ""]), "/proximity/_");
    }
}
