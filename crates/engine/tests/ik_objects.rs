//! Lua scripts in the style of CoppeliaSim 4.2's kinematics tutorials, run end to end on
//! the paper's arm: an IK world built object by object from the scene's joints
//! (`simIK.createDummy`, `createJoint`, `setObjectParent`, `setLinkedDummy`, ...), then
//! solved every step with `handleIkGroup` (an undamped group that restores the joints when
//! it misses, falling back to a damped one) or searched with `getConfigForTipPose`, and
//! the IK joints copied onto the scene's. The scene's tip must follow the goal dummy.

use crate::util;
use util::Drive;

use gantry_lua::{ScriptLimits, ScriptState};
use gantry_sim_core::Handle;
use gantry_test_support::repo;
use util::{Scene, int32_signal, script_state, world_position};

/// The arm (kinematic joints, the paper's start pose), a tip dummy on its flange and a
/// free goal dummy; `robot.lua` is attached to the arm.
fn scene(tag: &str, script: &str) -> Scene {
    let urdf = repo("assets/robots/arm6/arm6.urdf");
    let toml = format!(
        r#"
[simulation]
dt = 0.05

[floor]
size = [4, 4]

[[robot]]
name = "arm6"
urdf = "{}"
joint_mode = "kinematic"
initial = {{ joint5 = -90 }}
script = "robot.lua"

[[object]]
name = "ikTip"
kind = "dummy"
parent = "arm6/tip"

[[object]]
name = "goal"
kind = "dummy"
"#,
        urdf.display()
    );
    Scene::new(tag, &toml, &[("robot.lua", script)], ScriptLimits::default())
}

/// Builds the IK world from the scene, the way the 4.2 tutorials do: a base dummy where
/// the robot is, one IK joint per scene joint (mode, interval, position and pose copied,
/// then parented keeping its pose), the tip on the last joint, and a target linked to it.
const BUILD: &str = r#"
function buildIkWorld()
    base = sim.getObjectHandle('arm6')
    tip = sim.getObjectHandle('ikTip')
    goal = sim.getObjectHandle('goal')
    joints = {}
    for i = 1, 6 do joints[i] = sim.getObjectHandle('joint' .. i) end

    env = simIK.createEnvironment()
    ikBase = simIK.createDummy(env)
    simIK.setObjectMatrix(env, ikBase, -1, sim.getObjectMatrix(base, -1))
    ikJoints = {}
    local parent = ikBase
    for i = 1, #joints do
        local j = simIK.createJoint(env, simIK.jointtype_revolute)
        simIK.setJointMode(env, j, simIK.jointmode_ik)
        local cyclic, interval = sim.getJointInterval(joints[i])
        simIK.setJointInterval(env, j, cyclic, interval)
        simIK.setJointPosition(env, j, sim.getJointPosition(joints[i]))
        simIK.setObjectMatrix(env, j, -1, sim.getObjectMatrix(joints[i], -1))
        simIK.setObjectParent(env, j, parent, true)
        ikJoints[i] = j
        parent = j
    end
    ikTip = simIK.createDummy(env)
    simIK.setObjectMatrix(env, ikTip, -1, sim.getObjectMatrix(tip, -1))
    simIK.setObjectParent(env, ikTip, parent, true)
    ikTarget = simIK.createDummy(env)
    simIK.setObjectMatrix(env, ikTarget, -1, sim.getObjectMatrix(goal, -1))
    simIK.setLinkedDummy(env, ikTip, ikTarget)
end

function newGroup(method, damping, iterations)
    local g = simIK.createIkGroup(env)
    simIK.setIkGroupCalculation(env, g, method, damping, iterations)
    local e = simIK.addIkElement(env, g, ikTip)
    simIK.setIkElementBase(env, g, e, ikBase)
    simIK.setIkElementConstraints(env, g, e, simIK.constraint_pose)
    return g, e
end

function copyToScene(values)
    for i = 1, #joints do sim.setJointPosition(joints[i], values[i]) end
end
"#;

/// The goal circles in front of the tool; each step the IK target follows it, the fast
/// group tries first and the damped one takes over when it fails, and the scene follows.
const FOLLOW: &str = r#"
function sysCall_init()
    sim.setObjectMatrix(sim.getObjectHandle('goal'), -1,
        sim.getObjectMatrix(sim.getObjectHandle('ikTip'), -1))
    buildIkWorld()
    home = sim.getObjectPosition(goal, -1)
    fast = newGroup(simIK.method_pseudo_inverse, 0, 20)
    simIK.setIkGroupFlags(env, fast, 1 + 2 + 4 + 8)
    damped = newGroup(simIK.method_damped_least_squares, 0.3, 100)
    fallbacks = 0
    sim.setInt32Signal('fallbacks', 0)
end

function sysCall_actuation()
    local t = sim.getSimulationTime() + 0.05
    sim.setObjectPosition(goal, -1, {home[1] + 0.08 * math.sin(t), home[2] + 0.08 * (1 - math.cos(t)),
        home[3] - 0.05 * math.sin(2 * t)})
    simIK.setObjectMatrix(env, ikTarget, -1, sim.getObjectMatrix(goal, -1))
    if simIK.handleIkGroup(env, fast) == simIK.result_fail then
        simIK.handleIkGroup(env, damped)
        fallbacks = fallbacks + 1
        sim.setInt32Signal('fallbacks', fallbacks)
    end
    local q = {}
    for i = 1, #ikJoints do q[i] = simIK.getJointPosition(env, ikJoints[i]) end
    copyToScene(q)
end

function sysCall_cleanup()
    simIK.eraseEnvironment(env)
end
"#;

fn handle(sc: &Scene, path: &str) -> Handle {
    sc.find(path)
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    a.iter().zip(&b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt()
}

#[test]
fn handle_ik_group_on_a_hand_built_ik_world_makes_the_arm_follow_the_goal() {
    let mut sc = scene("ik-follow", &format!("{BUILD}{FOLLOW}"));
    let (tip, goal) = (handle(&sc, "/arm6/tip/ikTip"), handle(&sc, "/goal"));
    let start = world_position(&sc.sim, tip);
    let mut travelled: f64 = 0.0;
    for step in 0..60 {
        sc.sim.step();
        assert_eq!(script_state(&sc.sim, "robot.lua"), ScriptState::Running);
        let (t, g) = (world_position(&sc.sim, tip), world_position(&sc.sim, goal));
        let d = distance(t, g);
        assert!(d < 1e-3, "step {step}: the tip is {d} m from the goal");
        travelled = travelled.max(distance(t, start));
    }
    assert!(travelled > 0.1, "the arm moved along the circle ({travelled} m)");
    assert_eq!(sc.sim.core().ik.len(), 1, "one IK environment while running");
    // The undamped group kept the joints when it missed; the damped one never had to
    // take over on such a slow, smooth path.
    assert_eq!(int32_signal(&mut sc.sim, "fallbacks"), Some(0));
    sc.sim.stop();
    assert_eq!(sc.sim.core().ik.len(), 0);
}

/// Four goals, each the tool pose of a configuration on another branch of the arm; each
/// step the script searches a configuration for the current goal with
/// `getConfigForTipPose` (a 3-iteration pseudo-inverse group, as the tutorial's) and
/// applies it to the scene.
const SEARCH: &str = r#"
function sysCall_init()
    buildIkWorld()
    local start = {}
    for i = 1, #joints do start[i] = sim.getJointPosition(joints[i]) end
    goals = {}
    for k, q in ipairs({{0.6, -0.4, 0.5, 0.3, -1.1, 0.2}, {-1.2, -0.2, 0.8, -0.5, -0.9, 1.0},
                        {2.5, 0.3, 0.4, 0.0, -1.4, -0.6}, {-2.6, -0.6, 1.2, 1.0, -0.5, 0.4}}) do
        copyToScene(q)
        goals[k] = sim.getObjectMatrix(tip, -1)
    end
    copyToScene(start)
    group, element = newGroup(simIK.method_pseudo_inverse, 0, 3)
    simIK.setIkElementPrecision(env, group, element, {0.00005, 0.1 * math.pi / 180})
    index = 0
    found = 0
end

function sysCall_actuation()
    index = index % #goals + 1
    sim.setObjectMatrix(goal, -1, goals[index])
    simIK.setObjectMatrix(env, ikTarget, -1, goals[index])
    local t0 = sim.getSystemTimeInMs(-1)
    while sim.getSystemTimeInMs(t0) < 100 do
        local q = simIK.getConfigForTipPose(env, group, ikJoints, 0.65, 10000, {1, 1, 1, 0.1}, '')
        if q then
            copyToScene(q)
            found = found + 1
            sim.setInt32Signal('found', found)
            break
        end
    end
end
"#;

#[test]
fn get_config_for_tip_pose_puts_the_tool_on_goals_across_the_workspace() {
    let mut sc = scene("ik-search", &format!("{BUILD}{SEARCH}"));
    let (tip, goal) = (handle(&sc, "/arm6/tip/ikTip"), handle(&sc, "/goal"));
    for step in 0..8 {
        sc.sim.step();
        assert_eq!(script_state(&sc.sim, "robot.lua"), ScriptState::Running);
        let d = distance(world_position(&sc.sim, tip), world_position(&sc.sim, goal));
        assert!(d < 1e-3, "step {step}: the tool is {d} m from the goal");
        let w = sc.sim.world();
        let (t, g) = (w.object(tip).expect("tip").world, w.object(goal).expect("goal").world);
        let angle = t.rotation.angle_to(&g.rotation);
        assert!(angle < 0.2f64.to_radians(), "step {step}: {angle} rad off");
    }
    assert_eq!(int32_signal(&mut sc.sim, "found"), Some(8));
}
