//! The viewer in replay mode (`gantry replay FILE`): a clock over a [`Recording`]
//! instead of a running simulation.
//!
//! The world is the recorded scene, built and never stepped (its scripts are not even
//! loaded). A player task owns the replay clock (time, playing, speed); each time the
//! clock moves (a page's seek or step, or the play tick at [`PLAY_RATE`] Hz) it sends
//! the simulation thread one closure that sets every object's pose to the recording's
//! at that time ([`apply_at`]: joints first, then each object's world pose composed
//! from the recorded parent-relative poses, parents before children) and publishes the
//! [`Frame`] through the same `watch` channel the live viewer uses, so sessions, deltas
//! and the page's 3-D view are the live viewer's own.
//!
//! What the page shows beside the view comes from the recording, not the world: the
//! graph streams (every sample at once, the page draws a cursor at the current time),
//! the `/rosout` lines up to the current time, and the latest image of each recorded
//! vision sensor ([`ReplayPanels`]). The clock's state goes to the pages as
//! `{"t":"replay",...}` ([`ReplayStatus`]).

use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::{Duration, Instant};

use gantry_lua::Simulation;
use gantry_record::Recording;
use gantry_record::format::{WORLD_FRAME, topic_name};
use gantry_record::reader::FrameId;
use gantry_sim_core::Handle;
use gantry_sim_core::math::{Pose, Vec3, quat_from_array};
use gantry_sim_core::world::ObjectKind;
use gantry_sim_core::world::object_path::full_paths;
use serde::Serialize;
use serde_json::{Value as Json, json};
use tokio::sync::{mpsc, oneshot, watch};

use super::command::ReplayAction;
use super::frame::{Frame, FrameSender};
use super::panels::{MAX_LOG_LINES, MAX_LOG_MESSAGE, MSG_IMAGE, truncate};
use crate::sim_thread::{SendError, SimHandle};

/// Frames per second of the replay clock while playing.
pub const PLAY_RATE: f64 = 30.0;

/// The clock's state, as pages get it: `{"t":"replay", ...}`. Times are recording log
/// times, s.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ReplayStatus {
    /// The time shown.
    pub time: f64,
    /// The recording's first message.
    pub start: f64,
    /// Its last message.
    pub end: f64,
    /// Whether the clock runs.
    pub playing: bool,
    /// Replay seconds per wall-clock second.
    pub speed: f64,
    /// Index of the snapshot shown (the latest at or before `time`).
    pub frame: usize,
    /// Snapshots in the recording.
    pub frames: usize,
    /// Milliseconds the simulation thread took to set the poses and build the frame for
    /// `time` (what a scrub costs on the server).
    pub apply_ms: f64,
}

/// Why a replay command failed; the text is the reply's.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The player has stopped (gantry is shutting down).
    #[error("the replay has ended")]
    Ended,
    /// The simulation thread did not take the request.
    #[error(transparent)]
    Send(#[from] SendError),
}

/// One command to the player, with where its outcome goes.
struct PlayerRequest {
    action: ReplayAction,
    time: Option<f64>,
    speed: Option<f64>,
    frames: Option<i64>,
    reply: oneshot::Sender<Result<ReplayStatus, ReplayError>>,
}

/// A graph stream of the recording, as the page's graph panel takes it.
#[derive(Debug, Clone)]
struct GraphTrack {
    topic: String,
    /// The graph object's handle when the scene has it, else a number of its own.
    graph: i64,
    graph_alias: String,
    /// Index of the stream in its graph.
    id: i64,
    label: String,
}

/// What every session of a replay shares: the recording, the player's clock and how
/// recorded names map to the scene's objects.
#[derive(Clone)]
pub struct ReplayHub {
    rec: Arc<Recording>,
    /// Commands to the player task; closed when it ends.
    tx: mpsc::Sender<PlayerRequest>,
    /// The clock's state, sent by the player after each move.
    status: watch::Receiver<ReplayStatus>,
    graphs: Arc<Vec<GraphTrack>>,
    /// Image topics and the vision sensor each shows in.
    images: Arc<Vec<(String, Handle)>>,
}

impl ReplayHub {
    /// Maps the recording's frames onto the scene on the simulation thread, shows the
    /// recording's first snapshot and starts the player task (on the current runtime).
    ///
    /// # Errors
    /// The simulation thread did not answer.
    pub async fn start(rec: Arc<Recording>, sim: SimHandle, frames: FrameSender) -> Result<ReplayHub, SendError> {
        let names: Vec<String> = rec.frames().to_vec();
        let topics: Vec<String> = rec.graphs().keys().cloned().collect();
        let image_topics: Vec<String> = rec.image_topics().map(str::to_owned).collect();
        let image_frames: Vec<Option<String>> = image_topics
            .iter()
            .map(|t| rec.image_at(t, u64::MAX).map(|i| i.frame_id))
            .collect();
        let (map, graphs, images) = sim
            .with(move |s| {
                let core = s.core();
                let world = &core.world;
                let by_name = object_names(world);
                let map: Vec<Option<Handle>> = names.iter().map(|n| by_name.get(n).copied()).collect();
                let graph_objects: Vec<(String, Handle, String)> = by_name
                    .iter()
                    .filter(|(_, h)| world.object(**h).is_ok_and(|o| matches!(o.kind, ObjectKind::Graph)))
                    .map(|(n, &h)| {
                        let alias = world.object(h).map(|o| o.alias.clone()).unwrap_or_default();
                        (topic_name(&["graph", n]) + "/", h, alias)
                    })
                    .collect();
                let graphs = graph_tracks(&topics, &graph_objects);
                let images = image_topics
                    .iter()
                    .zip(&image_frames)
                    .filter_map(|(t, f)| Some((t.clone(), *by_name.get(f.as_deref()?)?)))
                    .collect();
                (map, graphs, images)
            })
            .await?;
        let map = Arc::new(map);
        let times: Arc<Vec<u64>> = Arc::new(rec.snapshot_times().collect());
        let clock = Clock::new(&rec);
        let apply_ms = show(&rec, &map, &sim, &frames, &clock).await?;
        let (status_tx, status) = watch::channel(clock.status(&rec, &times, apply_ms));
        let (tx, rx) = mpsc::channel(64);
        tokio::spawn(player(
            PlayerTask {
                rec: rec.clone(),
                map,
                times,
                sim,
                frames,
                status: status_tx,
            },
            clock,
            rx,
        ));
        Ok(ReplayHub {
            rec,
            tx,
            status,
            graphs: Arc::new(graphs),
            images: Arc::new(images),
        })
    }

    /// The clock's state now, and a receiver that sees its changes.
    pub fn status(&self) -> watch::Receiver<ReplayStatus> {
        self.status.clone()
    }

    /// The recording.
    pub fn recording(&self) -> &Recording {
        &self.rec
    }

    /// Carries out a timeline command; answers once the new time is on show.
    ///
    /// # Errors
    /// The player or the simulation has ended.
    pub async fn command(
        &self,
        action: ReplayAction,
        time: Option<f64>,
        speed: Option<f64>,
        frames: Option<i64>,
    ) -> Result<ReplayStatus, ReplayError> {
        let (reply, rx) = oneshot::channel();
        self.tx
            .send(PlayerRequest {
                action,
                time,
                speed,
                frames,
                reply,
            })
            .await
            .map_err(|_| ReplayError::Ended)?;
        rx.await.map_err(|_| ReplayError::Ended)?
    }

    /// `{"t":"replay",...}` for a page that just connected: the status, the file and
    /// what was wrong with it.
    pub fn hello(&self) -> Json {
        let mut j = status_json(&self.status.borrow());
        j["file"] = json!(self.rec.path().display().to_string());
        j["warnings"] = json!(self.rec.warnings());
        j
    }
}

/// Every object of `world` by its frame id in recordings (its path without the leading
/// `/`, as the recorder names it).
pub fn object_names(world: &gantry_sim_core::World) -> BTreeMap<String, Handle> {
    full_paths(world)
        .into_iter()
        .map(|(h, path)| (path.trim_start_matches('/').to_owned(), h))
        .collect()
}

/// The object of each of `rec`'s frames in `world` ([`apply_at`]'s map), by
/// [`FrameId`]; `None` for frames the scene does not have.
pub fn frame_handles(rec: &Recording, world: &gantry_sim_core::World) -> Vec<Option<Handle>> {
    let by_name = object_names(world);
    rec.frames().iter().map(|n| by_name.get(n).copied()).collect()
}

/// `{"t":"replay", ...status}`.
pub fn status_json(s: &ReplayStatus) -> Json {
    let mut j = serde_json::to_value(s).unwrap_or_else(|_| json!({}));
    j["t"] = json!("replay");
    j
}

/// Which graph each recorded stream belongs to: the graph object whose topic prefix
/// (`/graph/<its path>/`) starts the topic, or one made-up graph per prefix.
fn graph_tracks(topics: &[String], objects: &[(String, Handle, String)]) -> Vec<GraphTrack> {
    // Made-up graph numbers stay clear of the scene's handles.
    const UNKNOWN_GRAPHS: i64 = 1 << 40;
    let mut out: Vec<GraphTrack> = Vec::new();
    let mut unknown: BTreeMap<String, i64> = BTreeMap::new();
    for topic in topics {
        let (graph, alias, label) = match objects.iter().find(|(prefix, _, _)| topic.starts_with(prefix.as_str())) {
            Some((prefix, h, alias)) => (*h, alias.clone(), topic[prefix.len()..].to_owned()),
            None => {
                let (prefix, label) = topic.rsplit_once('/').unwrap_or(("", topic));
                let n = unknown.len() as i64;
                let graph = *unknown.entry(prefix.to_owned()).or_insert(UNKNOWN_GRAPHS + n);
                (graph, prefix.trim_start_matches("/graph/").to_owned(), label.to_owned())
            }
        };
        let id = out.iter().filter(|g| g.graph == graph).count() as i64;
        out.push(GraphTrack {
            topic: topic.clone(),
            graph,
            graph_alias: alias,
            id,
            label,
        });
    }
    out
}

/// The replay clock.
#[derive(Debug, Clone)]
struct Clock {
    /// The time on show, ns.
    t_ns: u64,
    playing: bool,
    speed: f64,
    /// While playing: the wall-clock instant and replay time the clock runs from.
    anchor: (Instant, u64),
}

impl Clock {
    fn new(rec: &Recording) -> Self {
        Self {
            t_ns: rec.start_ns(),
            playing: false,
            speed: 1.0,
            anchor: (Instant::now(), rec.start_ns()),
        }
    }

    fn status(&self, rec: &Recording, times: &[u64], apply_ms: f64) -> ReplayStatus {
        let frame = times.partition_point(|&t| t <= self.t_ns).saturating_sub(1);
        ReplayStatus {
            time: secs(self.t_ns),
            start: secs(rec.start_ns()),
            end: secs(rec.end_ns()),
            playing: self.playing,
            speed: self.speed,
            frame,
            frames: times.len(),
            apply_ms,
        }
    }

    /// Carries out a command.
    fn apply(&mut self, req: &PlayerRequest, rec: &Recording, times: &[u64]) {
        let now = Instant::now();
        match req.action {
            ReplayAction::Play => {
                if self.t_ns >= rec.end_ns() {
                    // Playing at the end starts over.
                    self.t_ns = rec.start_ns();
                }
                self.playing = true;
            }
            ReplayAction::Pause => self.playing = false,
            ReplayAction::Seek => {
                let t = req.time.unwrap_or(0.0);
                self.t_ns = nanos(t).clamp(rec.start_ns(), rec.end_ns());
            }
            ReplayAction::Step => {
                self.playing = false;
                let here = times.partition_point(|&t| t <= self.t_ns).saturating_sub(1);
                let k = req.frames.unwrap_or(1);
                let to = if k >= 0 {
                    here.saturating_add(k.unsigned_abs() as usize)
                } else {
                    here.saturating_sub(k.unsigned_abs() as usize)
                };
                if let Some(&t) = times.get(to.min(times.len().saturating_sub(1))) {
                    self.t_ns = t;
                }
            }
            ReplayAction::Speed => self.speed = req.speed.unwrap_or(1.0),
        }
        self.anchor = (now, self.t_ns);
    }

    /// Moves a playing clock to now; stops it at the end.
    fn advance(&mut self, rec: &Recording) {
        let (at, t0) = self.anchor;
        let elapsed = at.elapsed().as_secs_f64() * self.speed;
        self.t_ns = t0.saturating_add(nanos(elapsed)).min(rec.end_ns());
        if self.t_ns >= rec.end_ns() {
            self.playing = false;
        }
    }
}

/// Seconds from nanoseconds.
fn secs(ns: u64) -> f64 {
    ns as f64 * 1e-9
}

/// Nanoseconds from seconds (negative and non-finite: 0; saturating).
fn nanos(s: f64) -> u64 {
    if s.is_finite() && s > 0.0 {
        (s * 1e9).round() as u64
    } else {
        0
    }
}

/// What the player task owns besides its clock.
struct PlayerTask {
    rec: Arc<Recording>,
    /// Object handle of each recorded frame, by [`FrameId`].
    map: Arc<Vec<Option<Handle>>>,
    /// Snapshot times, ns.
    times: Arc<Vec<u64>>,
    sim: SimHandle,
    frames: FrameSender,
    /// Read by every session; only the player sends.
    status: watch::Sender<ReplayStatus>,
}

/// The player: moves the clock on commands and, while playing, [`PLAY_RATE`] times a
/// second; shows each new time. Ends when every hub is dropped.
async fn player(task: PlayerTask, mut clock: Clock, mut rx: mpsc::Receiver<PlayerRequest>) {
    let mut tick = tokio::time::interval(Duration::from_secs_f64(1.0 / PLAY_RATE));
    tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
    loop {
        let reply = tokio::select! {
            req = rx.recv() => {
                let Some(req) = req else { break };
                clock.apply(&req, &task.rec, &task.times);
                Some(req.reply)
            }
            _ = tick.tick(), if clock.playing => {
                clock.advance(&task.rec);
                None
            }
        };
        let shown = show(&task.rec, &task.map, &task.sim, &task.frames, &clock).await;
        let result = match shown {
            Ok(apply_ms) => {
                let s = clock.status(&task.rec, &task.times, apply_ms);
                task.status.send_replace(s.clone());
                Ok(s)
            }
            Err(e) => Err(ReplayError::Send(e)),
        };
        if let Some(reply) = reply {
            let _ = reply.send(result);
        } else if matches!(result, Err(ReplayError::Send(SendError::Closed))) {
            break;
        }
    }
}

/// Shows the clock's time: the poses set and a frame published, on the simulation
/// thread. Returns the milliseconds that took there.
async fn show(
    rec: &Arc<Recording>,
    map: &Arc<Vec<Option<Handle>>>,
    sim: &SimHandle,
    frames: &FrameSender,
    clock: &Clock,
) -> Result<f64, SendError> {
    let (rec, map, frames) = (rec.clone(), map.clone(), frames.clone());
    let (t_ns, playing, speed) = (clock.t_ns, clock.playing, clock.speed);
    sim.with(move |s| {
        let started = Instant::now();
        let mut frame = apply_at(&rec, &map, t_ns, s);
        frame.time = secs(t_ns);
        // The page's badge: running while playing, paused otherwise.
        frame.state = if playing { 17 } else { 8 };
        frame.rtf = if playing { speed } else { 0.0 };
        frames.send_replace(Arc::new(frame));
        started.elapsed().as_secs_f64() * 1e3
    })
    .await
}

/// Sets the world to the recording's state at `t_ns` and captures the frame the viewer
/// draws: joint positions first (they move their subtrees), then every recorded
/// object's world pose, composed from the parent-relative poses of the tree at that
/// time (`world` is the identity) and set parents before children, so that each is
/// exactly the recorded one. Frames the scene does not have (objects scripts created
/// during the run) are skipped.
pub fn apply_at(rec: &Recording, map: &[Option<Handle>], t_ns: u64, sim: &mut Simulation) -> Frame {
    let handle = |id: FrameId| map.get(id.0 as usize).copied().flatten();
    let mut core = sim.core_mut();
    let world = &mut core.world;
    if let Some(js) = rec.joints_at(t_ns) {
        for (&name, &q) in js.names.iter().zip(&js.position) {
            if let Some(h) = handle(name) {
                // A recorded position is within the joint's limits; a refusal (not a
                // joint any more) leaves it, and the poses below place its children.
                let _ = world.set_joint_position(h, q);
            }
        }
    }
    let tree = rec.tree_at(t_ns);
    let mut poses: Vec<Option<Pose>> = vec![None; rec.frames().len()];
    let root = rec.frame_id(WORLD_FRAME);
    // Parents usually come first, so one pass places nearly everything; a static frame
    // under a moving one may need another. A frame whose parent never resolves (a
    // cycle, a missing parent) stays unplaced.
    let mut pending: Vec<_> = tree.iter().collect();
    while !pending.is_empty() {
        let before = pending.len();
        pending.retain(|f| {
            let parent = if Some(f.parent) == root {
                Some(Pose::identity())
            } else {
                poses.get(f.parent.0 as usize).copied().flatten()
            };
            let Some(parent) = parent else { return true };
            let [x, y, z, qx, qy, qz, qw] = f.pose;
            let Some(q) = quat_from_array([qx, qy, qz, qw]) else {
                return false;
            };
            let local = Pose::from_parts(Vec3::new(x, y, z).into(), q);
            if let Some(slot) = poses.get_mut(f.child.0 as usize) {
                *slot = Some(parent * local);
            }
            false
        });
        if pending.len() == before {
            break;
        }
    }
    let mut by_handle: BTreeMap<Handle, Pose> = BTreeMap::new();
    for (i, p) in poses.iter().enumerate() {
        if let (Some(p), Some(h)) = (p, map.get(i).copied().flatten()) {
            by_handle.insert(h, *p);
        }
    }
    // `handles()` lists parents before children: a parent set later would carry its
    // children away from their recorded poses.
    let order: Vec<Handle> = world.handles().to_vec();
    for h in order {
        if let Some(p) = by_handle.get(&h) {
            let _ = world.set_world_pose(h, *p);
        }
    }
    drop(core);
    Frame::capture(&sim.core())
}

/// What a session of a replay has sent of the panels.
#[derive(Debug, Default)]
pub struct ReplayPanels {
    /// Whether the graph streams went out (all at once, on the first update).
    graphs_sent: bool,
    /// The time the log shows lines up to, ns; `None` before the first update.
    log_until: Option<u64>,
    /// Per image topic: the time of the image on show.
    images: BTreeMap<String, u64>,
    /// The clock's time at the last update, ns: nothing changes while it stays.
    shown: Option<u64>,
}

impl ReplayPanels {
    /// What changed for a page showing time `status.time`: `{"t":"panels", ...}` with
    /// the graphs (the first time), the log lines up to now (`log_reset` when the time
    /// went back, so the page starts the log over) and the images.
    pub fn update(&mut self, hub: &ReplayHub, status: &ReplayStatus) -> (Option<Json>, Vec<Vec<u8>>) {
        let rec = &hub.rec;
        let t_ns = nanos(status.time);
        if self.shown == Some(t_ns) {
            return (None, Vec::new());
        }
        self.shown = Some(t_ns);
        let mut msg = serde_json::Map::new();
        if !self.graphs_sent {
            self.graphs_sent = true;
            let palette = [
                [0.9, 0.3, 0.2],
                [0.2, 0.6, 0.9],
                [0.3, 0.8, 0.3],
                [0.9, 0.7, 0.2],
                [0.7, 0.4, 0.9],
            ];
            let graphs: Vec<Json> = hub
                .graphs
                .iter()
                .map(|g| {
                    let samples: Vec<[f64; 2]> = rec
                        .graphs()
                        .get(&g.topic)
                        .map(|s| s.iter().map(|&(t, v)| [secs(t), v]).collect())
                        .unwrap_or_default();
                    json!({
                        "graph": g.graph,
                        "graph_alias": g.graph_alias,
                        "id": g.id,
                        "label": g.label,
                        "unit": "",
                        "color": palette[g.id as usize % palette.len()],
                        "reset": true,
                        "samples": samples,
                    })
                })
                .collect();
            if !graphs.is_empty() {
                msg.insert("graphs".into(), Json::Array(graphs));
            }
        }
        let lines = rec.logs_until(t_ns);
        let from = match self.log_until {
            Some(shown) if shown <= t_ns => lines.partition_point(|l| l.time_ns <= shown),
            _ => {
                msg.insert("log_reset".into(), json!(true));
                0
            }
        };
        if self.log_until != Some(t_ns) {
            // A page shows its newest lines: after a jump, only the last MAX_LOG_LINES.
            let from = from.max(lines.len().saturating_sub(MAX_LOG_LINES));
            let log: Vec<Json> = lines[from..]
                .iter()
                .enumerate()
                .map(|(i, l)| {
                    json!({
                        "seq": from + i,
                        "time": secs(l.stamp_ns),
                        "verbosity": verbosity(l.level),
                        "source": l.name,
                        "message": truncate(&l.msg, MAX_LOG_MESSAGE),
                    })
                })
                .collect();
            if !log.is_empty() {
                msg.insert("log".into(), Json::Array(log));
            }
            self.log_until = Some(t_ns);
        }
        let mut images = Vec::new();
        for (topic, handle) in hub.images.iter() {
            let Some(img) = rec.image_at(topic, t_ns) else { continue };
            if self.images.get(topic) == Some(&img.time_ns) {
                continue;
            }
            self.images.insert(topic.clone(), img.time_ns);
            if let Some(b) = encode_image(*handle, &img) {
                images.push(b);
            }
        }
        let json = (!msg.is_empty()).then(|| {
            msg.insert("t".into(), json!("panels"));
            Json::Object(msg)
        });
        (json, images)
    }
}

/// CoppeliaSim's verbosity for a ROS level (what the page colours lines by).
fn verbosity(level: u8) -> i64 {
    match level {
        0..=10 => 600,
        11..=20 => 450,
        21..=30 => 300,
        _ => 200,
    }
}

/// A recorded `rgb8` image as the page's [`MSG_IMAGE`] message: the bottom row first,
/// as the live viewer sends a vision sensor's image. Other encodings are not shown.
fn encode_image(handle: Handle, img: &gantry_record::reader::ImageFrame) -> Option<Vec<u8>> {
    let (w, h, step) = (img.width as usize, img.height as usize, img.step as usize);
    let row = w.checked_mul(3)?;
    if img.encoding != "rgb8" || step < row || img.data.len() < step.checked_mul(h)? {
        return None;
    }
    let mut b = Vec::with_capacity(16 + row * h);
    for v in [MSG_IMAGE, u32::try_from(handle).ok()?, img.width, img.height] {
        b.extend(v.to_le_bytes());
    }
    for y in (0..h).rev() {
        b.extend(&img.data[y * step..y * step + row]);
    }
    Some(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recorded_streams_are_grouped_by_the_graph_they_belong_to() {
        let topics = vec![
            "/graph/bubbleRob_graph/speed".to_owned(),
            "/graph/bubbleRob_graph/turn".to_owned(),
            "/graph/lost/x".to_owned(),
        ];
        let objects = vec![("/graph/bubbleRob_graph/".to_owned(), 30, "graph".to_owned())];
        let g = graph_tracks(&topics, &objects);
        assert_eq!(
            g.iter().map(|t| (t.graph, t.id, t.label.as_str())).collect::<Vec<_>>(),
            vec![(30, 0, "speed"), (30, 1, "turn"), (1 << 40, 0, "x")]
        );
        assert_eq!(g[2].graph_alias, "lost");
    }

    #[test]
    fn images_go_out_bottom_row_first() {
        let img = gantry_record::reader::ImageFrame {
            time_ns: 0,
            frame_id: "cam".into(),
            width: 1,
            height: 2,
            encoding: "rgb8".into(),
            step: 3,
            data: vec![1, 2, 3, 4, 5, 6],
        };
        let b = encode_image(7, &img).expect("encoded");
        assert_eq!(&b[16..], &[4, 5, 6, 1, 2, 3]);
        assert_eq!(u32::from_le_bytes([b[4], b[5], b[6], b[7]]), 7);
        let bad = gantry_record::reader::ImageFrame {
            encoding: "mono8".into(),
            ..img
        };
        assert!(encode_image(7, &bad).is_none());
    }
}
