//! What a gantry recording is, beyond its messages: the format's version, the fixed
//! topics, how other topics are named, and the files attached to it.

/// The version of what gantry writes into a recording (channels, metadata, inputs),
/// in the `gantry` metadata record as `format_version`: a reader refuses files of a
/// later version rather than misreading them.
pub const FORMAT_VERSION: u32 = 1;

/// The frame of the world, parent of every root object.
pub use gantry_protocol::ros::typed::WORLD_FRAME;

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

/// A ROS topic name from parts (`/graph/<graph>/<stream>`), as gantry-protocol
/// makes it for the live ROS 2 graph too.
pub use gantry_protocol::ros::topic_from_parts as topic_name;
