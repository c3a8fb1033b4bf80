//! What a gantry recording is, beyond its messages: the format's version, the fixed
//! topics, how other topics are named, and the files attached to it.

/// The version of what gantry writes into a recording (channels, metadata, inputs),
/// in the `gantry` metadata record as `format_version`: a reader refuses files of a
/// later version rather than misreading them.
pub const FORMAT_VERSION: u32 = 1;

/// The frame of the world, parent of every root object.
pub const WORLD_FRAME: &str = "world";

/// `/tf`.
pub const TF_TOPIC: &str = "/tf";
/// `/joint_states`.
pub const JOINT_STATES_TOPIC: &str = "/joint_states";
/// `/rosout`.
pub const ROSOUT_TOPIC: &str = "/rosout";
/// `/tf_static`.
pub const TF_STATIC_TOPIC: &str = "/tf_static";

/// A file attached to the recording (the scene, its scripts).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AttachedFile {
    /// Its name in the recording, e.g. `scene.toml` or `scripts/robot.lua`.
    pub name: String,
    /// Its media type, e.g. `application/toml`.
    pub media_type: String,
    /// Its bytes.
    pub data: Vec<u8>,
}

/// A ROS topic name from parts: `/a/b/c`, with every character other than ASCII
/// letters, digits and `_` replaced by `_` inside a part.
pub fn topic_name(parts: &[&str]) -> String {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn topic_names_keep_to_ros_characters() {
        assert_eq!(
            topic_name(&["graph", "robot/graph[1]", "speed (m/s)"]),
            "/graph/robot_graph_1_/speed__m_s_"
        );
        assert_eq!(topic_name(&["proximity", ""]), "/proximity/_");
    }
}
