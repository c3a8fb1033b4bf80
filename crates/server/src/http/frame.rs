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
//! only the poses, joints and drawings that changed go over the wire.

use std::sync::Arc;
use std::time::{Duration, Instant};

use gantry_script::Simulation;
use gantry_sim_core::Sim;
use gantry_sim_core::drawing::DrawingKind;
use gantry_sim_core::math::euler_from_quat;
use gantry_sim_core::world::ObjectKind;
use serde_json::json;
use tokio::sync::watch;

use crate::sim_thread::Observer;

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
        let (tx, _) = watch::channel(Arc::new(Frame::default()));
        let tx = Arc::new(tx);
        let publisher = FramePublisher {
            tx: tx.clone(),
            last: None,
            last_run_steps: 0,
            window: None,
            rates: (0.0, 0.0),
        };
        (publisher, tx)
    }
}

impl Observer for FramePublisher {
    fn observe(&mut self, sim: &Simulation, run_steps: u64) {
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
        let core = sim.core();
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
        let mut frame = Frame::capture(&core);
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
    /// drawing count, `u32` 0; per pose `u32` object index and 7 `f32`; per drawing
    /// `u32` handle, `u32` kind ([`DRAWING_REMOVED`] when gone), `f32` size, 3 `f32`
    /// colour, `u32` vertex count and 3 `f32` per vertex.
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
        if !changed.is_empty() || !drawings.is_empty() || !removed.is_empty() {
            let count = drawings.len() + removed.len();
            let mut b = Vec::with_capacity(16 + 32 * changed.len());
            for v in [MSG_FRAME, changed.len() as u32, count as u32, 0] {
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
            out.binary = Some(b);
            if !drawings.is_empty() || !removed.is_empty() {
                self.drawings.clone_from(&frame.drawings);
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

    #[test]
    fn reset_resends_everything() {
        let mut d = FrameDelta::default();
        d.update(&frame(1.0));
        d.reset();
        let m = d.update(&frame(1.0));
        assert!(m.binary.is_some() && m.tick.is_some());
    }
}
