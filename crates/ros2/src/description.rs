//! URDF robots on the ROS 2 graph as `robot_state_publisher` presents them, so that
//! rviz2's RobotModel display (and MoveIt, and anything else that reads the description)
//! can place their links:
//!
//! - `/robot_description` (`std_msgs/String`, reliable, transient local, depth 1): the
//!   URDF file's text as read, when the scene holds one URDF robot; with several, each
//!   robot's on `/<robot>/robot_description`, where `<robot>` is the token of its
//!   `/<robot>/forward_position_controller/commands` topics. Published once per tree
//!   (the durability hands it to late subscribers), and again when a load or removal
//!   changes which robots there are.
//! - TF frames: an object made from a URDF link is named by the link (`link1`, or
//!   `<robot>/link1` with several robots: robot_state_publisher's `frame_prefix`), and
//!   the objects made from URDF joints are left out of `/tf`: what hangs from a joint
//!   object hangs, in TF, from the joint's parent (the parent link), with the joint's
//!   transform folded into its pose. So each link's TF parent is its parent link, the
//!   root link's is the robot's model base, and every frame still resolves to `world`.
//!   Other objects keep their path names (`arm6`, `arm6/link1/camera`).
//! - `/joint_states` names a URDF joint by its URDF name (prefixed as the frames are).
//!
//! A URDF name that would clash with another frame (a scene object aliased `base_link`
//! beside one robot) falls back to the object's path, so every frame id stays unique.
//! Only the ROS graph names frames this way: recordings keep object paths.

use std::collections::HashMap;
use std::sync::Arc;

use gantry_ros::msg;
use gantry_ros::{Direction, EndpointId, FrameNames, NetworkError, RosNetwork, RosQos, Snapshot};
use gantry_sim_core::Handle;
use gantry_sim_core::World;
use gantry_sim_core::world::ObjectKind;

use crate::topics::{open, send, topic_token};

/// The QoS of a description: reliable, transient local, depth 1 (a latched topic).
pub const DESCRIPTION_QOS: RosQos = RosQos {
    depth: 1,
    transient_local: true,
    reliable: true,
};

/// How the ROS graph names the objects of one tree (see the module docs).
#[derive(Debug, Clone, Default)]
pub struct RosNames {
    /// Frame id of each handle on `/tf`; for an object made from a URDF joint, the name
    /// `/joint_states` gives it. Empty for gaps.
    frames: FrameNames,
    /// Whether each handle is a URDF joint's object, left out of `/tf`.
    hidden: Vec<bool>,
}

/// One URDF robot as the graph publishes it.
struct LiveRobot<'a> {
    /// The robot's topic token (`arm6`).
    token: String,
    robot: &'a gantry_sim_core::world::UrdfRobot,
}

/// The URDF robots whose model base is still in `world`, with their topic tokens (from
/// `paths`, the object paths of the tree).
fn live_robots<'a>(world: &'a World, paths: &[String]) -> Vec<LiveRobot<'a>> {
    world
        .urdf_robots()
        .iter()
        .filter(|r| world.object(r.base).is_ok())
        .map(|robot| LiveRobot {
            token: topic_token(name_of(paths, robot.base)),
            robot,
        })
        .collect()
}

/// The entry of `names` for `h` (empty when out of range).
fn name_of(names: &[String], h: Handle) -> &str {
    usize::try_from(h)
        .ok()
        .and_then(|i| names.get(i))
        .map_or("", String::as_str)
}

impl RosNames {
    /// The names of `world`'s tree, whose object paths are `paths`.
    pub fn new(world: &World, paths: &FrameNames) -> Self {
        let robots = live_robots(world, paths);
        if robots.is_empty() {
            return Self {
                frames: paths.clone(),
                hidden: Vec::new(),
            };
        }
        let prefix = |r: &LiveRobot<'_>| {
            if robots.len() > 1 {
                format!("{}/", r.token)
            } else {
                String::new()
            }
        };
        let slot = |h: Handle| usize::try_from(h).ok().filter(|&i| i < paths.len());
        let mut names: Vec<String> = paths.to_vec();
        let mut hidden = vec![false; paths.len()];
        // Handles whose name comes from the URDF, links and joints apart: the two
        // namespaces are separate in a URDF, and only links are frames.
        let mut links: Vec<usize> = Vec::new();
        let mut joints: Vec<usize> = Vec::new();
        for r in &robots {
            let prefix = prefix(r);
            for (h, link) in &r.robot.links {
                if let Some(i) = slot(*h).filter(|_| world.object(*h).is_ok()) {
                    names[i] = format!("{prefix}{link}");
                    links.push(i);
                }
            }
            for (h, joint) in &r.robot.joints {
                let is_joint = matches!(world.object(*h).map(|o| &o.kind), Ok(ObjectKind::Joint(_)));
                if let Some(i) = slot(*h).filter(|_| is_joint) {
                    names[i] = format!("{prefix}{joint}");
                    hidden[i] = true;
                    joints.push(i);
                }
            }
        }
        // A URDF name that clashes goes back to the object's path (paths are unique);
        // that can make a new clash only with another URDF name, hence the loop.
        let tf: Vec<usize> = (0..names.len())
            .filter(|&i| !hidden[i] && !names[i].is_empty())
            .collect();
        unclash(&mut names, &tf, &mut links, paths);
        unclash(&mut names, &joints.clone(), &mut joints, paths);
        Self {
            frames: Arc::new(names),
            hidden,
        }
    }

    /// Renames `s`'s frames and takes the URDF joints' objects out of its poses, each
    /// of their children then hanging from the joint's parent, its pose composed with
    /// the joint's (so every frame still resolves to `world`).
    pub fn apply(&self, s: &mut Snapshot) {
        s.frames = self.frames.clone();
        if !self.hidden.contains(&true) {
            return;
        }
        let hidden = |h: Handle| usize::try_from(h).ok().and_then(|i| self.hidden.get(i)) == Some(&true);
        // Each hidden object's parent and pose relative to it, after the hidden objects
        // above it were folded in. Poses come parents first, so a parent is always here
        // before its children look it up.
        let mut folded: HashMap<Handle, (Option<Handle>, [f64; 7])> = HashMap::new();
        s.poses.retain_mut(|p| {
            if let Some((parent, pose)) = p.parent.and_then(|q| folded.get(&q)) {
                p.parent = *parent;
                p.pose = compose(pose, &p.pose);
            }
            if hidden(p.handle) {
                folded.insert(p.handle, (p.parent, p.pose));
                false
            } else {
                true
            }
        });
    }
}

/// Puts the path back for each of `candidates` (indices into `names`, a subset of
/// `within`) whose name another entry of `within` also has, until no clash is left.
fn unclash(names: &mut [String], within: &[usize], candidates: &mut Vec<usize>, paths: &[String]) {
    loop {
        let mut count: HashMap<&str, usize> = HashMap::new();
        for &i in within {
            *count.entry(names[i].as_str()).or_default() += 1;
        }
        let clashing: Vec<usize> = candidates
            .iter()
            .copied()
            .filter(|&i| count.get(names[i].as_str()).is_some_and(|&c| c > 1))
            .collect();
        if clashing.is_empty() {
            return;
        }
        for &i in &clashing {
            tracing::warn!(
                "ROS 2 graph: frame {:?} is taken, so the object {:?} keeps its path as its frame id",
                names[i],
                paths[i]
            );
            names[i].clone_from(&paths[i]);
        }
        candidates.retain(|i| !clashing.contains(i));
    }
}

/// Pose `b` (in `a`'s frame) in the frame `a` is given in: `a * b`, each as translation
/// (m) then quaternion `x, y, z, w`.
fn compose(a: &[f64; 7], b: &[f64; 7]) -> [f64; 7] {
    let [ax, ay, az, qx, qy, qz, qw] = *a;
    let [bx, by, bz, rx, ry, rz, rw] = *b;
    // v' = v + 2w (u x v) + 2 u x (u x v), with u the vector part of a's rotation.
    let cross =
        |[ux, uy, uz]: [f64; 3], [vx, vy, vz]: [f64; 3]| [uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx];
    let u = [qx, qy, qz];
    let t = cross(u, [bx, by, bz]).map(|c| 2.0 * c);
    let ut = cross(u, t);
    let moved = [bx + qw * t[0] + ut[0], by + qw * t[1] + ut[1], bz + qw * t[2] + ut[2]];
    [
        ax + moved[0],
        ay + moved[1],
        az + moved[2],
        qw * rx + qx * rw + qy * rz - qz * ry,
        qw * ry - qx * rz + qy * rw + qz * rx,
        qw * rz + qx * ry - qy * rx + qz * rw,
        qw * rw - qx * rx - qy * ry - qz * rz,
    ]
}

/// The open description topics, by topic name: the publisher and the text it published.
#[derive(Default)]
pub struct Descriptions {
    open: HashMap<String, (EndpointId, Arc<str>)>,
}

impl Descriptions {
    /// Opens and publishes the descriptions of `world`'s URDF robots (see the module
    /// docs), leaving alone the topics whose text has not changed and closing those no
    /// longer wanted.
    pub fn refresh(&mut self, net: &dyn RosNetwork, world: &World, paths: &[String]) {
        let robots = live_robots(world, paths);
        let mut wanted: HashMap<String, Arc<str>> = HashMap::new();
        for r in &robots {
            let topic = if robots.len() > 1 {
                format!("/{}/robot_description", r.token)
            } else {
                "/robot_description".to_owned()
            };
            match &r.robot.text {
                Some(text) => {
                    wanted.insert(topic, text.clone());
                }
                None => tracing::warn!(
                    "ROS 2 graph: no {topic}: {} was too large to keep",
                    r.robot.path.display()
                ),
            }
        }
        self.open.retain(|topic, (id, text)| {
            let keep = wanted.get(topic).is_some_and(|t| Arc::ptr_eq(t, text));
            if !keep {
                net.close(*id);
            }
            keep
        });
        for (topic, text) in wanted {
            if self.open.contains_key(&topic) {
                continue;
            }
            match publish(net, &topic, &text) {
                Ok(id) => {
                    self.open.insert(topic, (id, text));
                }
                Err(e) => tracing::warn!("ROS 2 graph: no {topic}: {e}"),
            }
        }
    }

    /// Closes every description topic.
    pub fn close(&mut self, net: &dyn RosNetwork) {
        for (id, _) in std::mem::take(&mut self.open).into_values() {
            net.close(id);
        }
    }
}

/// Opens `topic` as a latched `std_msgs/String` and publishes `text` on it once.
fn publish(net: &dyn RosNetwork, topic: &str, text: &str) -> Result<EndpointId, NetworkError> {
    let id = open(net, Direction::Publish, topic, "std_msgs/msg/String", DESCRIPTION_QOS)?;
    send(net, id, &msg::string(text));
    Ok(id)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn composing_poses_matches_rotating_then_translating() {
        // a: 1 m along x, turned 90° about z; b: 1 m along its x, turned 90° about z.
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let a = [1.0, 0.0, 0.0, 0.0, 0.0, s, s];
        let c = compose(&a, &a);
        let want = [1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        for (got, want) in c.iter().zip(want) {
            assert!((got - want).abs() < 1e-12, "{c:?}");
        }
        let identity = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
        assert_eq!(compose(&identity, &a), a);
    }

    #[test]
    fn a_clashing_urdf_name_falls_back_to_the_path() {
        let paths = ["base_link", "arm/base_link", "arm/base_link/j/link1"].map(String::from);
        let mut names = ["base_link", "base_link", "link1"].map(String::from).to_vec();
        let mut links = vec![1, 2];
        unclash(&mut names, &[0, 1, 2], &mut links, &paths);
        assert_eq!(names, ["base_link", "arm/base_link", "link1"]);
        assert_eq!(links, [2]);
    }
}
