//! gantry's recordings as data: what an MCAP recording of a run holds and how it is
//! read back, with no simulation in it. Pure, so it is fuzzed on its own
//! (`fuzz/fuzz_targets/recording.rs`).
//!
//! - [`format`](mod@format): the format's version, fixed topics, topic naming, attachments;
//! - [`schema`]: the `ros2msg` schema text of every message recorded;
//! - [`input`]: what reached the simulation from outside (`/gantry/input`);
//! - [`decode`] and [`reader`]: reading a recording back (`gantry replay`, `gantry
//!   verify`), damaged and cut-short files included.
//!
//! Where the line is: the messages are *encoded* by gantry-protocol's typed encoders
//! ([`gantry_protocol::ros::typed`], pure like this crate, so the fuzz target can
//! check that what [`decode`] reads re-encodes), from the world that gantry-ros
//! samples; the recorder (gantry-record, above both) writes them into MCAP and
//! rebuilds a recording's scene from its attachments. Nothing here knows the
//! simulation, the scene loader, Lua, a runtime or physics.
//!
//! Topics: `/tf` (`tf2_msgs/msg/TFMessage`: every moving object's pose in its parent's
//! frame, frame ids the object paths without the leading `/`, roots in `world`),
//! `/tf_static` (the frames that have not moved), `/joint_states`
//! (`sensor_msgs/msg/JointState`), `/rosout` (`rcl_interfaces/msg/Log`),
//! `/graph/<graph>/<stream>` (`std_msgs/msg/Float64`), `/proximity/<sensor>`
//! (`sensor_msgs/msg/Range`), `/signal/<type>/<name>`, `/vision/<sensor>/image`
//! (`sensor_msgs/msg/Image`) and `/gantry/input`. Stamps are simulation time. See
//! docs/recording.md.

pub mod decode;
pub mod format;
pub mod input;
pub mod reader;
pub mod schema;

pub use format::{AttachedFile, FORMAT_VERSION};
pub use input::{INPUT_TOPIC, Input, InputDecodeError};
pub use reader::{ReadError, Recording};
