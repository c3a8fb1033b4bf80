//! A [`Snapshot`]: what the simulation thread takes from the world after a step, as
//! plain numbers (poses, joints, ranges, new graph samples, log lines, signals and
//! images), to be encoded elsewhere: on the recorder's writer thread, or the ROS 2
//! graph's encoder thread. The [`Sampler`](crate::Sampler) makes them.

use std::sync::Arc;

use gantry_sim_core::Handle;

/// Frame ids by handle: an object's path without its leading `/`
/// (`bubbleRob/leftMotor`, `wheel[1]` when siblings share an alias). Empty for gaps.
pub type FrameNames = Arc<Vec<String>>;

/// One object's pose relative to its parent (or the world for a root).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectPose {
    /// The object.
    pub handle: Handle,
    /// Its parent, `None` for a root (the `world` frame).
    pub parent: Option<Handle>,
    /// Translation (m) then rotation quaternion `x, y, z, w`, in the parent's frame.
    pub pose: [f64; 7],
}

/// One joint's state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointSample {
    /// The joint.
    pub handle: Handle,
    /// Position, rad or m.
    pub position: f64,
    /// Velocity, rad/s or m/s.
    pub velocity: f64,
    /// Torque or force the motor applied in the last step, N·m or N.
    pub effort: f64,
}

/// One proximity sensor's last reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RangeSample {
    /// The sensor.
    pub handle: Handle,
    /// Distance to the detected point, m; `+inf` when nothing is detected.
    pub range: f64,
    /// Near end of the detection volume, m.
    pub min_range: f64,
    /// Far end of the detection volume, m.
    pub max_range: f64,
    /// Full opening angle of a cone volume, rad (0 for the other shapes).
    pub field_of_view: f64,
}

/// A new sample of a graph stream.
#[derive(Debug, Clone, PartialEq)]
pub struct GraphSample {
    /// `/graph/<graph path>/<stream name>`.
    pub topic: Arc<str>,
    /// Recording time of the sample (run time, see [`Snapshot::log_time_ns`]).
    pub log_time_ns: u64,
    /// The value.
    pub value: f64,
}

/// A script log line.
#[derive(Debug, Clone, PartialEq)]
pub struct LogSample {
    /// Simulation time of the line, ns.
    pub stamp_ns: u64,
    /// Recording time of the line (run time).
    pub log_time_ns: u64,
    /// CoppeliaSim verbosity.
    pub verbosity: i64,
    /// Who logged it (a script's name).
    pub source: String,
    /// The text.
    pub message: String,
}

/// A signal's new value (set or changed since the previous snapshot).
#[derive(Debug, Clone, PartialEq)]
pub enum SignalSample {
    /// An int32 signal.
    Int32(String, i32),
    /// A float signal.
    Float(String, f64),
    /// A string signal (its bytes, shown as text where they are UTF-8).
    String(String, Vec<u8>),
}

/// A vision sensor's image, recorded at its stream's rate.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageSample {
    /// The sensor.
    pub handle: Handle,
    /// `[width, height]`, pixels.
    pub resolution: [u32; 2],
    /// RGB, 3 bytes per pixel, bottom row first (as the sensor holds it).
    pub rgb: Vec<u8>,
}

/// A vision sensor whose images are recorded (opt-in: images are large).
#[derive(Debug, Clone, PartialEq)]
pub struct ImageStream {
    /// The sensor's path (`/showroom/camera`), as `sim.getObject` takes it, or its
    /// alias.
    pub sensor: String,
    /// Images per simulated second, at most.
    pub rate_hz: f64,
}

/// Everything recorded for one step.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// Simulation time after the step, ns: the stamp of every message.
    pub stamp_ns: u64,
    /// Recording time: simulation time plus the length of earlier runs, when a stop
    /// restarted the simulation clock, so that a file's times never go back.
    pub log_time_ns: u64,
    /// Frame ids of the objects (shared until the tree changes).
    pub frames: FrameNames,
    /// Every object's pose, parents before children.
    pub poses: Vec<ObjectPose>,
    /// Every joint's state, in tree order.
    pub joints: Vec<JointSample>,
    /// Every handled proximity sensor's reading.
    pub ranges: Vec<RangeSample>,
    /// Graph samples added since the previous snapshot.
    pub graphs: Vec<GraphSample>,
    /// Log lines added since the previous snapshot.
    pub logs: Vec<LogSample>,
    /// Signals set or changed since the previous snapshot.
    pub signals: Vec<SignalSample>,
    /// Images due at this snapshot.
    pub images: Vec<ImageSample>,
}

impl Snapshot {
    /// The frame id of object `h` (empty for a handle not in the tree).
    pub fn frame(&self, h: Handle) -> &str {
        usize::try_from(h)
            .ok()
            .and_then(|i| self.frames.get(i))
            .map_or("", String::as_str)
    }
}
