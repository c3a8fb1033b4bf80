//! The pose stream: one [`Frame`] per publication, built on the simulation thread by
//! [`FramePublisher`] and shared by every viewer through a `watch` channel.
//!
//! Latest-value semantics are the point: the channel holds one frame, each viewer
//! session takes the newest when it is ready, and a slow browser simply skips frames.
//! The simulation never waits for a viewer and memory does not grow with their lag.
//! Frames are only built while a viewer is connected, at most [`MAX_FRAME_RATE`] per
//! second while the simulation advances and [`IDLE_FRAME_RATE`] while it does not (so
//! joints moved by packets during a pause still show).
//!
//! Each session turns frames into deltas against what it sent last ([`FrameDelta`]):
//! only the poses, joints, drawings and point clouds that changed go over the wire.
//! Point clouds are sent in their own frame, once per change of their points or
//! settings; the page places them with the cloud's pose, so a moving cloud costs only
//! its pose.

use std::sync::Arc;
use std::time::{Duration, Instant};

use gantry_engine::Observer;
use gantry_sim_core::Sim;
use gantry_sim_core::drawing::DrawingKind;
use gantry_sim_core::math::euler_from_quat;
use gantry_sim_core::world::{ObjectKind, PointCloud};
use serde_json::json;
use tokio::sync::watch;

/// Most frames per second while the simulation advances (the browser's display rate;
/// more would only cost the simulation thread).
pub const MAX_FRAME_RATE: f64 = 60.0;
/// Frames per second while the simulation does not advance.
pub const IDLE_FRAME_RATE: f64 = 10.0;
/// Most vertices sent per drawing object (its newest items); the rest is not drawn.
pub const MAX_DRAWING_VERTICES: usize = 30_000;
/// Most drawing vertices per frame, all drawing objects together; drawing objects past
/// it are not drawn (they stay in the simulation).
pub const MAX_FRAME_VERTICES: usize = 300_000;
/// Most points sent per point cloud: larger clouds are sent as an even subsample.
pub const MAX_CLOUD_POINTS: usize = 200_000;
/// Most point-cloud points per frame, all clouds together; clouds past it are not
/// drawn (they stay in the simulation).
pub const MAX_FRAME_CLOUD_POINTS: usize = 1_000_000;
/// How often steps/s and the real-time factor are measured.
const RATE_WINDOW: Duration = Duration::from_millis(500);

/// Binary message type of a frame delta (the first little-endian `u32`).
pub const MSG_FRAME: u32 = 1;
/// Drawing kind code that tells the page a drawing object was removed.
pub const DRAWING_REMOVED: u32 = 255;

/// One drawing object's vertices, in the world frame.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawingFrame {
    /// The drawing object's handle.
    pub handle: i64,
    /// 0 points, 1 lines, 2 triangles, 7 sphere points, 8 line strip (as `sim.drawing_*`).
    pub kind: u32,
    /// Pixels for points and lines, metres for sphere points.
    pub size: f32,
    /// RGB, 0..1.
    pub color: [f32; 3],
    /// `x, y, z` per vertex, world frame, m.
    pub vertices: Vec<f32>,
}

/// One point cloud's points, in the cloud's own frame (the page places them with the
/// cloud's pose from [`Frame::poses`]).
#[derive(Debug, Clone, PartialEq)]
pub struct PointCloudFrame {
    /// The cloud's object handle.
    pub handle: i64,
    /// [`PointCloud::generation`]: the same number means the same points and settings.
    pub generation: u64,
    /// Point size, pixels.
    pub size: f32,
    /// `x, y, z` per point, cloud frame, m (at most [`MAX_CLOUD_POINTS`] points).
    pub points: Vec<f32>,
    /// `r, g, b` bytes per point.
    pub colors: Vec<u8>,
}

impl PointCloudFrame {
    /// The cloud as the page draws it: every point, or an even subsample of
    /// [`MAX_CLOUD_POINTS`]; random colours (option bit 0) are made up here, the same
    /// for each point from frame to frame.
    pub fn capture(handle: i64, cloud: &PointCloud) -> PointCloudFrame {
        let n = cloud.len();
        let stride = n.div_ceil(MAX_CLOUD_POINTS).max(1);
        let random = cloud.options().random_colors();
        let mut points = Vec::with_capacity(3 * n / stride);
        let mut colors = Vec::with_capacity(3 * n / stride);
        for (i, (p, c)) in cloud.points().iter().zip(cloud.colors()).enumerate().step_by(stride) {
            points.extend([p.x as f32, p.y as f32, p.z as f32]);
            colors.extend(if random { random_color(i) } else { *c });
        }
        PointCloudFrame {
            handle,
            generation: cloud.generation(),
            size: cloud.options().point_size as f32,
            points,
            colors,
        }
    }

    /// Number of points sent.
    pub fn len(&self) -> usize {
        self.points.len() / 3
    }

    /// Whether no point is sent.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

/// CoppeliaSim's random point colours: each channel in [0.2, 1], here from a hash of the
/// point's index so that it keeps its colour.
fn random_color(i: usize) -> [u8; 3] {
    let mut x = (i as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^= x >> 31;
    [0, 1, 2].map(|k| 51 + ((x >> (16 * k)) & 0xffff) as u8 % 205)
}

/// What the page shows that changes while the simulation runs.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Frame {
    /// Simulation time, s.
    pub time: f64,
    /// Steps of the current simulation (reset by stop).
    pub steps: u64,
    /// `sim.getSimulationState` code: 0 stopped, 8 paused, 17 running.
    pub state: i64,
    /// Steps per second of wall-clock time, over the last half second.
    pub steps_per_s: f64,
    /// Real-time factor (simulated seconds per wall-clock second), same window.
    pub rtf: f64,
    /// World pose of every object as `x, y, z, qx, qy, qz, qw` (m), in the scene
    /// description's object order ([`gantry_sim_core::World::handles`]).
    pub poses: Vec<[f32; 7]>,
    /// Position of every joint (rad or m), in the scene description's joint order.
    pub joints: Vec<f32>,
    /// Target velocity of every joint (rad/s or m/s), same order.
    pub joint_target_velocities: Vec<f32>,
    /// Per proximity sensor (scene order): distance to the detected point (m), or -1.
    pub detections: Vec<f32>,
    /// Every drawing object.
    pub drawings: Vec<DrawingFrame>,
    /// Every point cloud, in scene order, until [`MAX_FRAME_CLOUD_POINTS`] (the rest are
    /// not drawn); each shared with the previous frame while it does not change.
    pub point_clouds: Vec<Arc<PointCloudFrame>>,
    /// The first selected object (`sim.getObjectSel`, the page's pick) and its
    /// orientation as `sim.getObjectOrientation(h, -1)` gives it: CoppeliaSim Euler
    /// angles, world frame, rad. One object only, so frames stay as cheap as before.
    pub selected: Option<SelectedOrientation>,
    /// `Uis::revision`: changes whenever a custom UI does.
    pub ui_revision: u64,
    /// `World::scene_revision`: when it differs from the scene description's, objects
    /// were created, removed, re-parented or restyled and the page needs the scene again.
    pub scene_revision: u64,
    /// `World::structure_revision`: when it differs, the object list or its order changed
    /// and poses no longer line up with the description until it is sent again.
    pub structure_revision: u64,
}

/// The picked object's orientation, for the page's pick panel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SelectedOrientation {
    /// The object's handle.
    pub handle: i64,
    /// `alpha, beta, gamma` (rad), from sim-core's `euler_from_quat` in f64: the page
    /// shows exactly what the API returns.
    pub euler: [f64; 3],
}

impl Frame {
    /// Reads a frame from the simulation. `steps_per_s` and `rtf` are left at 0.
    pub fn capture(sim: &Sim) -> Frame {
        Frame::capture_after(sim, None)
    }

    /// As [`Frame::capture`], taking the point clouds that did not change since
    /// `previous` from it instead of copying their points again.
    pub fn capture_after(sim: &Sim, previous: Option<&Frame>) -> Frame {
        let world = &sim.world;
        let mut f = Frame {
            time: world.time(),
            steps: world.steps(),
            state: sim.state.code(),
            ui_revision: sim.uis.revision(),
            scene_revision: world.scene_revision(),
            structure_revision: world.structure_revision(),
            ..Frame::default()
        };
        f.poses.reserve(world.handles().len());
        let mut cloud_budget = MAX_FRAME_CLOUD_POINTS;
        for &h in world.handles() {
            let Ok(o) = world.object(h) else {
                // Keeps the indices aligned with the scene description, which lists
                // every handle; the page draws nothing there.
                f.poses.push([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
                continue;
            };
            f.poses.push(pose_f32(&o.world));
            match &o.kind {
                ObjectKind::Joint(j) => {
                    f.joints.push(j.position as f32);
                    f.joint_target_velocities.push(j.target_velocity as f32);
                }
                ObjectKind::ProximitySensor(p) => {
                    f.detections.push(match p.last {
                        Some(Some(d)) => d.distance as f32,
                        _ => -1.0,
                    });
                }
                ObjectKind::PointCloud(c) => {
                    let unchanged = previous
                        .and_then(|p| p.point_clouds.iter().find(|x| x.handle == h))
                        .filter(|x| x.generation == c.generation());
                    let cloud = match unchanged {
                        Some(x) => x.clone(),
                        None => Arc::new(PointCloudFrame::capture(h, c)),
                    };
                    if cloud.len() <= cloud_budget {
                        cloud_budget -= cloud.len();
                        f.point_clouds.push(cloud);
                    }
                }
                _ => {}
            }
        }
        f.selected = world.selection.handles().first().and_then(|&h| {
            let o = world.object(h).ok()?;
            Some(SelectedOrientation {
                handle: h,
                euler: euler_from_quat(&o.world.rotation),
            })
        });
        let mut budget = MAX_FRAME_VERTICES;
        for view in sim.drawings.iter_world(world) {
            let o = view.object;
            let n = view.vertices().len();
            let keep = n.min(MAX_DRAWING_VERTICES).min(budget);
            if keep == 0 && n > 0 {
                break;
            }
            budget -= keep;
            let skip = n - keep;
            let mut vertices = Vec::with_capacity(3 * (n - skip));
            for v in view.vertices().skip(skip) {
                vertices.extend([v.x as f32, v.y as f32, v.z as f32]);
            }
            f.drawings.push(DrawingFrame {
                handle: view.handle,
                kind: drawing_kind_code(o.kind()),
                size: o.size() as f32,
                color: o.color().map(|c| c as f32),
                vertices,
            });
        }
        f
    }
}

/// A pose as the wire's `x, y, z, qx, qy, qz, qw`.
pub fn pose_f32(p: &gantry_sim_core::math::Pose) -> [f32; 7] {
    let t = &p.translation.vector;
    let q = &p.rotation;
    [t.x, t.y, t.z, q.i, q.j, q.k, q.w].map(|v| v as f32)
}

fn drawing_kind_code(kind: DrawingKind) -> u32 {
    match kind {
        DrawingKind::Points => 0,
        DrawingKind::Lines => 1,
        DrawingKind::Triangles => 2,
        DrawingKind::SpherePoints => 7,
        DrawingKind::LineStrip => 8,
    }
}

/// The sending side of the pose stream, shared by the publisher (simulation thread)
/// and the HTTP server (which subscribes a receiver per viewer session).
pub type FrameSender = Arc<watch::Sender<Arc<Frame>>>;

/// Publishes frames from the simulation thread (an [`Observer`]).
///
/// Costs one atomic load per loop turn while no viewer is connected.
pub struct FramePublisher {
    /// Frames go out here; sessions hold the receivers. Only this publisher sends.
    tx: FrameSender,
    /// When the last frame went out.
    last: Option<Instant>,
    /// Steps of the run at the last frame: a frame goes out at the fast rate only when
    /// the simulation advanced since.
    last_run_steps: u64,
    /// Start of the current rate window: wall clock, run steps, simulation time.
    window: Option<(Instant, u64, f64)>,
    /// The last measured steps/s and real-time factor.
    rates: (f64, f64),
}

impl FramePublisher {
    /// A publisher and the sender the HTTP server subscribes viewers through.
    pub fn new() -> (FramePublisher, FrameSender) {
        let tx = frame_channel();
        (FramePublisher::on(tx.clone()), tx)
    }

    /// A publisher sending on `tx` (made by [`frame_channel`]).
    pub fn on(tx: FrameSender) -> FramePublisher {
        FramePublisher {
            tx,
            last: None,
            last_run_steps: 0,
            window: None,
            rates: (0.0, 0.0),
        }
    }
}

/// A new pose stream, with no frame yet.
pub fn frame_channel() -> FrameSender {
    Arc::new(watch::channel(Arc::new(Frame::default())).0)
}

/// One publisher shared by the engine (an observer after each step and at idle ticks)
/// and the simulation thread's wait service (while a script holds the step in a
/// blocking call), so that the frame rate and the rate window are one.
#[derive(Clone)]
pub struct SharedPublisher(pub std::rc::Rc<std::cell::RefCell<FramePublisher>>);

impl Observer for SharedPublisher {
    fn stepped(&mut self, sim: &Sim, run_steps: u64) {
        self.0.borrow_mut().observe(sim, run_steps);
    }

    fn idle(&mut self, sim: &Sim, run_steps: u64) {
        self.0.borrow_mut().observe(sim, run_steps);
    }
}

/// Frames at each step and, while nothing steps, at the loop's idle ticks (a paused
/// simulation still changes: the viewer moves objects, scripts' non-simulation hooks).
impl Observer for FramePublisher {
    fn stepped(&mut self, sim: &Sim, run_steps: u64) {
        self.observe(sim, run_steps);
    }

    fn idle(&mut self, sim: &Sim, run_steps: u64) {
        self.observe(sim, run_steps);
    }
}

impl FramePublisher {
    /// [`FramePublisher::observe`] while the run's step count cannot move (a script
    /// holds the step): the simulation still changes under the viewer's eyes.
    pub fn observe_waiting(&mut self, sim: &Sim) {
        let steps = self.last_run_steps;
        self.observe(sim, steps);
    }

    /// Publishes a frame if a viewer watches and the frame rate allows one now.
    pub fn observe(&mut self, sim: &Sim, run_steps: u64) {
        if self.tx.receiver_count() == 0 {
            // Nobody watches: forget the rate window so a new viewer starts afresh.
            self.window = None;
            return;
        }
        let now = Instant::now();
        let advanced = run_steps != self.last_run_steps;
        let rate = if advanced { MAX_FRAME_RATE } else { IDLE_FRAME_RATE };
        if self
            .last
            .is_some_and(|t| now.duration_since(t).as_secs_f64() < 1.0 / rate)
        {
            return;
        }
        let core = sim;
        let world = &core.world;
        match self.window {
            Some((t0, s0, time0)) if now.duration_since(t0) >= RATE_WINDOW => {
                let wall = now.duration_since(t0).as_secs_f64();
                // After a stop the simulation time restarts from 0: no factor then.
                let rtf = ((world.time() - time0) / wall).max(0.0);
                self.rates = ((run_steps - s0) as f64 / wall, rtf);
                self.window = Some((now, run_steps, world.time()));
            }
            Some(_) => {}
            None => self.window = Some((now, run_steps, world.time())),
        }
        let previous = self.tx.borrow().clone();
        let mut frame = Frame::capture_after(core, Some(&previous));
        (frame.steps_per_s, frame.rtf) = self.rates;
        self.tx.send_replace(Arc::new(frame));
        self.last = Some(now);
        self.last_run_steps = run_steps;
    }
}

/// What one viewer session last sent, to send only what changed.
#[derive(Debug, Default)]
pub struct FrameDelta {
    poses: Vec<[f32; 7]>,
    joints: Vec<f32>,
    joint_target_velocities: Vec<f32>,
    detections: Vec<f32>,
    drawings: Vec<DrawingFrame>,
    /// `(handle, generation)` of each point cloud sent.
    clouds: Vec<(i64, u64)>,
    /// `None` until sent once (so a first or reset delta always says what is selected).
    selected: Option<Option<SelectedOrientation>>,
    scalars: Option<(f64, u64, i64, f64, f64)>,
}

/// One frame's messages for a session: a JSON text (scalars, joints, sensors, the
/// picked object's orientation) and a binary message (poses and drawings); either is
/// `None` when nothing of it changed.
#[derive(Debug, Default)]
pub struct DeltaMessages {
    /// `{"t":"tick",...}`; `"selected": {"handle", "euler"}` or `null` when the pick or
    /// its orientation changed.
    pub tick: Option<serde_json::Value>,
    /// [`MSG_FRAME`] binary message.
    pub binary: Option<Vec<u8>>,
}

impl FrameDelta {
    /// Forgets what was sent (after a new scene description): the next delta is complete.
    pub fn reset(&mut self) {
        *self = FrameDelta::default();
    }

    /// The messages that bring the page from the last frame sent to `frame`.
    ///
    /// Binary layout, little-endian: `u32` [`MSG_FRAME`], `u32` pose count, `u32`
    /// drawing count, `u32` point-cloud count; per pose `u32` object index and 7 `f32`;
    /// per drawing `u32` handle, `u32` kind ([`DRAWING_REMOVED`] when gone), `f32` size,
    /// 3 `f32` colour, `u32` vertex count and 3 `f32` per vertex; per point cloud `u32`
    /// object handle, `u32` 0 ([`DRAWING_REMOVED`] when gone or not drawn), `f32` point
    /// size (pixels), `u32` point count, 3 `f32` per point (cloud frame, m), then 3 `u8`
    /// colour bytes per point, padded with zeros to a multiple of 4 bytes.
    pub fn update(&mut self, frame: &Frame) -> DeltaMessages {
        let mut out = DeltaMessages::default();

        // Poses: a changed scene size means a new description was due; send them all.
        if self.poses.len() != frame.poses.len() {
            self.poses = vec![[f32::NAN; 7]; frame.poses.len()];
        }
        let changed: Vec<usize> = (0..frame.poses.len())
            .filter(|&i| !bit_equal(&self.poses[i], &frame.poses[i]))
            .collect();
        let mut drawings: Vec<&DrawingFrame> = Vec::new();
        for d in &frame.drawings {
            if self.drawings.iter().find(|s| s.handle == d.handle) != Some(d) {
                drawings.push(d);
            }
        }
        let removed: Vec<i64> = self
            .drawings
            .iter()
            .filter(|s| !frame.drawings.iter().any(|d| d.handle == s.handle))
            .map(|s| s.handle)
            .collect();
        let clouds: Vec<&PointCloudFrame> = frame
            .point_clouds
            .iter()
            .filter(|c| !self.clouds.contains(&(c.handle, c.generation)))
            .map(|c| &**c)
            .collect();
        let clouds_gone: Vec<i64> = self
            .clouds
            .iter()
            .filter(|(h, _)| !frame.point_clouds.iter().any(|c| c.handle == *h))
            .map(|(h, _)| *h)
            .collect();
        let any_cloud = !clouds.is_empty() || !clouds_gone.is_empty();
        if !changed.is_empty() || !drawings.is_empty() || !removed.is_empty() || any_cloud {
            let count = drawings.len() + removed.len();
            let cloud_count = clouds.len() + clouds_gone.len();
            let mut b = Vec::with_capacity(16 + 32 * changed.len());
            for v in [MSG_FRAME, changed.len() as u32, count as u32, cloud_count as u32] {
                b.extend(v.to_le_bytes());
            }
            for &i in &changed {
                b.extend((i as u32).to_le_bytes());
                for v in frame.poses[i] {
                    b.extend(v.to_le_bytes());
                }
                self.poses[i] = frame.poses[i];
            }
            for d in &drawings {
                // Handles are small positive integers; anything else cannot be drawn.
                b.extend((d.handle as u32).to_le_bytes());
                b.extend(d.kind.to_le_bytes());
                b.extend(d.size.to_le_bytes());
                for c in d.color {
                    b.extend(c.to_le_bytes());
                }
                b.extend(((d.vertices.len() / 3) as u32).to_le_bytes());
                for v in &d.vertices {
                    b.extend(v.to_le_bytes());
                }
            }
            for &h in &removed {
                b.extend((h as u32).to_le_bytes());
                b.extend(DRAWING_REMOVED.to_le_bytes());
                b.extend([0u8; 16]);
                b.extend(0u32.to_le_bytes());
            }
            for c in &clouds {
                // Object handles are small non-negative integers.
                b.extend((c.handle as u32).to_le_bytes());
                b.extend(0u32.to_le_bytes());
                b.extend(c.size.to_le_bytes());
                b.extend((c.len() as u32).to_le_bytes());
                for v in &c.points {
                    b.extend(v.to_le_bytes());
                }
                b.extend(&c.colors);
                b.resize(b.len().next_multiple_of(4), 0);
            }
            for &h in &clouds_gone {
                b.extend((h as u32).to_le_bytes());
                b.extend(DRAWING_REMOVED.to_le_bytes());
                b.extend([0u8; 8]);
            }
            out.binary = Some(b);
            if !drawings.is_empty() || !removed.is_empty() {
                self.drawings.clone_from(&frame.drawings);
            }
            if any_cloud {
                self.clouds = frame.point_clouds.iter().map(|c| (c.handle, c.generation)).collect();
            }
        }

        let scalars = (frame.time, frame.steps, frame.state, frame.steps_per_s, frame.rtf);
        let joints = self.joints != frame.joints || self.joint_target_velocities != frame.joint_target_velocities;
        let detections = self.detections != frame.detections;
        let selected = self.selected != Some(frame.selected);
        if self.scalars != Some(scalars) || joints || detections || selected {
            let mut tick = json!({
                "t": "tick",
                "time": frame.time,
                "steps": frame.steps,
                "state": frame.state,
                "steps_per_s": frame.steps_per_s,
                "rtf": frame.rtf,
                "ui_revision": frame.ui_revision,
            });
            if joints {
                tick["joints"] = json!(frame.joints);
                tick["joint_target_velocities"] = json!(frame.joint_target_velocities);
                self.joints.clone_from(&frame.joints);
                self.joint_target_velocities.clone_from(&frame.joint_target_velocities);
            }
            if detections {
                tick["detections"] = json!(frame.detections);
                self.detections.clone_from(&frame.detections);
            }
            if selected {
                tick["selected"] = match frame.selected {
                    Some(s) => json!({"handle": s.handle, "euler": s.euler}),
                    None => json!(null),
                };
                self.selected = Some(frame.selected);
            }
            self.scalars = Some(scalars);
            out.tick = Some(tick);
        }
        out
    }
}

/// Equal bit patterns: unlike `==`, a NaN (never sent) always differs from a number.
fn bit_equal(a: &[f32; 7], b: &[f32; 7]) -> bool {
    a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(x: f32) -> Frame {
        Frame {
            time: 0.5,
            steps: 10,
            state: 17,
            poses: vec![[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0], [x, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]],
            joints: vec![0.25],
            joint_target_velocities: vec![0.0],
            detections: vec![-1.0],
            drawings: vec![DrawingFrame {
                handle: 3,
                kind: 8,
                size: 2.0,
                color: [1.0, 1.0, 0.0],
                vertices: vec![1.0, 2.0, 3.0],
            }],
            ..Frame::default()
        }
    }

    fn u32_at(b: &[u8], i: usize) -> u32 {
        u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]])
    }

    #[test]
    fn first_delta_is_complete() {
        let mut d = FrameDelta::default();
        let m = d.update(&frame(1.0));
        let b = m.binary.expect("poses");
        assert_eq!([u32_at(&b, 0), u32_at(&b, 4), u32_at(&b, 8)], [MSG_FRAME, 2, 1]);
        // Header, two poses, one drawing of one vertex.
        assert_eq!(b.len(), 16 + 2 * 32 + 7 * 4 + 3 * 4);
        let tick = m.tick.expect("tick");
        assert_eq!(tick["joints"], json!([0.25]));
        assert_eq!(tick["detections"], json!([-1.0]));
    }

    #[test]
    fn only_changes_are_sent() {
        let mut d = FrameDelta::default();
        d.update(&frame(1.0));
        let same = d.update(&frame(1.0));
        assert!(same.binary.is_none() && same.tick.is_none(), "{same:?}");

        let moved = d.update(&frame(2.0));
        let b = moved.binary.expect("one pose");
        assert_eq!([u32_at(&b, 4), u32_at(&b, 8), u32_at(&b, 16)], [1, 0, 1]);
        assert_eq!(f32::from_le_bytes([b[20], b[21], b[22], b[23]]), 2.0);
        assert!(moved.tick.is_none(), "scalars did not change");

        let mut later = frame(2.0);
        later.time = 0.55;
        let tick = d.update(&later).tick.expect("time changed");
        assert!(tick.get("joints").is_none(), "joints did not change: {tick}");
    }

    #[test]
    fn the_picked_orientation_is_sent_when_it_changes() {
        let mut d = FrameDelta::default();
        let first = d.update(&frame(1.0)).tick.expect("first tick");
        assert_eq!(first["selected"], json!(null), "a first tick says nothing is picked");

        let mut picked = frame(1.0);
        picked.selected = Some(SelectedOrientation {
            handle: 7,
            euler: [0.5, -0.25, 1.0],
        });
        let tick = d.update(&picked).tick.expect("the pick changed");
        assert_eq!(tick["selected"], json!({"handle": 7, "euler": [0.5, -0.25, 1.0]}));
        assert!(d.update(&picked).tick.is_none(), "nothing changed");

        let cleared = d.update(&frame(1.0)).tick.expect("the pick was cleared");
        assert_eq!(cleared["selected"], json!(null));
        let mut later = frame(1.0);
        later.time = 0.55;
        let tick = d.update(&later).tick.expect("time changed");
        assert!(tick.get("selected").is_none(), "the pick did not change: {tick}");
    }

    #[test]
    fn removed_drawings_are_announced_once() {
        let mut d = FrameDelta::default();
        d.update(&frame(1.0));
        let mut gone = frame(1.0);
        gone.drawings.clear();
        let b = d.update(&gone).binary.expect("removal");
        assert_eq!([u32_at(&b, 4), u32_at(&b, 8)], [0, 1]);
        assert_eq!([u32_at(&b, 16), u32_at(&b, 20)], [3, DRAWING_REMOVED]);
        assert!(d.update(&gone).binary.is_none());
    }

    /// A simulation with one dummy, and a point cloud of two points (one red) below it
    /// at (1, 0, 0) in its frame.
    fn cloud_sim() -> (Sim, i64) {
        use gantry_sim_core::api::{CallContext, call};
        use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene_text};
        let text = "[[object]]\nname = \"base\"\nkind = \"dummy\"\nposition = [0, 0, 1]\n";
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("cloud.toml");
        let mut sim = Sim::new(&load_scene_text(&DiskFiles, text, &path, &LoadOptions::default()).expect("scene"));
        let mut api = |name: &str, args: &[gantry_sim_core::Value]| {
            call(&mut sim, &CallContext::default(), name, args).unwrap_or_else(|e| panic!("{e}"))
        };
        use gantry_sim_core::Value::{Array, Bool, Float, Int};
        let h = api("sim.createPointCloud", &[Float(0.01), Int(10), Int(0), Float(3.0)])[0]
            .as_i64()
            .expect("handle");
        api("sim.setObjectParent", &[Int(h), Int(0), Bool(false)]);
        api(
            "sim.setObjectPosition",
            &[Int(h), Int(0), gantry_sim_core::Value::floats(&[1.0, 0.0, 0.0])],
        );
        let points = gantry_sim_core::Value::floats(&[0.0, 0.0, 0.0, 0.5, 0.25, 0.0]);
        let colors = Array([255, 0, 0, 9, 9, 9].map(Int).to_vec());
        api("sim.insertPointsIntoPointCloud", &[Int(h), Int(3), points, colors]);
        (sim, h)
    }

    #[test]
    fn point_clouds_are_captured_in_their_frame_and_shared_while_unchanged() {
        let (mut sim, h) = cloud_sim();
        let f = Frame::capture(&sim);
        let c = &f.point_clouds[0];
        assert_eq!((c.handle, c.size, c.len()), (h, 3.0, 2));
        assert_eq!(c.points, [0.0, 0.0, 0.0, 0.5, 0.25, 0.0], "cloud frame, not world");
        assert_eq!(c.colors, [255, 0, 0, 9, 9, 9]);
        // The cloud's pose travels with the other poses: (1, 0, 1) in the world.
        let i = sim.world.handles().iter().position(|&x| x == h).expect("listed");
        assert_eq!(f.poses[i][..3], [1.0, 0.0, 1.0]);
        // The scene description lists it as a point cloud.
        let desc = super::super::scene::describe(&sim.world);
        assert_eq!(desc.json["objects"][i]["kind"], "point cloud");

        let again = Frame::capture_after(&sim, Some(&f));
        assert!(
            Arc::ptr_eq(&f.point_clouds[0], &again.point_clouds[0]),
            "not copied again"
        );
        let before = sim.world.point_cloud(h).expect("cloud").generation();
        sim.world.point_cloud_mut(h).expect("cloud").clear();
        let cleared = Frame::capture_after(&sim, Some(&again));
        assert!(cleared.point_clouds[0].is_empty(), "captured again once changed");
        assert_ne!(cleared.point_clouds[0].generation, before);
    }

    #[test]
    fn random_colours_are_stable_and_coppeliasims_range() {
        let a: Vec<[u8; 3]> = (0..100).map(random_color).collect();
        let b: Vec<[u8; 3]> = (0..100).map(random_color).collect();
        assert_eq!(a, b);
        assert!(a.iter().flatten().all(|&c| c >= 51), "each channel at least 0.2");
        assert!(a.windows(2).any(|w| w[0] != w[1]));
    }

    #[test]
    fn point_clouds_are_sent_when_they_change_and_announced_when_gone() {
        let (mut sim, h) = cloud_sim();
        let mut d = FrameDelta::default();
        let first = Frame::capture(&sim);
        let b = d.update(&first).binary.expect("poses and the cloud");
        let poses = u32_at(&b, 4) as usize;
        assert_eq!([u32_at(&b, 8), u32_at(&b, 12)], [0, 1], "no drawing, one cloud");
        let at = 16 + 32 * poses;
        assert_eq!(
            [u32_at(&b, at), u32_at(&b, at + 4), u32_at(&b, at + 12)],
            [h as u32, 0, 2]
        );
        assert_eq!(f32::from_le_bytes(b[at + 8..at + 12].try_into().unwrap()), 3.0);
        // Two points: 24 bytes of coordinates, 6 colour bytes padded to 8.
        assert_eq!(&b[at + 16 + 24..], [255, 0, 0, 9, 9, 9, 0, 0]);

        // Unchanged points are not sent again, even when the cloud moves.
        sim.world
            .set_world_pose(h, gantry_sim_core::math::Pose::translation(2.0, 0.0, 0.0))
            .expect("move");
        let moved = d
            .update(&Frame::capture_after(&sim, Some(&first)))
            .binary
            .expect("the pose");
        assert_eq!([u32_at(&moved, 4), u32_at(&moved, 12)], [1, 0]);

        // New points are.
        sim.world.point_cloud_mut(h).expect("cloud").clear();
        let b = d.update(&Frame::capture(&sim)).binary.expect("the emptied cloud");
        assert_eq!([u32_at(&b, 4), u32_at(&b, 12)], [0, 1]);
        assert_eq!(u32_at(&b, 16 + 12), 0, "no points");

        // A removed cloud is announced once.
        let mut gone = Frame::capture(&sim);
        gone.point_clouds.clear();
        let b = d.update(&gone).binary.expect("removal");
        assert_eq!(
            [u32_at(&b, 12), u32_at(&b, 16), u32_at(&b, 20)],
            [1, h as u32, DRAWING_REMOVED]
        );
        assert_eq!(b.len(), 16 + 16);
        assert!(d.update(&gone).binary.is_none());
    }

    #[test]
    fn reset_resends_everything() {
        let mut d = FrameDelta::default();
        d.update(&frame(1.0));
        d.reset();
        let m = d.update(&frame(1.0));
        assert!(m.binary.is_some() && m.tick.is_some());
    }
}
