//! ROS 2 over gantry's world: what both the recorder (gantry-record) and the live ROS
//! 2 graph (gantry-ros2) take from a running simulation, and the network the graph and
//! the Lua host's `simROS2` publish on.
//!
//! - [`Sampler`] and [`Snapshot`]: after a step, the world as plain numbers (poses,
//!   joints, ranges, graph samples, log lines, signals, images), with the frame ids of
//!   the object tree ([`FrameNames`]); encoding happens on another thread;
//! - [`TfFrames`]: which frames go on `/tf_static` and which on `/tf`, one rule for the
//!   recording and the graph;
//! - [`RosNetwork`] and its types: a network that moves CDR bodies; gantry-ros2
//!   implements it over DDS, the Lua host's `simROS2` and the graph use it;
//! - [`msg`]: the typed message encoders, gantry-protocol's [`ros::typed`].
//!
//! Where the line is: encoding a message needs no world, so the typed encoders live in
//! gantry-protocol, pure and fuzzed, where gantry-mcap's decoders and the recording
//! fuzz target reach them too; they are written by hand rather than through the
//! catalog's `Value` codec because they run every step (about 20 times faster for
//! `/tf`; [`ros::typed`] says more, and its tests check them against the catalog).
//! Sampling needs the world (gantry-sim-core), so it is here, above gantry-mcap and
//! beside it rather than under it. This crate has no runtime, no Lua, no transport
//! and no file format: the recorder writes MCAP, gantry-ros2 speaks DDS, the Lua host
//! binds the network to scripts.
//!
//! [`ros::typed`]: gantry_protocol::ros::typed

mod network;
mod sampler;
mod snapshot;
mod tf_frames;

pub use gantry_protocol::ros::typed as msg;
pub use network::{Direction, EndpointId, EndpointSpec, NetworkError, RosNetwork, RosQos, RosSample};
pub use sampler::Sampler;
pub use snapshot::{
    FrameNames, GraphSample, ImageSample, ImageStream, JointSample, LogSample, ObjectPose, RangeSample, SignalSample,
    Snapshot,
};
pub use tf_frames::{STATIC_TOLERANCE, TfFrames};
