//! gantry's recordings as data: what an MCAP recording of a run holds and how it is
//! encoded, with no simulation in it (the recorder, which samples a running
//! simulation, is gantry-record, above). Pure codecs, so they are fuzzed on their own.
//!
//! - [`cdr`] and [`msg`]: the CDR encoding of the ROS 2 messages (byte-exact tests),
//!   and [`decode`]: their decoding (total, bounded), for reading recordings back;
//! - [`schema`]: their `ros2msg` schema text, with every type they use;
//! - [`input`]: what reached the simulation from outside (`/gantry/input`);
//! - [`format`](mod@format): the format's version, fixed topics, topic naming, attachments;
//! - [`decode`] and [`reader`]: reading a recording back (`gantry replay`, `gantry
//!   verify`), damaged and cut-short files included.
//!
//! Topics: `/tf` (`tf2_msgs/msg/TFMessage`: every moving object's pose in its parent's
//! frame, frame ids the object paths without the leading `/`, roots in `world`),
//! `/tf_static` (the frames that have not moved), `/joint_states`
//! (`sensor_msgs/msg/JointState`), `/rosout` (`rcl_interfaces/msg/Log`),
//! `/graph/<graph>/<stream>` (`std_msgs/msg/Float64`), `/proximity/<sensor>`
//! (`sensor_msgs/msg/Range`), `/signal/<type>/<name>`, `/vision/<sensor>/image`
//! (`sensor_msgs/msg/Image`) and `/gantry/input`. Stamps are simulation time. See
//! docs/recording.md.

pub mod cdr;
pub mod decode;
pub mod format;
pub mod input;
pub mod msg;
pub mod reader;
pub mod schema;

pub use format::{AttachedFile, FORMAT_VERSION};
pub use input::{INPUT_TOPIC, Input, InputDecodeError};
pub use reader::{ReadError, Recording};
