//! V-REP 3 / CoppeliaSim 4.0-4.2's built-in kinematics: an IK group defined in the scene
//! (`[[ik_group]]`), reached by handle with `sim.getIkGroupHandle`, solved explicitly with
//! `sim.handleIkGroup`, or every step by the main script once `sim.setExplicitHandling`
//! clears its explicit flag. The bundled six-axis arm's tool tip follows the target.

use crate::util;
use util::Drive;

use gantry_sim_core::Value;
use gantry_test_support::{TempDir, assert_contains, floats, int, ints, num, text};
use util::Scene;

/// The paper's arm, kinematic, in its start pose (tool down), its tip dummy on the
/// flange, a target dummy on the tip, and an IK group driving the tip onto the target,
/// flagged explicit as `explicit` says. `script` is attached to the target.
fn arm_scene(explicit: bool, script: &str) -> String {
    util::arm6_scene_head(None)
        + &format!(
            r#"
[[object]]
name = "tip_frame"
alias = "ik_tip"
kind = "dummy"
parent = "arm6/tip"

[[object]]
name = "target"
kind = "dummy"
position = [0.45, 0, 0.652]
orientation_deg = [0, 90, 0]
script = "{script}"

[[ik_group]]
name = "arm_ik"
method = "damped_least_squares"
damping = 0.05
max_iterations = 200
explicit = {explicit}

[[ik_group.element]]
tip = "tip_frame"
target = "target"
base = "arm6"
constraints = "pose"
"#
        )
}

/// A non-threaded V-REP 3.x style script: it moves the target each step; on odd steps
/// it also handles the group explicitly, on even steps not (the group is explicit, so
/// nothing else solves it). It records the tip-target distance after each.
const EXPLICIT: &str = r#"
function sysCall_init()
    ikGroup = sim.getIkGroupHandle('arm_ik')
    tip = sim.getObjectHandle('ik_tip')
    target = sim.getObjectHandle('target')
    explicitAtStart = sim.getExplicitHandling(ikGroup)
    step = 0
    results = {}
    handled = {}
    unhandled = {}
    ok1, unknownName = pcall(sim.getIkGroupHandle, 'no_such_group')
    ok2, badHandle = pcall(sim.handleIkGroup, 12345)
    ok3, badExplicit = pcall(sim.setExplicitHandling, 987654, 0)
    ok4, badMatrix = pcall(sim.getIkGroupMatrix, ikGroup, 7)
end

local function distance()
    local a = sim.getObjectPosition(tip, -1)
    local b = sim.getObjectPosition(target, -1)
    return math.sqrt((a[1]-b[1])^2 + (a[2]-b[2])^2 + (a[3]-b[3])^2)
end

function sysCall_actuation()
    step = step + 1
    if step > 4 then return end
    local p = sim.getObjectPosition(target, -1)
    sim.setObjectPosition(target, -1, {p[1] - 0.03, p[2] + 0.04, p[3] - 0.03})
    if step % 2 == 1 then
        results[#results + 1] = sim.handleIkGroup(ikGroup)
        handled[#handled + 1] = distance()
    end
end

function sysCall_sensing()
    if step <= 4 and step % 2 == 0 then
        unhandled[#unhandled + 1] = distance()
    end
end

function report()
    local jacobian, size = sim.getIkGroupMatrix(ikGroup, 0)
    local manipulability = sim.getIkGroupMatrix(ikGroup, 1)
    return explicitAtStart, results, handled, unhandled, sim.ikresult_success,
        unknownName, badHandle, badExplicit, badMatrix, size, #jacobian, manipulability[1]
end
"#;

#[test]
fn an_explicit_group_moves_the_tip_onto_the_target_only_when_handled() {
    let mut sc = Scene::new(
        "ikgroups-explicit",
        &arm_scene(true, "ik.lua"),
        &[("ik.lua", EXPLICIT)],
        gantry_lua::ScriptLimits::default(),
    );
    sc.sim.start();
    for _ in 0..6 {
        sc.sim.step();
    }
    util::assert_running(&sc.sim, "ik.lua");
    let r = sc.call("report", &[]);
    assert_eq!(r[0], Value::Int(1), "the scene flags the group explicit");
    let success = r[4].clone();
    assert_eq!(ints(&r[1]), vec![int(&success); 2], "sim.handleIkGroup succeeds");
    for d in floats(&r[2]) {
        assert!(d < 1e-3, "after sim.handleIkGroup the tip is on the target: {d} m");
    }
    // The target moved by about 5.8 cm on those steps and nothing solved the group.
    for d in floats(&r[3]) {
        assert!(d > 0.05, "an explicit group is not handled by the main script: {d} m");
    }
    assert_contains(text(&r[5]), &["sim.getIkGroupHandle", "no_such_group"]);
    assert_contains(text(&r[6]), &["sim.handleIkGroup", "IK group 12345 does not exist"]);
    assert_contains(text(&r[7]), &["sim.setExplicitHandling", "987654"]);
    assert_contains(text(&r[8]), &["sim.getIkGroupMatrix", "options"]);
    // Six constrained components (pose), six joints between the base and the tip.
    assert_eq!(ints(&r[9]), vec![6, 6]);
    assert_eq!(r[10], Value::Int(36));
    assert!(num(&r[11]) > 0.0, "the arm is not singular here");
}

/// A threaded V-REP 3.x style script: it makes the group automatic, then moves the
/// target and lets the step go on; the main script's IK handling after the actuation
/// puts the tip on the target before the thread resumes.
const AUTOMATIC: &str = r#"
function sysCall_threadmain()
    local ikGroup = sim.getIkGroupHandle('arm_ik')
    local tip = sim.getObjectHandle('ik_tip')
    local target = sim.getObjectHandle('target')
    sim.setExplicitHandling(ikGroup, 0)
    explicitNow = sim.getExplicitHandling(ikGroup)
    distances = {}
    for k = 1, 3 do
        local p = sim.getObjectPosition(target, -1)
        sim.setObjectPosition(target, -1, {p[1] - 0.03, p[2] - 0.04, p[3] + 0.03})
        sim.switchThread()
        local a = sim.getObjectPosition(tip, -1)
        local b = sim.getObjectPosition(target, -1)
        distances[k] = math.sqrt((a[1]-b[1])^2 + (a[2]-b[2])^2 + (a[3]-b[3])^2)
    end
    -- Each group handled explicitly still answers with its result.
    result = sim.handleIkGroup(ikGroup)
    count = sim.handleIkGroup(sim.handle_all)
    done = true
end

function report()
    return done, explicitNow, distances, result, sim.ikresult_success, count
end
"#;

#[test]
fn an_automatic_group_is_handled_every_step_after_the_scripts_actuation() {
    let mut sc = Scene::new(
        "ikgroups-automatic",
        &arm_scene(true, "ik.lua"),
        &[("ik.lua", AUTOMATIC)],
        gantry_lua::ScriptLimits::default(),
    );
    sc.sim.start();
    for _ in 0..6 {
        sc.sim.step();
    }
    util::assert_running(&sc.sim, "ik.lua");
    let r = sc.call("report", &[]);
    assert_eq!(r[0], Value::Bool(true), "the thread ran to its end");
    assert_eq!(
        r[1],
        Value::Int(0),
        "sim.setExplicitHandling(h, 0) made the group automatic"
    );
    let d = floats(&r[2]);
    assert_eq!(d.len(), 3);
    for d in d {
        assert!(d < 1e-3, "the main script put the tip on the target: {d} m");
    }
    assert_eq!(
        r[3], r[4],
        "sim.handleIkGroup on the solved group: sim.ikresult_success"
    );
    assert_eq!(r[5], Value::Int(1), "sim.handle_all handles the one automatic group");
}

/// `sim.setIkGroupProperties` and `sim.setIkElementProperties` change how the group
/// solves: position only leaves the tool's orientation alone, and one iteration of
/// the pseudo-inverse does not reach a target 10 cm away.
const PROPERTIES: &str = r#"
function sysCall_init()
    local ikGroup = sim.getIkGroupHandle('arm_ik')
    local tip = sim.getObjectHandle('ik_tip')
    local target = sim.getObjectHandle('target')
    local p = sim.getObjectPosition(target, -1)
    sim.setObjectPosition(target, -1, {p[1], p[2] + 0.1, p[3]})
    sim.setIkGroupProperties(ikGroup, sim.ik_pseudo_inverse_method, 1, 0)
    oneIteration = sim.handleIkGroup(ikGroup)
    sim.setIkGroupProperties(ikGroup, sim.ik_damped_least_squares_method, 200, 0.05)
    sim.setObjectOrientation(target, -1, {0, 0, 0})
    sim.setIkElementProperties(ikGroup, tip, sim.ik_x_constraint + sim.ik_y_constraint + sim.ik_z_constraint)
    positionOnly = sim.handleIkGroup(ikGroup)
    local a = sim.getObjectPosition(tip, -1)
    local b = sim.getObjectPosition(target, -1)
    gap = math.sqrt((a[1]-b[1])^2 + (a[2]-b[2])^2 + (a[3]-b[3])^2)
    jacobian, size = sim.getIkGroupMatrix(ikGroup, 0)
    ok1, badMethod = pcall(sim.setIkGroupProperties, ikGroup, 9, 10, 0.1)
    ok2, badTip = pcall(sim.setIkElementProperties, ikGroup, target, 7)
    local joints = {}
    for i = 1, 6 do joints[i] = sim.getObjectHandle('joint' .. i) end
    config = sim.getConfigForTipPose(ikGroup, joints, 0.5, 100)
end
function report()
    return oneIteration, positionOnly, gap, size, badMethod, badTip, config
end
"#;

#[test]
fn group_and_element_properties_change_the_solve() {
    let mut sc = Scene::new(
        "ikgroups-properties",
        &arm_scene(true, "ik.lua"),
        &[("ik.lua", PROPERTIES)],
        gantry_lua::ScriptLimits::default(),
    );
    sc.sim.start();
    util::assert_running(&sc.sim, "ik.lua");
    let r = sc.call("report", &[]);
    assert_eq!(r[0], Value::Int(2), "one iteration: sim.ikresult_fail");
    assert_eq!(r[1], Value::Int(1), "position only: sim.ikresult_success");
    assert!(num(&r[2]) < 1e-3, "the tip reached the target's position");
    assert_eq!(ints(&r[3]), vec![6, 3], "three position rows, six joints");
    assert_contains(text(&r[4]), &["sim.setIkGroupProperties", "resolution method 9"]);
    assert_contains(text(&r[5]), &["sim.setIkElementProperties", "no element whose tip"]);
    assert_eq!(floats(&r[6]).len(), 6, "a configuration for the six joints");
}

/// The loader checks `[[ik_group]]` tables: elements' tips and targets are dummies,
/// methods and constraints are known names, and the file's line is in the message.
#[test]
fn bad_ik_group_tables_are_load_errors() {
    use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene_text};
    let dir = TempDir::new("ikgroups-load");
    let path = dir.path().join("scene.toml");
    let load = |text: &str| {
        load_scene_text(&DiskFiles, text, &path, &LoadOptions::default())
            .map(|m| m.ik_groups.len())
            .map_err(|e| e.to_string())
    };
    let good = arm_scene(false, "none.lua").replace("script = \"none.lua\"\n", "");
    assert_eq!(load(&good), Ok(1));
    let err = load(&good.replace("tip = \"tip_frame\"", "tip = \"arm6/joint1\"")).unwrap_err();
    assert_contains(&err, &["ik_group 'arm_ik'", "'arm6/joint1' is not a dummy"]);
    let err = load(&good.replace("\"damped_least_squares\"", "\"newton\"")).unwrap_err();
    assert_contains(&err, &["unknown method 'newton'"]);
    let err = load(&good.replace("constraints = \"pose\"", "constraints = \"x+w\"")).unwrap_err();
    assert_contains(&err, &["constraints 'x+w'"]);
    let err = load(&good.replace("target = \"target\"", "target = \"nowhere\"")).unwrap_err();
    assert_contains(&err, &["nowhere"]);
}
