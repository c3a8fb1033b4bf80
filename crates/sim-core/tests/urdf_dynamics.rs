//! URDF robots as users bring them (issue 15): free joints under gravity against the
//! analytic pendulum, `<dynamics>` damping, `<mimic>`, `<limit velocity>`, self-collision
//! off by default, each unsupported element reported once, and links welded by fixed
//! joints fused into the link above (issue 33).
//!
//! The robots are written here as small URDF texts, so each test isolates one rule; the
//! public robots (pybullet_data, example-robot-data) are checked against Pinocchio in
//! tests/python/test_public_robots.py.

use crate::util;

use gantry_sim_core::{Sim, Value};
use gantry_test_support::{TempDir, load};
use util::{call, find, step};

/// A scratch folder with a scene and its URDF, removed on drop.
struct Scratch(TempDir);

impl Scratch {
    fn new(tag: &str) -> Self {
        Self(TempDir::new(&format!("urdf-{tag}")))
    }

    /// Writes `robot.urdf` and a scene that includes it with `robot_keys`, at `dt`
    /// seconds and one substep, and loads the scene.
    fn world(&self, urdf: &str, robot_keys: &str, dt: f64) -> Sim {
        self.0.write("robot.urdf", urdf);
        self.scene(&format!(
            "[simulation]\ndt = {dt}\nsubsteps = 1\n\n[[robot]]\nname = \"r\"\nurdf = \"robot.urdf\"\n{robot_keys}\n"
        ))
    }

    /// Writes `name` (a URDF, OBJ, ...) into the folder.
    fn file(&self, name: &str, text: &str) {
        self.0.write(name, text);
    }

    /// Loads a scene file with this text from the folder.
    fn scene(&self, text: &str) -> Sim {
        Sim::new(&load(&self.0.write("scene.toml", text)))
    }
}

/// The pendulum's numbers: a 1 kg bob whose centre of mass is `L` from a joint about +Y.
const M: f64 = 1.0;
const L: f64 = 0.5;
const I_COM: f64 = 0.01; // kg·m², about the bob's centre of mass
const G: f64 = 9.81;

/// A link `bob` hanging from `base` by `joint` about +Y, its centre of mass at +X
/// (horizontal at q = 0, so it starts falling at once). `world_root` adds what ROS
/// arm descriptions (UR, xArm, Kinova) start with: an empty `world` link welded to the
/// base by a fixed joint.
fn pendulum(world_root: bool, dynamics: &str) -> String {
    let root = if world_root {
        r#"<link name="world"/>
  <joint name="weld" type="fixed"><parent link="world"/><child link="base"/></joint>"#
    } else {
        ""
    };
    let bob = bob_link();
    format!(
        r#"<robot name="pendulum">
  {root}
  <link name="base">
    <inertial><mass value="2"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  {bob}
  <joint name="swing" type="continuous">
    <origin xyz="0 0 1"/><parent link="base"/><child link="bob"/><axis xyz="0 1 0"/>{dynamics}
  </joint>
</robot>"#
    )
}

/// The pendulum's bob: its centre of mass `L` along +X of its link frame.
fn bob_link() -> String {
    format!(
        r#"<link name="bob">
    <inertial><origin xyz="{L} 0 0"/><mass value="{M}"/>
      <inertia ixx="{I_COM}" iyy="{I_COM}" izz="{I_COM}" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>"#
    )
}

/// The pendulum's angle after `t` seconds from rest at q = 0, by RK4 at 0.1 ms:
/// `(I + m L²) q'' = m g L cos q - c q'`. A rotation by q about +Y takes +X to
/// (cos q, 0, -sin q), so positive q lowers the bob.
fn pendulum_angle(t: f64, damping: f64) -> f64 {
    let inertia = I_COM + M * L * L;
    let acc = |q: f64, v: f64| (M * G * L * q.cos() - damping * v) / inertia;
    let (mut q, mut v) = (0.0f64, 0.0f64);
    let h = 1e-4;
    for _ in 0..(t / h).round() as usize {
        let (k1q, k1v) = (v, acc(q, v));
        let (k2q, k2v) = (v + 0.5 * h * k1v, acc(q + 0.5 * h * k1q, v + 0.5 * h * k1v));
        let (k3q, k3v) = (v + 0.5 * h * k2v, acc(q + 0.5 * h * k2q, v + 0.5 * h * k2v));
        let (k4q, k4v) = (v + h * k3v, acc(q + h * k3q, v + h * k3v));
        q += h / 6.0 * (k1q + 2.0 * k2q + 2.0 * k3q + k4q);
        v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    }
    q
}

#[test]
fn free_pendulum_falls_as_the_equation_of_motion_says() {
    let dir = Scratch::new("pendulum");
    let dt = 1.0 / 1000.0;
    for world_root in [false, true] {
        for (damping, dynamics) in [(0.0, ""), (0.5, r#"<dynamics damping="0.5"/>"#)] {
            let mut w = dir.world(&pendulum(world_root, dynamics), "joint_mode = \"free\"", dt);
            let swing = find(&w, "/r/swing");
            step(&mut w, 500);
            let q = w.world.joint(swing).expect("joint").position;
            let want = pendulum_angle(0.5, damping);
            // Semi-implicit Euler at 1 ms against RK4: about 1e-3 rad apart after 0.5 s.
            assert!(
                (q - want).abs() < 5e-3,
                "world root {world_root}, damping {damping}: q(0.5 s) = {q:.5} rad, the equation says {want:.5}"
            );
        }
    }
    // Damping is felt: the damped pendulum is measurably behind.
    assert!(pendulum_angle(0.5, 0.0) - pendulum_angle(0.5, 0.5) > 0.02);
}

#[test]
fn free_pendulum_below_a_kinematic_joint_falls_at_the_right_speed() {
    // A mixed robot: a kinematic shoulder (held where the script puts it) carrying a free
    // pendulum. The pendulum's mechanism is rooted on the shoulder's kinematic body.
    let bob = bob_link();
    let urdf = format!(
        r#"<robot name="mixed">
  <link name="base"/>
  <link name="upper">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  {bob}
  <joint name="shoulder" type="continuous">
    <origin xyz="0 0 1"/><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>
  </joint>
  <joint name="swing" type="continuous">
    <origin xyz="0 0 0.2"/><parent link="upper"/><child link="bob"/><axis xyz="0 1 0"/>
  </joint>
</robot>"#
    );
    let dir = Scratch::new("mixed");
    let mut w = dir.world(
        &urdf,
        "joint_mode = \"free\"\njoint_modes = { shoulder = \"kinematic\" }",
        1.0 / 1000.0,
    );
    let swing = find(&w, "/r/swing");
    step(&mut w, 500);
    let q = w.world.joint(swing).expect("joint").position;
    let want = pendulum_angle(0.5, 0.0);
    assert!(
        (q - want).abs() < 5e-3,
        "q(0.5 s) = {q:.5} rad, the equation says {want:.5}"
    );
    // Turning the shoulder carries the mechanism: the swing axis (the bob's +Y, which the
    // swing leaves alone) turns from +Y to -X, in the tree and in rapier alike.
    let shoulder = find(&w, "/r/shoulder");
    let bob = find(&w, "/r/bob");
    w.world
        .set_joint_position(shoulder, std::f64::consts::FRAC_PI_2)
        .expect("joint");
    step(&mut w, 2);
    let axis = |p: &gantry_sim_core::math::Pose| p.rotation * nalgebra::Vector3::y();
    let tree = axis(&w.world.object(bob).expect("bob").world);
    let body = axis(&w.world.physics_pose(bob).expect("bob has a body"));
    for a in [tree, body] {
        assert!(
            (a - nalgebra::Vector3::new(-1.0, 0.0, 0.0)).norm() < 1e-3,
            "swing axis {a:?}"
        );
    }
}

/// An arm whose second link, a horizontal bar, swings down through the base box: the
/// base and the bar are not joined, so only self-collision can stop it.
const SWINGING_BAR: &str = r#"<robot name="bar">
  <link name="base">
    <inertial><mass value="5"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><box size="1.0 0.4 0.2"/></geometry></collision>
  </link>
  <link name="upper">
    <inertial><origin xyz="0 0 -0.3"/><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 -0.3"/><geometry><box size="0.1 0.1 0.5"/></geometry></collision>
  </link>
  <link name="bar">
    <inertial><origin xyz="0.3 0 0"/><mass value="1"/><inertia ixx="0.01" iyy="0.03" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0.3 0 0"/><geometry><box size="0.6 0.05 0.05"/></geometry></collision>
  </link>
  <joint name="shoulder" type="continuous">
    <origin xyz="0 0 1.0"/><parent link="base"/><child link="upper"/><axis xyz="0 1 0"/>
  </joint>
  <joint name="elbow" type="continuous">
    <origin xyz="0 0 -0.6"/><parent link="upper"/><child link="bar"/><axis xyz="0 1 0"/>
  </joint>
</robot>"#;

#[test]
fn links_of_one_robot_collide_only_with_self_collision_on() {
    let dir = Scratch::new("selfcol");
    let keys = "joint_mode = \"free\"\njoint_modes = { shoulder = \"position\" }";
    let elbow_after = |extra: &str| {
        let mut w = dir.world(SWINGING_BAR, &format!("{keys}\n{extra}"), 1.0 / 240.0);
        let elbow = find(&w, "/r/elbow");
        step(&mut w, 240);
        w.world.joint(elbow).expect("joint").position
    };
    // Off (the default): the bar swings through the base and hangs about straight down.
    let through = elbow_after("");
    assert!(
        through > 1.2,
        "without self-collision the bar should pass the base: q = {through:.3} rad"
    );
    // On: the bar comes to rest on the base's top face, 0.2 m below the elbow
    // (asin(0.2 / 0.6) = 0.34 rad, a little less with the bar's thickness).
    let stopped = elbow_after("self_collision = true");
    assert!(
        (0.2..0.5).contains(&stopped),
        "with self-collision the base should stop the bar near 0.34 rad: q = {stopped:.3} rad"
    );
}

#[test]
fn mimic_followers_move_with_their_leader_in_every_mode() {
    let gripper = r#"<robot name="gripper">
  <link name="palm">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="left">
    <inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="right">
    <inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="left_slide" type="prismatic">
    <parent link="palm"/><child link="left"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" effort="20" velocity="1"/>
  </joint>
  <joint name="right_slide" type="prismatic">
    <parent link="palm"/><child link="right"/><axis xyz="0 1 0"/>
    <limit lower="-0.04" upper="0" effort="20" velocity="1"/>
    <mimic joint="left_slide" multiplier="-1" offset="0"/>
  </joint>
</robot>"#;
    let dir = Scratch::new("mimic");
    // Kinematic: setting the leader places the follower at once.
    let mut w = dir.world(gripper, "", 0.01);
    let (left, right) = (find(&w, "/r/left_slide"), find(&w, "/r/right_slide"));
    w.world.set_joint_position(left, 0.03).expect("joint");
    assert!((w.world.joint(right).expect("joint").position + 0.03).abs() < 1e-12);
    // Simulated: the follower is coupled inside the mechanism and tracks the leader's
    // motor on its own (its own target is never set).
    let mut w = dir.world(gripper, "joint_mode = \"position\"", 0.01);
    w.world.set_joint_target_position(left, 0.03).expect("joint");
    step(&mut w, 200);
    let (l, r) = (
        w.world.joint(left).expect("joint").position,
        w.world.joint(right).expect("joint").position,
    );
    assert!((l - 0.03).abs() < 2e-3, "leader at {l}");
    assert!((r + l).abs() < 1e-3, "follower at {r} for leader at {l}");
}

/// One link on a vertical axis (no gravity torque) whose `<limit velocity>` is 0.5 rad/s.
const SLOW_JOINT: &str = r#"<robot name="slow">
  <link name="base"/>
  <link name="arm">
    <inertial><origin xyz="0.2 0 0"/><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="turn" type="revolute">
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="50" velocity="0.5"/>
  </joint>
</robot>"#;

#[test]
fn limit_velocity_bounds_position_and_velocity_control() {
    let dir = Scratch::new("vlimit");
    let mut w = dir.world(SLOW_JOINT, "joint_mode = \"position\"", 0.01);
    let turn = find(&w, "/r/turn");
    w.world.set_joint_target_position(turn, 1.0).expect("joint");
    step(&mut w, 100);
    let q = w.world.joint(turn).expect("joint").position;
    assert!(
        (q - 0.5).abs() < 0.05,
        "after 1 s at 0.5 rad/s the joint should be near 0.5 rad: {q:.3}"
    );
    step(&mut w, 200);
    let q = w.world.joint(turn).expect("joint").position;
    assert!(
        (q - 1.0).abs() < 0.01,
        "the joint should then settle on its target: {q:.3}"
    );

    let mut w = dir.world(SLOW_JOINT, "joint_mode = \"velocity\"", 0.01);
    w.world.set_joint_target_velocity(turn, 2.0).expect("joint");
    step(&mut w, 100);
    let v = w.world.joint(turn).expect("joint").velocity;
    assert!(
        (v - 0.5).abs() < 0.02,
        "a 2 rad/s command is capped at 0.5 rad/s: {v:.3}"
    );
}

#[test]
fn unsupported_elements_are_reported_once_per_file_even_when_loaded_twice() {
    let dir = Scratch::new("warn");
    dir.file(
        "robot.urdf",
        r#"<robot name="w">
  <link name="a"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="c"><inertial><mass value="0"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="float" type="floating"><parent link="a"/><child link="b"/></joint>
  <joint name="weld" type="fixed"><parent link="b"/><child link="c"/><mimic joint="float"/></joint>
  <transmission name="t1"><type>SimpleTransmission</type></transmission>
  <transmission name="t2"><type>SimpleTransmission</type></transmission>
  <gazebo reference="a"><material>Gazebo/Grey</material></gazebo>
</robot>"#,
    );
    let robot =
        |name: &str, x: f64| format!("[[robot]]\nname = \"{name}\"\nurdf = \"robot.urdf\"\nposition = [{x}, 0, 0]\n");
    let w = dir.scene(&(robot("one", 0.0) + &robot("two", 1.0)));
    let warnings = w.world.warnings();
    for needle in [
        "2 <transmission>",
        "1 <gazebo>",
        "floating joints (float)",
        "<mimic> on joints that cannot move",
    ] {
        let n = warnings.iter().filter(|m| m.contains(needle)).count();
        assert_eq!(n, 1, "'{needle}' should be said exactly once: {warnings:#?}");
    }
    // A massless link with an inertia keeps it (Franka's flange in pybullet_data): no
    // "has no <inertial>" fallback to a density.
    assert!(
        !warnings.iter().any(|m| m.contains("has no <inertial>")),
        "{warnings:#?}"
    );
}

#[test]
fn concave_meshes_are_hulled_on_dynamic_links_and_warned_about_once() {
    let dir = Scratch::new("hull");
    // A unit cube whose top face is dented down to its centre: concave.
    dir.file(
        "dent.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nv 0.5 0.5 0.5\n\
         f 1 3 2\nf 1 4 3\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n\
         f 5 6 9\nf 6 7 9\nf 7 8 9\nf 8 5 9\n",
    );
    // The same volume as two convex sections: a convex decomposition, no warning.
    dir.file(
        "parts.obj",
        "o low\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 0.5\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n\
         o high\nv 0 0 0.5\nv 1 0 0.5\nv 0 1 0.5\nv 0 0 1\nf 5 7 6\nf 5 6 8\nf 6 7 8\nf 7 5 8\n",
    );
    let link = |name: &str, mesh: &str| {
        format!(
            r#"<link name="{name}"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><mesh filename="{mesh}"/></geometry></collision></link>"#
        )
    };
    let urdf = format!(
        r#"<robot name="m">
  <link name="base"/>
  {}
  {}
  {}
  <joint name="j1" type="continuous"><parent link="base"/><child link="d1"/><axis xyz="0 0 1"/></joint>
  <joint name="j2" type="continuous"><origin xyz="2 0 0"/><parent link="base"/><child link="d2"/><axis xyz="0 0 1"/></joint>
  <joint name="j3" type="continuous"><origin xyz="4 0 0"/><parent link="base"/><child link="p"/><axis xyz="0 0 1"/></joint>
</robot>"#,
        link("d1", "dent.obj"),
        link("d2", "dent.obj"),
        link("p", "parts.obj")
    );
    let w = dir.world(&urdf, "joint_mode = \"free\"", 0.01);
    let concave: Vec<_> = w.world.warnings().iter().filter(|m| m.contains("not convex")).collect();
    assert_eq!(concave.len(), 1, "{:#?}", w.world.warnings());
    assert!(concave[0].contains("dent.obj"), "{concave:?}");
    // Kinematic links keep the triangle mesh, concavity and all: nothing to warn about.
    let w = dir.world(&urdf, "", 0.01);
    assert!(
        !w.world.warnings().iter().any(|m| m.contains("not convex")),
        "{:#?}",
        w.world.warnings()
    );
}

/// The pendulum's angle after `t` seconds from rest at q = 0 for any rigid bob: moment
/// of inertia `inertia` about the axis (kg·m²) and `mgl` = m g times the distance of its
/// centre of mass from the axis (N·m), by RK4 at 0.1 ms, no damping.
fn rigid_pendulum_angle(t: f64, inertia: f64, mgl: f64) -> f64 {
    let acc = |q: f64| mgl * q.cos() / inertia;
    let (mut q, mut v) = (0.0f64, 0.0f64);
    let h = 1e-4;
    for _ in 0..(t / h).round() as usize {
        let (k1q, k1v) = (v, acc(q));
        let (k2q, k2v) = (v + 0.5 * h * k1v, acc(q + 0.5 * h * k1q));
        let (k3q, k3v) = (v + 0.5 * h * k2v, acc(q + 0.5 * h * k2q));
        let (k4q, k4v) = (v + h * k3v, acc(q + h * k3q));
        q += h / 6.0 * (k1q + 2.0 * k2q + 2.0 * k3q + k4q);
        v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    }
    q
}

/// The pendulum with a `tip` link welded to the bob 0.6 m out by a fixed joint (a
/// tool, a flange, a hand on a wrist): 0.5 kg whose centre of mass is 0.05 m further
/// out, and `tip_collision` inside its link element.
fn welded_pendulum(tip_collision: &str) -> String {
    let tip = format!(
        r#"<link name="tip">
    <inertial><origin xyz="0.05 0 0"/><mass value="0.5"/>
      <inertia ixx="0.002" iyy="0.002" izz="0.002" ixy="0" ixz="0" iyz="0"/></inertial>
    {tip_collision}
  </link>
  <joint name="weld" type="fixed">
    <origin xyz="0.6 0 0"/><parent link="bob"/><child link="tip"/>
  </joint>
</robot>"#
    );
    pendulum(false, "").replace("</robot>", &tip)
}

/// The same pendulum with bob and tip as one link: the inertial that fusing must give.
/// Mass 1.5 kg; centre of mass (1 x 0.5 + 0.5 x 0.65) / 1.5 = 0.55 m out; about it, Iyy =
/// Izz = 0.01 + 1 x 0.05² + 0.002 + 0.5 x 0.1² = 0.0195 and Ixx = 0.012 kg·m².
const ONE_PIECE_PENDULUM: &str = r#"<robot name="one_piece">
  <link name="base">
    <inertial><mass value="2"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="bob">
    <inertial><origin xyz="0.55 0 0"/><mass value="1.5"/>
      <inertia ixx="0.012" iyy="0.0195" izz="0.0195" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="swing" type="continuous">
    <origin xyz="0 0 1"/><parent link="base"/><child link="bob"/><axis xyz="0 1 0"/>
  </joint>
</robot>"#;

/// The pendulum's angle (rad) after `steps` more steps.
fn swing_after(w: &mut Sim, steps: usize) -> f64 {
    let swing = find(w, "/r/swing");
    step(w, steps);
    w.world.joint(swing).expect("joint").position
}

/// Links of all rapier multibodies of a simulation.
fn multibody_links(w: Sim) -> usize {
    let (physics, _) = w.world.into_rapier();
    physics.multibody_joints.multibodies().map(|mb| mb.num_links()).sum()
}

#[test]
fn a_welded_link_is_fused_into_its_parent_and_swings_as_one_body() {
    let dir = Scratch::new("welded");
    let dt = 1.0 / 1000.0;
    let mut fused = dir.world(&welded_pendulum(""), "joint_mode = \"free\"", dt);
    let mut whole = dir.world(ONE_PIECE_PENDULUM, "joint_mode = \"free\"", dt);
    let (q, want) = (swing_after(&mut fused, 500), swing_after(&mut whole, 500));
    assert!((q - want).abs() < 1e-4, "welded {q:.6} rad, one piece {want:.6} rad");
    let analytic = rigid_pendulum_angle(0.5, 0.0195 + 1.5 * 0.55 * 0.55, 1.5 * G * 0.55);
    assert!(
        (q - analytic).abs() < 5e-3,
        "q(0.5 s) = {q:.5} rad, the equation says {analytic:.5}"
    );
    // The tip rides on the bob's body, where the tree has it.
    let tip = find(&fused, "/r/tip");
    let (tree, body) = (
        fused.world.object(tip).expect("tip").world,
        fused.world.physics_pose(tip).expect("the tip rides on a body"),
    );
    assert!((tree.translation.vector - body.translation.vector).norm() < 1e-5);
    // Fused: the multibody has the base and the bob, no link for the weld.
    assert_eq!(multibody_links(fused), 2);
    assert_eq!(multibody_links(whole), 2);
}

#[test]
fn a_fused_link_keeps_its_own_forces_mass_and_removal() {
    let dir = Scratch::new("welded-edits");
    let dt = 1.0 / 1000.0;
    let run = |urdf: &str, edit: &dyn Fn(&mut Sim)| {
        let mut w = dir.world(urdf, "joint_mode = \"free\"", dt);
        edit(&mut w);
        let swing = find(&w, "/r/swing");
        for _ in 0..300 {
            // A push on the tip's centre of mass, along -Z (down), at every step: on the
            // tip (at its centre of mass), or at that point of the one-piece bob.
            let push = Value::floats(&[0.0, 0.0, -3.0]);
            match w.world.find("/r/tip", None, 0) {
                Ok(tip) => call(&mut w, "sim.addForceAndTorque", &[Value::Int(tip), push]),
                Err(_) => {
                    let bob = find(&w, "/r/bob");
                    let at = Value::floats(&tip_centre(&w, bob));
                    call(&mut w, "sim.addForce", &[Value::Int(bob), at, push])
                }
            }
            .expect("a force");
            w.step();
        }
        w.world.joint(swing).expect("joint").position
    };
    // A force on the fused tip acts at the tip's own centre of mass, not the body's:
    // the same as that force applied at that point of the one-piece bob.
    let fused = run(&welded_pendulum(""), &|_| {});
    let whole = run(ONE_PIECE_PENDULUM, &|_| {});
    assert!(
        (fused - whole).abs() < 1e-4,
        "pushed tip: welded {fused:.6}, one piece {whole:.6}"
    );
    // The tip's mass, changed, changes the body it is fused into.
    let heavier = run(&welded_pendulum(""), &|w| {
        let tip = find(w, "/r/tip");
        call(w, "sim.setShapeMass", &[Value::Int(tip), Value::Float(2.0)]).expect("setShapeMass");
    });
    assert!(
        (heavier - fused).abs() > 1e-3,
        "a 2 kg tip swings like a 0.5 kg one: {heavier:.5}"
    );
    // Removed, it takes its mass along: the plain pendulum again.
    let mut w = dir.world(&welded_pendulum(""), "joint_mode = \"free\"", dt);
    let tip = find(&w, "/r/tip");
    call(&mut w, "sim.removeObjects", &[Value::Array(vec![Value::Int(tip)])]).expect("remove");
    let q = swing_after(&mut w, 500);
    let plain = pendulum_angle(0.5, 0.0);
    assert!(
        (q - plain).abs() < 5e-3,
        "without its tip: {q:.5} rad, the plain pendulum {plain:.5}"
    );
}

/// Where the welded tip's centre of mass is, world frame, on the one-piece bob: 0.65 m
/// along the bob's +X from the swing axis.
fn tip_centre(w: &Sim, bob: gantry_sim_core::Handle) -> [f64; 3] {
    let pose = w.world.object(bob).expect("bob").world;
    let p = pose.transform_point(&nalgebra::Point3::new(0.65, 0.0, 0.0));
    [p.x, p.y, p.z]
}

#[test]
fn a_welded_link_thinner_than_its_parent_stays_a_link_of_its_own() {
    // A 1 cm box on the bob's 10 cm one: fused, it would make rapier's automatic CCD
    // judge the whole bob by the box's thickness.
    let dir = Scratch::new("welded-thin");
    let bob_box = r#"<collision><origin xyz="0.5 0 0"/><geometry><box size="0.1 0.1 0.1"/></geometry></collision>"#;
    let urdf = welded_pendulum(r#"<collision><geometry><box size="0.01 0.01 0.01"/></geometry></collision>"#).replace(
        "</inertial>\n  </link>\n  <joint name=\"swing\"",
        &format!("</inertial>\n    {bob_box}\n  </link>\n  <joint name=\"swing\""),
    );
    assert!(urdf.contains(bob_box), "the bob got its box");
    let thin = dir.world(&urdf, "joint_mode = \"free\"", 1.0 / 1000.0);
    assert_eq!(multibody_links(thin), 3);
    let thick = welded_pendulum(r#"<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>"#).replace(
        "</inertial>\n  </link>\n  <joint name=\"swing\"",
        &format!("</inertial>\n    {bob_box}\n  </link>\n  <joint name=\"swing\""),
    );
    assert_eq!(
        multibody_links(dir.world(&thick, "joint_mode = \"free\"", 1.0 / 1000.0)),
        2
    );
}
