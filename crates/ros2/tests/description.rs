//! Issue 29, item 4: URDF robots on the ROS 2 graph as robot_state_publisher presents
//! them, so that rviz2's RobotModel display can place their links. The graph runs on an
//! in-memory network (Cyclone DDS receives the same in
//! tests/python/test_ros2_description.py):
//!
//! - `/robot_description` carries the URDF file's text unchanged, latched (reliable,
//!   transient local, depth 1); with two robots, each has `/<robot>/robot_description`;
//! - TF frames of URDF links are the link names (prefixed `<robot>/` with several
//!   robots), each link's parent is its parent link, every frame resolves to `world`, and
//!   the chain's poses compose to the link's world pose;
//! - `/joint_states` names URDF joints by their URDF names;
//! - a model loaded while running moves the descriptions to per-robot topics;
//! - a scene object that already holds a link's name keeps it, and the link its path.

use crate::util;

use std::collections::HashMap;
use std::sync::Arc;

use gantry_engine::{Engine, EngineConfig, Input, LoopControl};
use gantry_ros::Direction;
use gantry_ros2::{GraphOptions, RosGraph};
use gantry_sim_core::Value;
use gantry_sim_core::api::Target;
use gantry_sim_core::math::{Pose, quat_from_array};
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene};
use gantry_sim_core::sim::Control;
use gantry_test_support::{TempDir, repo};
use util::{Memory, decode, items, number, text};

const URDF: &str = "assets/robots/arm6/arm6.urdf";

/// arm6's links, root first.
const LINKS: [&str; 8] = ["base_link", "link1", "link2", "link3", "link4", "link5", "link6", "tip"];

/// A scene of `robots` (`(name, x)`: arm6 at `x` m) and `extra` TOML, in a folder of
/// its own, and its simulation, started.
fn scene(tag: &str, robots: &[(&str, f64)], extra: &str) -> (TempDir, Engine) {
    let urdf = repo(URDF);
    let mut toml = String::from("[simulation]\ndt = 0.05\n");
    for (name, x) in robots {
        toml.push_str(&format!(
            "[[robot]]\nname = \"{name}\"\nurdf = {urdf:?}\nposition = [{x}, 0, 0.1]\njoint_mode = \"kinematic\"\ninitial = {{ joint1 = 30, joint2 = -40, joint5 = -90 }}\n"
        ));
    }
    toml.push_str(extra);
    let dir = TempDir::new(tag);
    let path = dir.write("scene.toml", &toml);
    let model = load_scene(&DiskFiles, &path, &LoadOptions::default()).expect("the scene loads");
    let mut sim = Engine::new(model, EngineConfig::default(), None).expect("the simulation builds");
    sim.serve(Input::Control(LoopControl::Control(Control::Start)));
    (dir, sim)
}

/// Calls `name` as a remote client.
fn call(sim: &mut Engine, name: &str, args: &[Value]) -> Result<Vec<Value>, gantry_sim_core::api::CallError> {
    let target = Target::resolve_or_error(name)?;
    sim.serve(Input::Call { target: &target, args }).into_values()
}

/// Steps `sim` `n` times, the graph publishing after each step.
fn run(sim: &mut Engine, graph: &mut RosGraph, n: usize) {
    for _ in 0..n {
        sim.step();
        graph.after_step(&sim.sim());
    }
}

/// The graph on a fresh in-memory network.
fn graph() -> (Arc<Memory>, RosGraph) {
    let net = Arc::new(Memory::default());
    let graph = RosGraph::new(net.clone(), GraphOptions::default()).expect("the graph opens");
    (net, graph)
}

/// The transforms of every `/tf` and `/tf_static` message, by child frame: parent frame
/// and pose, the latest of each.
fn transforms(net: &Memory) -> HashMap<String, (String, Pose)> {
    let mut out = HashMap::new();
    for topic in ["rt/tf_static", "rt/tf"] {
        for body in net.written(topic) {
            let m = decode("tf2_msgs/msg/TFMessage", &body);
            for t in items(&m, "transforms") {
                let header = t.get("header").expect("a header");
                let tr = t.get("transform").expect("a transform");
                let (p, q) = (
                    tr.get("translation").expect("translation"),
                    tr.get("rotation").expect("rotation"),
                );
                let rotation = quat_from_array(["x", "y", "z", "w"].map(|k| number(q, k))).expect("a unit quaternion");
                let pose = Pose::from_parts([number(p, "x"), number(p, "y"), number(p, "z")].into(), rotation);
                out.insert(
                    text(t, "child_frame_id").to_owned(),
                    (text(header, "frame_id").to_owned(), pose),
                );
            }
        }
    }
    out
}

/// The pose of `frame` in `world`, following its TF parents; fails when the chain
/// does not reach `world`.
fn resolve(tf: &HashMap<String, (String, Pose)>, frame: &str) -> Pose {
    let mut pose = Pose::identity();
    let mut at = frame;
    for _ in 0..=tf.len() {
        if at == "world" {
            return pose;
        }
        let (parent, local) = tf
            .get(at)
            .unwrap_or_else(|| panic!("{frame}: frame {at:?} has no transform"));
        pose = local * pose;
        at = parent;
    }
    panic!("{frame}: the chain loops")
}

/// The URDF link `link`'s object's world pose in `sim`, of the `i`-th URDF robot.
fn link_pose(sim: &Engine, i: usize, link: &str) -> Pose {
    let world = sim.world();
    let r = &world.urdf_robots()[i];
    let h = r.links.iter().find(|(_, n)| n == link).expect("the link").0;
    world.object(h).expect("the object").world
}

/// The `/joint_states` names of the last message.
fn joint_names(net: &Memory) -> Vec<String> {
    let bodies = net.written("rt/joint_states");
    let m = decode("sensor_msgs/msg/JointState", bodies.last().expect("joint states"));
    items(&m, "name")
        .iter()
        .map(|v| v.as_str().expect("a name").to_owned())
        .collect()
}

#[test]
fn one_urdf_robot_is_described_and_framed_by_link() {
    let (_dir, mut sim) = scene(
        "one",
        &[("arm6", 0.5)],
        "[[object]]\nname = \"cam\"\nkind = \"dummy\"\nparent = \"arm6/link3\"\nposition = [0.1, 0, 0]\n",
    );
    let (net, mut graph) = graph();
    run(&mut sim, &mut graph, 3);
    // The joints move between steps: their links go on /tf, not /tf_static.
    let j1 = sim.world().urdf_robots()[0]
        .joints
        .iter()
        .find(|(_, n)| n == "joint1")
        .expect("joint1")
        .0;
    call(&mut sim, "sim.setJointPosition", &[Value::Int(j1), Value::Float(0.7)]).expect("the joint moves");
    run(&mut sim, &mut graph, 2);
    drop(graph);

    let file = std::fs::read_to_string(repo(URDF)).expect("the URDF is readable");
    let described = net.written("rt/robot_description");
    assert_eq!(described.len(), 1, "published once: the durability keeps it");
    assert_eq!(text(&decode("std_msgs/msg/String", &described[0]), "data"), file);
    let spec = net
        .opened()
        .into_iter()
        .find(|s| s.dds_topic == "rt/robot_description")
        .expect("the topic was opened");
    assert_eq!(spec.direction, Direction::Publish);
    assert_eq!(spec.dds_type, "std_msgs::msg::dds_::String_");
    assert!(
        spec.qos.transient_local && spec.qos.reliable && spec.qos.depth == 1,
        "{:?}",
        spec.qos
    );

    let tf = transforms(&net);
    assert_eq!(tf["base_link"].0, "arm6", "the root link hangs from the model base");
    for pair in LINKS.windows(2) {
        assert_eq!(tf[pair[1]].0, pair[0], "{}'s parent is its parent link", pair[1]);
    }
    assert_eq!(tf["arm6"].0, "world");
    for (frame, (parent, _)) in &tf {
        let last = frame.rsplit('/').next().unwrap_or(frame);
        assert!(
            !last.starts_with("joint") && last != "tool0",
            "URDF joints are not frames: {frame} (child of {parent})"
        );
    }
    // The dummy is no URDF link: it keeps its path, below the link's frame.
    let cam = tf.iter().find(|(f, _)| f.ends_with("/cam")).expect("the dummy's frame");
    assert!(cam.0.starts_with("arm6/base_link/joint1/link1"), "{}", cam.0);
    assert_eq!(cam.1.0, "link3");
    // Folding the joints into the links' transforms keeps every pose where it is.
    for (i, link) in LINKS.iter().enumerate() {
        let got = resolve(&tf, link);
        let want = link_pose(&sim, 0, link);
        let off = (got.translation.vector - want.translation.vector).norm() + got.rotation.angle_to(&want.rotation);
        assert!(off < 1e-9, "link {i} {link}: {got:?} != {want:?}");
    }
    assert_eq!(
        joint_names(&net),
        ["joint1", "joint2", "joint3", "joint4", "joint5", "joint6"],
        "URDF joint names; the fixed tool0 is a transform, not a joint state"
    );
}

#[test]
fn several_urdf_robots_get_a_topic_and_a_frame_prefix_each() {
    let (_dir, mut sim) = scene("two", &[("left", 0.5), ("right", -0.5)], "");
    let (net, mut graph) = graph();
    run(&mut sim, &mut graph, 2);
    let open = net.open_topics();
    drop(graph);

    let file = std::fs::read_to_string(repo(URDF)).expect("the URDF is readable");
    for robot in ["left", "right"] {
        let topic = format!("rt/{robot}/robot_description");
        assert!(open.contains(&topic), "{topic} in {open:?}");
        let bodies = net.written(&topic);
        assert_eq!(text(&decode("std_msgs/msg/String", &bodies[0]), "data"), file);
    }
    assert!(!open.contains(&"rt/robot_description".to_owned()), "{open:?}");

    let tf = transforms(&net);
    for (i, robot) in ["left", "right"].into_iter().enumerate() {
        assert_eq!(tf[&format!("{robot}/base_link")].0, robot);
        for pair in LINKS.windows(2) {
            assert_eq!(tf[&format!("{robot}/{}", pair[1])].0, format!("{robot}/{}", pair[0]));
        }
        let tip = resolve(&tf, &format!("{robot}/tip"));
        let want = link_pose(&sim, i, "tip");
        assert!((tip.translation.vector - want.translation.vector).norm() < 1e-9);
    }
    let names = joint_names(&net);
    assert_eq!(names.len(), 12);
    assert!(
        names.contains(&"left/joint1".to_owned()) && names.contains(&"right/joint6".to_owned()),
        "{names:?}"
    );
}

#[test]
fn a_model_loaded_while_running_moves_the_description_to_per_robot_topics() {
    let (_dir, mut sim) = scene("load", &[("arm6", 0.0)], "");
    let (net, mut graph) = graph();
    run(&mut sim, &mut graph, 2);
    assert!(net.open_topics().contains(&"rt/robot_description".to_owned()));
    let path = repo(URDF).display().to_string();
    call(&mut sim, "sim.loadModel", &[Value::Str(path)]).expect("the model loads");
    run(&mut sim, &mut graph, 2);
    let open = net.open_topics();
    let described: Vec<&String> = open.iter().filter(|t| t.ends_with("/robot_description")).collect();
    assert_eq!(described.len(), 2, "{open:?}");
    // Two siblings aliased arm6 are `arm6[0]` and `arm6[1]`: the tokens of their
    // command topics, which the descriptions share.
    for robot in ["arm6_0_", "arm6_1_"] {
        for topic in ["robot_description", "forward_position_controller/commands"] {
            let topic = format!("rt/{robot}/{topic}");
            assert!(open.contains(&topic), "{topic} in {open:?}");
        }
    }
    assert!(!open.contains(&"rt/robot_description".to_owned()), "{open:?}");
    drop(graph);
    assert!(
        !net.open_topics().iter().any(|t| t.ends_with("robot_description")),
        "closed with the graph"
    );
}

#[test]
fn a_link_name_another_object_holds_falls_back_to_the_path() {
    let (_dir, mut sim) = scene(
        "clash",
        &[("arm6", 0.0)],
        "[[object]]\nname = \"base_link\"\nkind = \"dummy\"\nposition = [2, 0, 0]\n",
    );
    let (net, mut graph) = graph();
    run(&mut sim, &mut graph, 2);
    drop(graph);
    let tf = transforms(&net);
    assert_eq!(tf["base_link"].0, "world", "the scene's own object keeps its name");
    assert_eq!(tf["arm6/base_link"].0, "arm6", "the link keeps its path");
    assert_eq!(tf["link1"].0, "arm6/base_link");
}
