//! The topics a ROS user expects from a simulator, without a script (`gantry run SCENE
//! --ros2`): `/clock`, `/tf` and `/tf_static` for the object tree, `/joint_states`,
//! `/robot_description` for URDF robots, and each vision sensor's RGB image, depth image
//! and camera info. Published after each step by the simulation thread (which owns the
//! world); the DDS thread sends.
//!
//! Names, frames and QoS (docs/ros2.md has the table):
//! - `/clock` (`rosgraph_msgs/Clock`): simulation time after each step; nothing while
//!   paused or stopped, so `use_sim_time` nodes pause with the simulation.
//! - `/tf` (depth 100) and `/tf_static` (transient local, depth 1): each object's pose
//!   relative to its parent, parent frame `world` for roots (REP 105's fixed frame);
//!   frame ids are object paths without the leading `/`, except for URDF robots, named
//!   as robot_state_publisher names them: a link's object by the URDF link name
//!   (`<robot>/` first when the scene holds several URDF robots), and the URDF joints'
//!   objects left out, so a link's TF parent is its parent link ([`crate::description`]).
//! - `/joint_states`: every revolute and prismatic joint, named by its frame id (a URDF
//!   joint by its URDF name); rad, rad/s, N·m (m, m/s, N for prismatic joints; REP 103).
//! - `/robot_description` (`std_msgs/String`, transient local, depth 1): the URDF text
//!   of the scene's one URDF robot; with several, `/<robot>/robot_description` each.
//!   Published once per robot (the durability hands it to late subscribers), and again
//!   when a load or removal changes the scene's URDF robots.
//! - `/<sensor>/image_raw` (`rgb8`), `/<sensor>/depth/image_raw` (`32FC1`, m, +inf
//!   where nothing is seen within the far plane) and `/<sensor>/camera_info`, top row
//!   first, in the sensor's frame, at most the sensor's `ros2_rate` (scene key) or else
//!   [`GraphOptions::camera_rate_hz`] per simulated second.
//! - Joint commands in, as `ros2_control`'s forward command controllers take them: for
//!   each model base with joints below it (a robot), `std_msgs/Float64MultiArray` on
//!   `/<robot>/forward_position_controller/commands` (rad or m) and
//!   `/<robot>/forward_velocity_controller/commands` (rad/s or m/s), one value per joint
//!   in the order `/joint_states` lists them. A command received during a step is set
//!   (`sim.setJointTargetPosition` / `sim.setJointTargetVelocity`) after it, so it acts
//!   from the next step on; one of the wrong length is dropped with a warning.

use std::collections::HashMap;
use std::sync::Arc;
use std::sync::mpsc::{Receiver, SyncSender};
use std::thread::JoinHandle;

use gantry_engine::Observer;
use gantry_ros::msg::{self, Time, nanos_from_secs};
use gantry_ros::{Direction, EndpointId, FrameNames, NetworkError, RosNetwork, RosQos, Sampler, Snapshot, TfFrames};
use gantry_sim_core::api::Target;
use gantry_sim_core::scene::{JointType, Projection};
use gantry_sim_core::vision;
use gantry_sim_core::vision::VisionStates;
use gantry_sim_core::world::ObjectKind;
use gantry_sim_core::{Handle, Sim, Value};

use crate::description::{Descriptions, RosNames};
pub use crate::topics::topic_token;
use crate::topics::{open, send};

/// What the graph publishes besides the always-on topics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GraphOptions {
    /// Images per simulated second of each vision sensor whose scene sets no
    /// `ros2_rate`, at most (0: none).
    pub camera_rate_hz: f64,
}

impl Default for GraphOptions {
    fn default() -> Self {
        Self { camera_rate_hz: 30.0 }
    }
}

/// One vision sensor's topics.
struct Camera {
    image: EndpointId,
    depth: EndpointId,
    info: EndpointId,
    /// Simulation time of the last image published, ns.
    last_ns: Option<u64>,
}

/// Snapshots waiting for the encoder, at most (about a second of a fast run's worth of
/// `/tf` is never needed: ROS consumers want the newest).
const ENCODER_QUEUE: usize = 64;

/// How long the encoder rests between batches (see [`Encoder::run`]).
const BATCH_PERIOD: std::time::Duration = std::time::Duration::from_millis(1);

/// The always-on topics, encoded and sent on a thread of their own.
struct Encoder {
    net: Arc<dyn RosNetwork>,
    clock: EndpointId,
    tf: EndpointId,
    tf_static: EndpointId,
    joint_states: EndpointId,
    frames: TfFrames,
}

impl Encoder {
    fn open(net: Arc<dyn RosNetwork>) -> Result<Self, NetworkError> {
        let n = net.as_ref();
        let clock = open(
            n,
            Direction::Publish,
            "/clock",
            "rosgraph_msgs/msg/Clock",
            RosQos::default(),
        )?;
        let tf = open(
            n,
            Direction::Publish,
            "/tf",
            "tf2_msgs/msg/TFMessage",
            RosQos {
                depth: 100,
                ..RosQos::default()
            },
        )?;
        let tf_static = open(
            n,
            Direction::Publish,
            "/tf_static",
            "tf2_msgs/msg/TFMessage",
            RosQos {
                depth: 1,
                transient_local: true,
                reliable: true,
            },
        )?;
        let joint_states = open(
            n,
            Direction::Publish,
            "/joint_states",
            "sensor_msgs/msg/JointState",
            RosQos::default(),
        )?;
        Ok(Self {
            net,
            clock,
            tf,
            tf_static,
            joint_states,
            frames: TfFrames::tolerant(),
        })
    }

    /// Publishes each snapshot until the graph is dropped, then closes the topics.
    ///
    /// A fast run steps thousands of times a second; waking this thread (and the DDS
    /// thread behind it) for each step would cost more than the messages. So it takes
    /// what has queued up, publishes it all, and rests [`BATCH_PERIOD`] before looking
    /// again: at most a millisecond later, in batches.
    fn run(mut self, rx: &Receiver<(Snapshot, Arc<RosNames>)>) {
        while let Ok((mut s, names)) = rx.recv() {
            names.apply(&mut s);
            self.publish(&s);
            while let Ok((mut s, names)) = rx.try_recv() {
                names.apply(&mut s);
                self.publish(&s);
            }
            std::thread::sleep(BATCH_PERIOD);
        }
        for id in [self.clock, self.tf, self.tf_static, self.joint_states] {
            self.net.close(id);
        }
    }

    fn write(&self, id: EndpointId, message: &[u8]) {
        send(self.net.as_ref(), id, message);
    }

    fn publish(&mut self, s: &Snapshot) {
        let stamp = Time::from_nanos(s.stamp_ns);
        self.write(self.clock, &msg::clock(stamp));
        let (statics, tf) = self.frames.messages(s);
        if let Some(m) = statics {
            self.write(self.tf_static, &m);
        }
        self.write(self.tf, &tf);
        if !s.joints.is_empty() {
            let names: Vec<&str> = s.joints.iter().map(|j| s.frame(j.handle)).collect();
            let position: Vec<f64> = s.joints.iter().map(|j| j.position).collect();
            let velocity: Vec<f64> = s.joints.iter().map(|j| j.velocity).collect();
            let effort: Vec<f64> = s.joints.iter().map(|j| j.effort).collect();
            self.write(
                self.joint_states,
                &msg::joint_state(stamp, &names, &position, &velocity, &effort),
            );
        }
    }
}

/// One robot's command topics.
struct Robot {
    /// Its frame id, for messages.
    name: String,
    /// Its joints, in tree order.
    joints: Vec<Handle>,
    position: EndpointId,
    velocity: EndpointId,
    /// Whether a malformed command was reported.
    warned: bool,
}

/// The graph's endpoints and what it remembers between steps (see the module docs).
pub struct RosGraph {
    net: Arc<dyn RosNetwork>,
    options: GraphOptions,
    /// Snapshots to the encoder's thread, with the names to publish them under; `None`
    /// once dropped (at the end).
    encoder: Option<SyncSender<(Snapshot, Arc<RosNames>)>>,
    worker: Option<JoinHandle<()>>,
    /// Snapshots the encoder's full queue refused.
    dropped: u64,
    cameras: HashMap<Handle, Camera>,
    /// The robots' command topics, opened at the first step.
    robots: Option<Vec<Robot>>,
    sampler: Sampler,
    /// Simulation time of the last publication, ns.
    last_ns: Option<u64>,
    /// The frame names (object paths) of the tree the cameras', robots' and
    /// descriptions' topics were opened for.
    tree: Option<FrameNames>,
    /// How that tree is named on the graph (URDF links by link name).
    names: Arc<RosNames>,
    /// The URDF robots' `/robot_description` topics.
    descriptions: Descriptions,
    /// The cameras' renders: the graph's own, so that publishing an image never
    /// changes what the scripts' sensors hold.
    vision: VisionStates,
    /// The joint commands received since the last step, as calls for the engine.
    commands: Vec<(Target, Vec<Value>)>,
}

impl RosGraph {
    /// Opens the always-on topics on `net`.
    ///
    /// # Errors
    /// The network could not start or open them.
    pub fn new(net: Arc<dyn RosNetwork>, options: GraphOptions) -> Result<Self, NetworkError> {
        let encoder = Encoder::open(net.clone())?;
        let (tx, rx) = std::sync::mpsc::sync_channel::<(Snapshot, Arc<RosNames>)>(ENCODER_QUEUE);
        let worker = std::thread::Builder::new()
            .name("gantry-ros2-graph".to_owned())
            .spawn(move || encoder.run(&rx))
            .map_err(|e| NetworkError(format!("cannot start the graph's encoder: {e}")))?;
        Ok(Self {
            net,
            options,
            encoder: Some(tx),
            worker: Some(worker),
            dropped: 0,
            cameras: HashMap::new(),
            robots: None,
            sampler: Sampler::new(None),
            last_ns: None,
            tree: None,
            names: Arc::default(),
            descriptions: Descriptions::default(),
            vision: VisionStates::default(),
            commands: Vec::new(),
        })
    }

    fn write(&self, id: EndpointId, message: &[u8]) {
        send(self.net.as_ref(), id, message);
    }

    /// Publishes the state after a step (nothing when simulation time has not moved).
    pub fn after_step(&mut self, sim: &Sim) {
        let snapshot = {
            let core = sim;
            let now = nanos_from_secs(core.world.time());
            if self.last_ns.is_some_and(|t| t == now) {
                return;
            }
            self.last_ns = Some(now);
            self.sampler.sample(core)
        };
        let Some(mut s) = snapshot else { return };
        {
            let core = sim;
            s.joints.retain(|j| movable(&core.world, j.handle));
        }
        // The frame names are shared until the object tree changes (a scene or model
        // loaded, an object removed): then handles may name other objects, so the
        // cameras', robots' and descriptions' topics are opened afresh, and the graph's
        // names made again.
        let frames = s.frames.clone();
        if !self.tree.as_ref().is_some_and(|t| Arc::ptr_eq(t, &frames)) {
            self.tree = Some(frames.clone());
            self.close_tree_topics();
            let core = sim;
            self.names = Arc::new(RosNames::new(&core.world, &frames));
            self.descriptions.refresh(self.net.as_ref(), &core.world, &frames);
        }
        // Encoding and sending happen on the encoder's thread: the simulation thread
        // only copies numbers. A full queue (the network cannot keep up) drops the
        // snapshot, counted, rather than slowing the simulation.
        let stamp_ns = s.stamp_ns;
        if let Some(tx) = &self.encoder
            && tx.try_send((s, self.names.clone())).is_err()
        {
            self.dropped += 1;
            if self.dropped.is_power_of_two() {
                tracing::warn!(
                    "ROS 2 graph: {} steps not published (the network is behind)",
                    self.dropped
                );
            }
        }
        self.cameras_after_step(sim, &frames, stamp_ns);
        if self.robots.is_none() {
            self.robots = Some(self.open_robots(sim, &frames));
        }
        self.read_commands();
    }

    /// Closes the topics opened for the objects of the tree (cameras and robots).
    fn close_tree_topics(&mut self) {
        for c in std::mem::take(&mut self.cameras).into_values() {
            for id in [c.image, c.depth, c.info] {
                self.net.close(id);
            }
        }
        for r in self.robots.take().into_iter().flatten() {
            self.net.close(r.position);
            self.net.close(r.velocity);
        }
    }

    /// Opens the command topics of every model base with joints below it.
    fn open_robots(&self, sim: &Sim, frames: &[String]) -> Vec<Robot> {
        let core = sim;
        let world = &core.world;
        let mut robots = Vec::new();
        for &h in world.handles() {
            if !world.object(h).is_ok_and(|o| o.model_base) {
                continue;
            }
            let joints: Vec<Handle> = world
                .handles()
                .iter()
                .copied()
                .filter(|&j| movable(world, j) && below(world, j, h))
                .collect();
            if joints.is_empty() {
                continue;
            }
            let name = usize::try_from(h)
                .ok()
                .and_then(|i| frames.get(i))
                .cloned()
                .unwrap_or_default();
            let base = format!("/{}", topic_token(&name));
            let n = self.net.as_ref();
            let ty = "std_msgs/msg/Float64MultiArray";
            let opened = open(
                n,
                Direction::Subscribe,
                &format!("{base}/forward_position_controller/commands"),
                ty,
                RosQos::default(),
            )
            .and_then(|p| {
                open(
                    n,
                    Direction::Subscribe,
                    &format!("{base}/forward_velocity_controller/commands"),
                    ty,
                    RosQos::default(),
                )
                .map(|v| (p, v))
            });
            match opened {
                Ok((position, velocity)) => robots.push(Robot {
                    name,
                    joints,
                    position,
                    velocity,
                    warned: false,
                }),
                Err(e) => tracing::warn!("ROS 2 graph: no command topics for {name}: {e}"),
            }
        }
        robots
    }

    /// Reads the latest commands into the joint-target calls they ask for, which the
    /// engine carries out before the next step ([`Observer::calls`]).
    fn read_commands(&mut self) {
        let Some(robots) = self.robots.as_mut() else { return };
        let ty = match gantry_protocol::ros::message_type("std_msgs/msg/Float64MultiArray") {
            Ok(t) => t,
            Err(_) => return,
        };
        for r in robots {
            for (id, function) in [
                (r.position, "setJointTargetPosition"),
                (r.velocity, "setJointTargetVelocity"),
            ] {
                // Only the newest command counts: the ones before it were overtaken.
                let Some(sample) = self.net.take(id, usize::MAX).pop() else {
                    continue;
                };
                let values = ty
                    .decode_body(&sample.body, sample.little_endian, 0)
                    .map_err(|e| e.to_string())
                    .and_then(|v| match v.get("data") {
                        Some(gantry_protocol::Value::Array(a)) => Ok(a
                            .iter()
                            .filter_map(gantry_protocol::Value::as_f64)
                            .collect::<Vec<f64>>()),
                        _ => Err("no data".to_owned()),
                    })
                    .and_then(|v| {
                        if v.len() == r.joints.len() {
                            Ok(v)
                        } else {
                            Err(format!("{} values for {} joints", v.len(), r.joints.len()))
                        }
                    });
                let values = match values {
                    Ok(v) => v,
                    Err(e) => {
                        if !std::mem::replace(&mut r.warned, true) {
                            tracing::warn!("ROS 2: a joint command for {} was dropped: {e}", r.name);
                        }
                        continue;
                    }
                };
                let Some(target) = Target::resolve(function) else {
                    continue;
                };
                for (&j, &v) in r.joints.iter().zip(&values) {
                    self.commands.push((target, vec![Value::Int(j), Value::Float(v)]));
                }
            }
        }
    }

    /// Renders (when stale) and publishes the vision sensors whose period has passed.
    fn cameras_after_step(&mut self, sim: &Sim, frames: &[String], stamp_ns: u64) {
        // Each sensor's rate: its scene's `ros2_rate`, else the run's; 0 is none.
        let sensors: Vec<(Handle, f64)> = {
            let core = sim;
            core.world
                .handles()
                .iter()
                .filter_map(|&h| match core.world.object(h).map(|o| &o.kind) {
                    Ok(ObjectKind::VisionSensor(v)) => Some((h, v.ros2_rate.unwrap_or(self.options.camera_rate_hz))),
                    _ => None,
                })
                .filter(|(_, rate)| rate.is_finite() && *rate > 0.0)
                .collect()
        };
        for (h, rate) in sensors {
            let period_ns = nanos_from_secs(1.0 / rate);
            let frame = usize::try_from(h)
                .ok()
                .and_then(|i| frames.get(i))
                .cloned()
                .unwrap_or_default();
            if !self.cameras.contains_key(&h) {
                match self.open_camera(&frame) {
                    Ok(c) => {
                        self.cameras.insert(h, c);
                    }
                    Err(e) => {
                        tracing::warn!("ROS 2 graph: no topics for vision sensor {frame}: {e}");
                        continue;
                    }
                }
            }
            let due = self.cameras[&h]
                .last_ns
                .is_none_or(|t| stamp_ns < t || stamp_ns - t >= period_ns);
            if !due {
                continue;
            }
            let messages = camera_messages(&sim.world, &mut self.vision, h, &frame, Time::from_nanos(stamp_ns));
            match messages {
                Ok([image, depth, info]) => {
                    let c = &self.cameras[&h];
                    let ids = (c.image, c.depth, c.info);
                    self.write(ids.0, &image);
                    self.write(ids.1, &depth);
                    self.write(ids.2, &info);
                    if let Some(c) = self.cameras.get_mut(&h) {
                        c.last_ns = Some(stamp_ns);
                    }
                }
                Err(e) => tracing::debug!("ROS 2 graph: vision sensor {frame}: {e}"),
            }
        }
    }

    fn open_camera(&self, frame: &str) -> Result<Camera, NetworkError> {
        let base = format!("/{}", topic_token(frame));
        let n = self.net.as_ref();
        let q = RosQos {
            depth: 5,
            ..RosQos::default()
        };
        Ok(Camera {
            image: open(
                n,
                Direction::Publish,
                &format!("{base}/image_raw"),
                "sensor_msgs/msg/Image",
                q,
            )?,
            depth: open(
                n,
                Direction::Publish,
                &format!("{base}/depth/image_raw"),
                "sensor_msgs/msg/Image",
                q,
            )?,
            info: open(
                n,
                Direction::Publish,
                &format!("{base}/camera_info"),
                "sensor_msgs/msg/CameraInfo",
                q,
            )?,
            last_ns: None,
        })
    }
}

/// The graph publishes after each step the engine takes, and hands it the joint
/// commands it received, as a front end's calls.
impl Observer for RosGraph {
    fn stepped(&mut self, sim: &Sim, _steps: u64) {
        self.after_step(sim);
    }

    fn calls(&mut self) -> Vec<(Target, Vec<Value>)> {
        std::mem::take(&mut self.commands)
    }
}

/// Whether `h` is a revolute or prismatic joint (fixed joints are frames on `/tf`, as
/// robot_state_publisher has them, not entries of `/joint_states`).
fn movable(world: &gantry_sim_core::World, h: Handle) -> bool {
    matches!(world.object(h).map(|o| &o.kind), Ok(ObjectKind::Joint(j)) if j.joint_type != JointType::Fixed)
}

/// Whether `h` is `ancestor` or below it.
fn below(world: &gantry_sim_core::World, h: Handle, ancestor: Handle) -> bool {
    let mut at = Some(h);
    while let Some(x) = at {
        if x == ancestor {
            return true;
        }
        at = world.object(x).ok().and_then(|o| o.parent);
    }
    false
}

impl Drop for RosGraph {
    fn drop(&mut self) {
        // The encoder publishes what is queued, closes its topics and ends.
        self.encoder = None;
        if let Some(w) = self.worker.take() {
            let _ = w.join();
        }
        self.close_tree_topics();
        self.descriptions.close(self.net.as_ref());
    }
}

/// The image, depth image and camera info of sensor `h`, rendered first when stale.
fn camera_messages(
    world: &gantry_sim_core::World,
    states: &mut gantry_sim_core::vision::VisionStates,
    h: Handle,
    frame: &str,
    stamp: Time,
) -> Result<[Vec<u8>; 3], gantry_sim_core::SimError> {
    let (model, _) = vision::sensor_model(world, h)?;
    let (near, far, fov, projection, ortho) = (model.near, model.far, model.fov, model.projection, model.ortho_size);
    let img = vision::read(world, states, h)?;
    let [w, hgt] = img.resolution();
    let image = msg::image(stamp, frame, w, hgt, img.rgb());
    // The sensor's depth buffer holds 0..1 between the near and far planes; ROS wants
    // metres, +inf where nothing is seen within the far plane (REP 118).
    let depth_m: Vec<f32> = img
        .depth()
        .iter()
        .map(|&v| {
            if v >= 1.0 {
                f32::INFINITY
            } else {
                (near + f64::from(v) * (far - near)) as f32
            }
        })
        .collect();
    let depth = msg::depth_image(stamp, frame, w, hgt, &depth_m);
    let info = camera_info(stamp, frame, w, hgt, projection, fov, ortho);
    Ok([image, depth, info])
}

/// `sensor_msgs/CameraInfo` of a pinhole camera whose view angle `fov` (rad) spans the
/// larger side of the image, as CoppeliaSim's perspective angle does. An orthographic
/// sensor has no pinhole model: its matrices are left at zero (ROS's "uncalibrated").
fn camera_info(stamp: Time, frame: &str, w: u32, h: u32, projection: Projection, fov: f64, _ortho: f64) -> Vec<u8> {
    let (fx, cx, cy) = match projection {
        Projection::Perspective => {
            let f = (f64::from(w.max(h)) / 2.0) / (fov / 2.0).tan();
            (f, (f64::from(w) - 1.0) / 2.0, (f64::from(h) - 1.0) / 2.0)
        }
        Projection::Orthographic => (0.0, 0.0, 0.0),
    };
    msg::camera_info(stamp, frame, w, h, fx, cx, cy)
}
