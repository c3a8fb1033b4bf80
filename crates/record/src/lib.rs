//! gantry's run recorder: one MCAP file per run, with ROS 2 messages, readable by
//! Foxglove, Rerun, `ros2 bag` and the `mcap` and `rosbags` Python packages.
//!
//! - [`cdr`] and [`msg`]: the CDR encoding of the messages (pure, byte-exact tests);
//! - [`schema`]: their `ros2msg` schema text, with every type they use;
//! - [`snapshot`]: what the simulation thread takes from the world after a step;
//! - [`writer`]: snapshots to MCAP messages (zstd chunks, indexed summary);
//! - [`recorder`]: the writer thread and the bounded queue to it, which drops (and
//!   counts) rather than ever making the simulation wait.
//!
//! Topics: `/tf` (`tf2_msgs/msg/TFMessage`: every object's pose in its parent's frame,
//! frame ids the object paths without the leading `/`, roots in `world`),
//! `/joint_states` (`sensor_msgs/msg/JointState`, every joint of the scene),
//! `/rosout` (`rcl_interfaces/msg/Log`, script log lines and errors),
//! `/graph/<graph>/<stream>` (`std_msgs/msg/Float64`) and `/proximity/<sensor>`
//! (`sensor_msgs/msg/Range`), `/tf_static` (the frames that have not moved) and
//! `/gantry/input` (what reached the simulation from outside, for `gantry verify`, see
//! [`input`]). Stamps are simulation time. See docs/recording.md.

pub mod cdr;
pub mod input;
pub mod msg;
pub mod recorder;
pub mod schema;
pub mod snapshot;
pub mod tap;
pub mod verify;
pub mod writer;

pub use input::{INPUT_TOPIC, Input, InputDecodeError};
pub use recorder::{
    BATCH, DEFAULT_QUEUE, FLUSH_EVERY, FORMAT_VERSION, RecordError, RecordParams, RecordReport, Recorder,
    RunDescription,
};
pub use snapshot::ImageStream;
pub use tap::{RecordTap, RunRecorder};
pub use verify::{RecordedRun, Verdict, VerifyError};
pub use writer::AttachedFile;
