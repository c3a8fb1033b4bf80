//! `simOMPL` as CoppeliaSim's public planning scripts use it: state spaces over the
//! bundled six-axis arm's joints, collision pairs with an obstacle, RRT-Connect, and a
//! path that stays collision-free when replayed state by state.

use crate::util;
use util::Drive;

use gantry_sim_core::Value;
use gantry_test_support::{assert_close, assert_contains, floats, text};
use util::Scene;

/// The paper's arm, kinematic, with two boxes at the tool's height on either side, so
/// that turning the base half a turn with the arm stretched out hits one of them.
fn arm_scene() -> String {
    util::arm6_scene_head(Some("planner.lua"))
        + r#"
[[object]]
name = "left"
kind = "shape"
shape = "box"
size = [0.2, 0.2, 0.2]
position = [0, 0.45, 0.65]

[[object]]
name = "right"
kind = "shape"
shape = "box"
size = [0.2, 0.2, 0.2]
position = [0, -0.45, 0.65]
"#
}

/// The planning script, in the form of the public ones: spaces, task, algorithm,
/// collision pairs, start and goal, `compute`; then the path is replayed with
/// `simOMPL.writeState` and checked with `sim.checkCollision` at each state.
const PLANNER: &str = r#"
function sysCall_init()
    local joints = {}
    for i = 1, 6 do joints[i] = sim.getObject('./joint' .. i) end
    local arm = sim.createCollection(0)
    sim.addItemToCollection(arm, sim.handle_tree, sim.getObject('.'), 0)
    local obstacles = sim.createCollection(0)
    sim.addItemToCollection(obstacles, sim.handle_single, sim.getObject('/left'), 0)
    sim.addItemToCollection(obstacles, sim.handle_single, sim.getObject('/right'), 0)

    local ss = {
        simOMPL.createStateSpace('j1', simOMPL.StateSpaceType.cyclic_joint_position, joints[1], {}, {}, 1),
        simOMPL.createStateSpace('j2', simOMPL.StateSpaceType.joint_position, joints[2], {-1.9}, {1.5}, 1),
        simOMPL.createStateSpace('j3', simOMPL.StateSpaceType.joint_position, joints[3], {-0.8}, {3.1}, 1),
    }
    task = simOMPL.createTask('arm')
    simOMPL.setStateSpace(task, ss)
    simOMPL.setAlgorithm(task, simOMPL.Algorithm.RRTConnect)
    simOMPL.setCollisionPairs(task, {arm, obstacles})
    start = simOMPL.readState(task)
    goal = {3.0, start[2], start[3]}
    simOMPL.setStartState(task, start)
    simOMPL.setGoalState(task, goal)
    -- Turning the base alone, the arm stretched out, runs into a box half way.
    halfway = simOMPL.isStateValid(task, {1.5, start[2], start[3]})
    startValid = simOMPL.isStateValid(task, start)
    solved, path = simOMPL.compute(task, 10, -1, 50)

    -- Replay: every state of the path is put in the scene and checked.
    collisions = 0
    for k = 0, #path / 3 - 1 do
        simOMPL.writeState(task, {path[3 * k + 1], path[3 * k + 2], path[3 * k + 3]})
        if sim.checkCollision(arm, obstacles) ~= 0 then collisions = collisions + 1 end
    end
    states = math.tointeger(#path / 3)
    afterReplay = {sim.getJointPosition(joints[1]), sim.getJointPosition(joints[2])}
    ok1, badSpace = pcall(simOMPL.createStateSpace, 'd', simOMPL.StateSpaceType.dubins, joints[1], {0, 0}, {1, 1}, 1)
    ok2, badState = pcall(simOMPL.setStartState, task, {1, 2})
    ok3, badPairs = pcall(simOMPL.setCollisionPairs, task, {arm})
    ok4, badTask = pcall(simOMPL.solve, 12345, 1)
end
function report()
    return solved, states, collisions, halfway, startValid, path, start, goal, afterReplay,
        badSpace, badState, badPairs, badTask
end
"#;

#[test]
fn a_plan_for_the_arm_goes_around_the_obstacles_and_replays_without_collision() {
    let mut sc = Scene::new(
        "ompl-arm",
        &arm_scene(),
        &[("planner.lua", PLANNER)],
        gantry_lua::ScriptLimits::default(),
    );
    sc.sim.start();
    sc.sim.step();
    util::assert_running(&sc.sim, "planner.lua");
    let r = sc.call("report", &[]);
    assert_eq!(r[0], Value::Bool(true), "a path was found");
    assert_eq!(r[1], Value::Int(50), "the path was resampled to 50 states");
    assert_eq!(r[2], Value::Int(0), "no state of the replayed path collides");
    assert_eq!(r[3], Value::Bool(false), "turning the base alone hits a box");
    assert_eq!(r[4], Value::Bool(true));
    let path = floats(&r[5]);
    let (start, goal) = (floats(&r[6]), floats(&r[7]));
    assert_close(&path[..3], &start, 1e-9);
    assert_close(&path[path.len() - 3..], &goal, 1e-9);
    // Going around means leaving the stretched-out posture on the way.
    let bends = path
        .chunks(3)
        .any(|s| (s[1] - start[1]).abs() > 0.1 || (s[2] - start[2]).abs() > 0.1);
    assert!(bends, "the path lifts or folds the arm: {path:?}");
    assert_close(&floats(&r[8]), &[goal[0], goal[1]], 1e-9);
    assert_contains(text(&r[9]), &["simOMPL.createStateSpace", "Dubins"]);
    assert_contains(text(&r[10]), &["simOMPL.setStartState", "3 values"]);
    assert_contains(text(&r[11]), &["simOMPL.setCollisionPairs", "two by two"]);
    assert_contains(text(&r[12]), &["simOMPL.solve", "task 12345 does not exist"]);
}

/// Two runs of the same script plan the same path: planners are seeded per task.
#[test]
fn plans_are_the_same_in_every_run() {
    let run = || {
        let mut sc = Scene::new(
            "ompl-repeat",
            &arm_scene(),
            &[("planner.lua", PLANNER)],
            gantry_lua::ScriptLimits::default(),
        );
        sc.sim.start();
        sc.sim.step();
        floats(&sc.call("report", &[])[5])
    };
    assert_eq!(run(), run());
}
