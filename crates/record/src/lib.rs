//! gantry's run recorder: one MCAP file per run, with ROS 2 messages, readable by
//! Foxglove, Rerun, `ros2 bag` and the `mcap` and `rosbags` Python packages. What the
//! file holds and how it is encoded is gantry-mcap (re-exported here); this crate
//! samples the running simulation and writes.
//!
//! - [`snapshot`]: what the simulation thread takes from the world after a step;
//! - [`writer`]: snapshots to MCAP messages (zstd chunks, indexed summary, `/tf_static`);
//! - [`recorder`]: the writer thread and the bounded queue to it, which drops (and
//!   counts) rather than ever making the simulation wait;
//! - [`tap`]: the recorder on the engine (every input and step), and the factory that
//!   starts recordings scripts ask for;
//! - [`verify`]: `gantry verify`, a recorded run simulated again and compared;
//! - [`reader`]: reading a recording back (`gantry replay`), damaged and cut-short
//!   files included, on gantry-mcap's [`decode`], and its scene rebuilt.
//!
//! See docs/recording.md.

pub mod recorder;
pub mod snapshot;
pub mod tap;
pub mod tf_frames;
pub mod verify;
pub mod writer;

pub use gantry_mcap::{
    AttachedFile, FORMAT_VERSION, INPUT_TOPIC, Input, InputDecodeError, ReadError, Recording, cdr, decode, format,
    input, msg, reader, schema,
};
pub use recorder::{
    BATCH, DEFAULT_QUEUE, FLUSH_EVERY, RecordError, RecordParams, RecordReport, Recorder, RunDescription,
};
pub use snapshot::ImageStream;
pub use tap::{RecordTap, RunRecorder};
pub use verify::{RecordedRun, Verdict, VerifyError};
