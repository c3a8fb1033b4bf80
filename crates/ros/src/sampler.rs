//! The [`Sampler`]: takes [`Snapshot`]s from a simulation after its steps, at most
//! one per period of simulated time. Reading the world is all it does; encoding and
//! I/O happen on the thread it hands the snapshots to.

use std::collections::HashMap;
use std::sync::Arc;

use gantry_protocol::ros::topic_from_parts;
use gantry_protocol::ros::typed::nanos_from_secs;
use gantry_sim_core::Handle;
use gantry_sim_core::Sim;
use gantry_sim_core::math::quat_to_array;
use gantry_sim_core::scene::ProximityModel;
use gantry_sim_core::signals::Signals;
use gantry_sim_core::world::object_path::full_paths;
use gantry_sim_core::world::{ObjectKind, World};

use crate::snapshot::{
    FrameNames, GraphSample, ImageSample, ImageStream, JointSample, LogSample, ObjectPose, RangeSample, SignalSample,
    Snapshot,
};

/// An image stream's sampling state.
#[derive(Debug)]
struct ImageState {
    stream: ImageStream,
    period_ns: u64,
    /// The sensor, found by its path when the tree changes.
    handle: Option<Handle>,
    /// Recording time of the last image recorded.
    last_ns: Option<u64>,
    /// The sensor's render count at that image.
    last_renders: u64,
    /// Whether a missing sensor was reported.
    warned: bool,
}

/// Takes [`Snapshot`]s from a simulation, at most one per `period`.
#[derive(Debug)]
pub struct Sampler {
    /// Simulation time between snapshots, ns (0: every step).
    period_ns: u64,
    /// The recording time of the last snapshot.
    last_log_ns: Option<u64>,
    /// The simulation time of the last snapshot.
    last_stamp_ns: Option<u64>,
    /// The world's step count at the last snapshot.
    last_steps: u64,
    /// Added to simulation time: the recording time at which the current run started.
    offset_ns: u64,
    /// `(handle, parent, alias)` of every object at the last snapshot, to notice a
    /// change of the tree without rebuilding the frame names each step.
    tree: Vec<(Handle, Option<Handle>, String)>,
    /// Frame ids for `tree`.
    frames: FrameNames,
    /// The first log sequence number not yet recorded.
    next_log: u64,
    /// Topic and last recorded sample time of each graph stream, by (graph, stream id).
    streams: HashMap<(Handle, i64), (Arc<str>, f64)>,
    /// The signals at the last snapshot.
    signals: Signals,
    /// The image streams.
    images: Vec<ImageState>,
}

impl Sampler {
    /// A sampler taking at most `rate_hz` snapshots per simulated second (`None`: one
    /// per step).
    pub fn new(rate_hz: Option<f64>) -> Self {
        let period_ns = rate_hz
            .filter(|r| r.is_finite() && *r > 0.0)
            .map_or(0, |r| nanos_from_secs(1.0 / r));
        Self {
            period_ns,
            last_log_ns: None,
            last_stamp_ns: None,
            offset_ns: 0,
            last_steps: 0,
            tree: Vec::new(),
            frames: Arc::new(Vec::new()),
            next_log: 0,
            streams: HashMap::new(),
            signals: Signals::default(),
            images: Vec::new(),
        }
    }

    /// Also records the images of `streams`.
    #[must_use]
    pub fn with_images(mut self, streams: &[ImageStream]) -> Self {
        self.images = streams
            .iter()
            .map(|s| ImageState {
                period_ns: nanos_from_secs(1.0 / s.rate_hz.max(1e-6)),
                stream: s.clone(),
                handle: None,
                last_ns: None,
                last_renders: 0,
                warned: false,
            })
            .collect();
        self
    }

    /// A snapshot of `sim` if one is due at its current time: the first call, and then
    /// once `period` of simulated time has passed (or the clock restarted). `None`
    /// when the simulation has not advanced since the last one.
    pub fn sample(&mut self, sim: &Sim) -> Option<Snapshot> {
        let world = &sim.world;
        let stamp_ns = nanos_from_secs(world.time());
        if let (Some(last_stamp), Some(last_log)) = (self.last_stamp_ns, self.last_log_ns) {
            if stamp_ns < last_stamp {
                // The simulation was stopped and started again: its clock restarted.
                // Carry on from the recording time reached, one nanosecond later.
                self.offset_ns = last_log + 1;
                for (_, last) in self.streams.values_mut() {
                    *last = f64::NEG_INFINITY;
                }
            } else if stamp_ns == last_stamp || stamp_ns - last_stamp < self.period_ns {
                return None;
            }
        }
        let log_time_ns = self.offset_ns + stamp_ns;
        self.last_stamp_ns = Some(stamp_ns);
        self.last_log_ns = Some(log_time_ns);
        let look_back = usize::try_from(world.steps().saturating_sub(self.last_steps))
            .unwrap_or(usize::MAX)
            .saturating_add(2);
        self.last_steps = world.steps();
        self.refresh_frames(world);
        Some(Snapshot {
            stamp_ns,
            log_time_ns,
            frames: self.frames.clone(),
            poses: poses(world),
            joints: joints(world),
            ranges: ranges(world),
            graphs: self.graph_samples(sim, look_back),
            logs: self.log_lines(world),
            signals: self.signal_samples(&sim.signals),
            images: self.image_samples(sim, log_time_ns),
        })
    }

    /// Signals set or changed since the last snapshot (removed ones are not
    /// recorded: a later value is).
    fn signal_samples(&mut self, now: &Signals) -> Vec<SignalSample> {
        if *now == self.signals {
            return Vec::new();
        }
        let mut out = Vec::new();
        for (k, v) in &now.int32 {
            if self.signals.int32.get(k) != Some(v) {
                out.push(SignalSample::Int32(k.clone(), *v));
            }
        }
        for (k, v) in &now.float {
            // Bit for bit, so that a NaN signal set once is recorded once.
            if self.signals.float.get(k).map(|x| x.to_bits()) != Some(v.to_bits()) {
                out.push(SignalSample::Float(k.clone(), *v));
            }
        }
        for (k, v) in &now.string {
            if self.signals.string.get(k) != Some(v) {
                out.push(SignalSample::String(k.clone(), v.clone()));
            }
        }
        self.signals.clone_from(now);
        out
    }

    /// The images due at recording time `log_time_ns`: a sensor rendered since its
    /// last image, and its period has passed.
    fn image_samples(&mut self, sim: &Sim, log_time_ns: u64) -> Vec<ImageSample> {
        let mut out = Vec::new();
        for st in &mut self.images {
            let Some(h) = st.handle else { continue };
            let Some(img) = sim.vision.image(h) else { continue };
            let due = st
                .last_ns
                .is_none_or(|t| log_time_ns < t || log_time_ns - t >= st.period_ns);
            if !due || img.renders() == st.last_renders {
                continue;
            }
            st.last_ns = Some(log_time_ns);
            st.last_renders = img.renders();
            out.push(ImageSample {
                handle: h,
                resolution: img.resolution(),
                rgb: img.rgb().to_vec(),
            });
        }
        out
    }

    /// The recording time of `sim`'s current simulation time (for inputs between
    /// snapshots; the writer keeps the file's times from going back).
    pub fn log_time_now(&self, sim: &Sim) -> u64 {
        self.offset_ns + nanos_from_secs(sim.world.time())
    }

    /// Log lines only (the run's cleanup hooks log after its last step).
    pub fn sample_logs(&mut self, sim: &Sim) -> Vec<LogSample> {
        self.log_lines(&sim.world)
    }

    /// Rebuilds the frame names when an object was added, removed, moved to another
    /// parent or renamed since the last snapshot.
    fn refresh_frames(&mut self, world: &World) {
        let handles = world.handles();
        let same = handles.len() == self.tree.len()
            && handles
                .iter()
                .zip(&self.tree)
                .all(|(&h, (th, tp, ta))| h == *th && world.object(h).is_ok_and(|o| o.parent == *tp && o.alias == *ta));
        if same {
            return;
        }
        self.tree = handles
            .iter()
            .filter_map(|&h| world.object(h).ok().map(|o| (h, o.parent, o.alias.clone())))
            .collect();
        let paths = full_paths(world);
        let mut names = vec![String::new(); world.len()];
        for (h, path) in paths {
            if let Some(slot) = usize::try_from(h).ok().and_then(|i| names.get_mut(i)) {
                *slot = path.trim_start_matches('/').to_owned();
            }
        }
        self.frames = Arc::new(names);
        for st in &mut self.images {
            let wanted = st.stream.sensor.trim_start_matches('/');
            st.handle = self
                .frames
                .iter()
                .position(|n| n == wanted)
                .or_else(|| {
                    self.tree
                        .iter()
                        .find(|(_, _, a)| a == wanted)
                        .and_then(|(h, _, _)| usize::try_from(*h).ok())
                })
                .and_then(|i| Handle::try_from(i).ok());
            if st.handle.is_none() && !st.warned {
                st.warned = true;
                tracing::warn!(
                    "recording: no object {:?} in the scene, so none of its images are recorded \
                     (name a vision sensor by its path, as /parent/sensor, or its alias)",
                    st.stream.sensor
                );
            }
        }
    }

    /// Samples recorded since the last snapshot, for every graph stream. Scripts add
    /// at most one sample per stream and step, so only the `look_back` newest samples
    /// of each can be new (a stream is a ring of up to thousands).
    fn graph_samples(&mut self, sim: &Sim, look_back: usize) -> Vec<GraphSample> {
        let now = sim.world.time();
        let mut out = Vec::new();
        for s in sim.graphs.streams() {
            let key = (s.graph(), s.id());
            let (topic, last) = self.streams.entry(key).or_insert_with(|| {
                let graph = self
                    .frames
                    .get(usize::try_from(s.graph()).unwrap_or(usize::MAX))
                    .filter(|n| !n.is_empty())
                    .cloned()
                    .unwrap_or_else(|| format!("graph{}", s.graph()));
                (
                    topic_from_parts(&["graph", &graph, &s.params().name]).into(),
                    f64::NEG_INFINITY,
                )
            });
            // After a restart, samples of the earlier run (later than now) are not new.
            let n = s.len();
            let mut newest = *last;
            let fresh: Vec<(f64, f64)> = s
                .samples()
                .skip(n.saturating_sub(look_back))
                .filter(|&(t, _)| t > *last && t <= now)
                .collect();
            for (t, value) in fresh {
                newest = t;
                out.push(GraphSample {
                    topic: topic.clone(),
                    log_time_ns: self.offset_ns + nanos_from_secs(t),
                    value,
                });
            }
            *last = newest;
        }
        out
    }

    /// Log lines logged since the last call.
    fn log_lines(&mut self, world: &World) -> Vec<LogSample> {
        let out: Vec<LogSample> = world
            .log
            .since(self.next_log)
            .map(|l| {
                let stamp_ns = nanos_from_secs(l.sim_time);
                LogSample {
                    stamp_ns,
                    log_time_ns: self.offset_ns + stamp_ns,
                    verbosity: l.verbosity,
                    source: l.source.clone(),
                    message: l.message.clone(),
                }
            })
            .collect();
        if let Some(last) = world.log.lines().last() {
            self.next_log = last.seq + 1;
        }
        out
    }
}

/// Every object's pose relative to its parent, parents first.
fn poses(world: &World) -> Vec<ObjectPose> {
    let mut out = Vec::with_capacity(world.handles().len());
    for &h in world.handles() {
        let Ok(o) = world.object(h) else { continue };
        // The parent's own frame (for a joint, its fixed side): composing the frames
        // from the world down gives back each object's world pose.
        let rel = match o.parent.and_then(|p| world.object(p).ok()) {
            Some(p) => p.world.inverse() * o.world,
            None => o.world,
        };
        let t = rel.translation.vector;
        let [qx, qy, qz, qw] = quat_to_array(&rel.rotation);
        out.push(ObjectPose {
            handle: h,
            parent: o.parent,
            pose: [t.x, t.y, t.z, qx, qy, qz, qw],
        });
    }
    out
}

/// Every joint's state.
fn joints(world: &World) -> Vec<JointSample> {
    world
        .handles()
        .iter()
        .filter_map(|&h| match &world.object(h).ok()?.kind {
            ObjectKind::Joint(j) => Some(JointSample {
                handle: h,
                position: j.position,
                velocity: j.velocity,
                effort: j.force,
            }),
            _ => None,
        })
        .collect()
}

/// Every proximity sensor that was handled at least once.
fn ranges(world: &World) -> Vec<RangeSample> {
    world
        .handles()
        .iter()
        .filter_map(|&h| match &world.object(h).ok()?.kind {
            ObjectKind::ProximitySensor(p) => {
                let last = p.last?;
                let (offset, depth, fov) = match p.volume {
                    ProximityModel::Ray { offset, range } => (offset, range, 0.0),
                    ProximityModel::Cone {
                        offset,
                        range,
                        half_angle,
                    }
                    | ProximityModel::Disc {
                        offset,
                        range,
                        half_angle,
                        ..
                    } => (offset, range, 2.0 * half_angle),
                    ProximityModel::Pyramid { offset, range, .. } | ProximityModel::Cylinder { offset, range, .. } => {
                        (offset, range, 0.0)
                    }
                };
                Some(RangeSample {
                    handle: h,
                    range: last.map_or(f64::INFINITY, |d| d.distance),
                    min_range: offset,
                    max_range: offset + depth,
                    field_of_view: fov,
                })
            }
            _ => None,
        })
        .collect()
}
