//! gantry's run recorder: one MCAP file per run, with ROS 2 messages, readable by
//! Foxglove, Rerun, `ros2 bag` and the `mcap` and `rosbags` Python packages. What the
//! file holds and how it is read back is gantry-mcap (re-exported here); what is
//! taken from the world after a step, and the messages it becomes, is gantry-ros,
//! which the live ROS 2 graph shares. This crate writes, re-runs and rebuilds.
//!
//! - [`writer`]: snapshots to MCAP messages (zstd chunks, indexed summary, `/tf_static`);
//! - [`recorder`]: the writer thread and the bounded queue to it, which drops (and
//!   counts) rather than ever making the simulation wait;
//! - [`tap`]: the recorder on the engine (every input and step), and the factory that
//!   starts recordings scripts ask for;
//! - [`verify`]: `gantry verify`, a recorded run simulated again and compared;
//! - [`scene`]: a recording's scene rebuilt from its attachments (`gantry replay` and
//!   `gantry verify`), on gantry-mcap's [`reader`].
//!
//! See docs/recording.md.

pub mod recorder;
pub mod scene;
pub mod tap;
pub mod verify;
pub mod writer;

pub use gantry_mcap::{
    AttachedFile, FORMAT_VERSION, INPUT_TOPIC, Input, InputDecodeError, ReadError, Recording, decode, format, input,
    reader, schema,
};
pub use gantry_ros::ImageStream;
/// The typed message encoders (gantry-ros's, which are gantry-protocol's).
pub use gantry_ros::msg;
pub use recorder::{
    BATCH, DEFAULT_QUEUE, FLUSH_EVERY, RecordError, RecordParams, RecordReport, Recorder, RunDescription,
};
pub use scene::{RecordedScene, SceneError, scene_from_files};
pub use tap::{RecordTap, RunRecorder};
pub use verify::{RecordedRun, Verdict, VerifyError};
