//! `simOMPL.*`: CoppeliaSim's motion-planning plugin, on gantry's planner
//! ([`crate::planning`]): state spaces over objects and joints, tasks with collision
//! pairs checked against the scene, RRT-Connect with path shortening.
//!
//! States are flat lists, the spaces' values in the order the task lists the spaces
//! (pose3d: x, y, z, qx, qy, qz, qw); paths are the states one after the other.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::planning::{ALGORITHMS, RRT_CONNECT, SpaceKind, StateSpace};
use crate::sim::Sim;
use crate::world::Handle;

/// `simOMPL.StateSpaceType.*` and `simOMPL.Algorithm.*` (gantry's numbers; scripts use
/// the names).
pub(super) const CONSTANTS: &[(&str, i64)] = &[
    ("StateSpaceType.position2d", 0),
    ("StateSpaceType.pose2d", 1),
    ("StateSpaceType.position3d", 2),
    ("StateSpaceType.pose3d", 3),
    ("StateSpaceType.joint_position", 4),
    ("StateSpaceType.dubins", 5),
    ("StateSpaceType.cyclic_joint_position", 6),
    ("Algorithm.BiTRRT", 0),
    ("Algorithm.BITstar", 1),
    ("Algorithm.BKPIECE1", 2),
    ("Algorithm.CForest", 3),
    ("Algorithm.EST", 4),
    ("Algorithm.FMT", 5),
    ("Algorithm.KPIECE1", 6),
    ("Algorithm.LazyPRM", 7),
    ("Algorithm.LazyPRMstar", 8),
    ("Algorithm.LazyRRT", 9),
    ("Algorithm.LBKPIECE1", 10),
    ("Algorithm.LBTRRT", 11),
    ("Algorithm.PDST", 12),
    ("Algorithm.PRM", 13),
    ("Algorithm.PRMstar", 14),
    ("Algorithm.pRRT", 15),
    ("Algorithm.pSBL", 16),
    ("Algorithm.RRT", 17),
    ("Algorithm.RRTConnect", RRT_CONNECT),
    ("Algorithm.RRTstar", 19),
    ("Algorithm.SBL", 20),
    ("Algorithm.SPARS", 21),
    ("Algorithm.SPARStwo", 22),
    ("Algorithm.STRIDE", 23),
    ("Algorithm.TRRT", 24),
    // Older plugin versions' names.
    ("Algorithm.BKPIECE", 2),
    ("Algorithm.KPIECE", 6),
    ("Algorithm.LBKPIECE", 10),
];

/// The functions, sorted by name.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    f("addGoalState", add_goal_state),
    f("compute", compute),
    f("createStateSpace", create_state_space),
    f("createTask", create_task),
    f("destroyStateSpace", destroy_state_space),
    f("destroyTask", destroy_task),
    f("getPath", get_path),
    f("getPathState", get_path_state),
    f("getPathStateCount", get_path_state_count),
    f("hasSolution", has_solution),
    f("interpolatePath", interpolate_path),
    f("isStateValid", is_state_valid),
    f("printTaskInfo", print_task_info),
    f("readState", read_state),
    f("setAlgorithm", set_algorithm),
    f("setCollisionPairs", set_collision_pairs),
    f("setGoalState", set_goal_state),
    f("setStartState", set_start_state),
    f("setStateSpace", set_state_space),
    f("setStateValidityCheckingResolution", set_resolution),
    f("setVerboseLevel", set_verbose_level),
    f("setup", setup),
    f("solve", solve),
    f("writeState", write_state),
];

/// A simOMPL function: planning (`compute`, `solve`) runs long, the rest is setting up.
const fn f(
    name: &'static str,
    call: fn(&mut Sim, &CallContext<'_>, &Args<'_>) -> Result<Ret, SimError>,
) -> ApiFunction {
    let long = matches!(name.as_bytes(), b"compute" | b"solve");
    ApiFunction {
        name,
        call: ApiFn::Sim(call),
        cost: if long { Cost::Long } else { Cost::Quick },
    }
}

/// A list of handles, argument `i`.
fn handles(a: &Args<'_>, i: usize) -> Result<Vec<Handle>, SimError> {
    let bad = || SimError::bad_argument(format!("argument {}: expected a table of handles", i + 1));
    let Value::Array(items) = a.get(i) else {
        return Err(bad());
    };
    items.iter().map(|v| v.as_i64().ok_or_else(bad)).collect()
}

fn flat(states: &[Vec<f64>]) -> Value {
    Value::Array(states.iter().flatten().map(|v| Value::Float(*v)).collect())
}

/// `simOMPL.createStateSpace(name, type, objectHandle, boundsLow, boundsHigh,
/// useForProjection, weight=1, refObjectHandle=-1)` → handle. Bounds are the
/// positions' (x, y or x, y, z, m) for object spaces, the joint's for a joint space;
/// rotations are unbounded. `useForProjection` only guides OMPL's projection-based
/// planners and is accepted.
fn create_state_space(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let name = a.str(0)?;
    let kind = SpaceKind::from_code(a.int(1)?)?;
    let object = a.handle(2)?;
    match kind {
        SpaceKind::JointPosition | SpaceKind::CyclicJointPosition => {
            sim.world.joint(object)?;
        }
        _ => {
            sim.world.object(object)?;
        }
    }
    let (low, high) = (a.numbers(3)?, a.numbers(4)?);
    let weight = a.opt_f64(6, 1.0)?;
    let reference = a.opt_int(7, -1)?;
    if reference >= 0 {
        sim.world.object(reference)?;
    }
    let space = StateSpace::new(name, kind, object, low, high, weight, reference)?;
    Ok(vec![Value::Int(sim.planning.add_space(space))])
}

/// `simOMPL.destroyStateSpace(handle)`.
fn destroy_state_space(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    sim.planning.remove_space(a.handle(0)?)?;
    Ok(Vec::new())
}

/// `simOMPL.createTask(name)` → handle.
fn create_task(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Int(sim.planning.add_task(a.str(0)?))])
}

/// `simOMPL.destroyTask(handle)`.
fn destroy_task(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    sim.planning.remove_task(a.handle(0)?)?;
    Ok(Vec::new())
}

/// `simOMPL.setStateSpace(task, stateSpaceHandles)`: the spaces whose values make up a
/// state, in order. Clears the start, goals and path.
fn set_state_space(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let task = a.handle(0)?;
    let spaces = handles(a, 1)?
        .into_iter()
        .map(|h| sim.planning.space(h).cloned())
        .collect::<Result<Vec<_>, _>>()?;
    if spaces.is_empty() {
        return Err(SimError::bad_argument(
            "argument 2: a task needs at least one state space",
        ));
    }
    let t = sim.planning.task_mut(task)?;
    t.spaces = spaces;
    t.start = None;
    t.goals.clear();
    t.path = None;
    Ok(Vec::new())
}

/// `simOMPL.setAlgorithm(task, algorithm)`. gantry plans with RRT-Connect; another
/// algorithm is accepted with a warning in the log and planned with RRT-Connect.
fn set_algorithm(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let task = a.handle(0)?;
    let algorithm = a.int(1)?;
    let name = usize::try_from(algorithm)
        .ok()
        .and_then(|i| ALGORITHMS.get(i))
        .ok_or_else(|| {
            SimError::bad_argument(format!(
                "argument 2: invalid algorithm {algorithm} (simOMPL.Algorithm.*)"
            ))
        })?;
    sim.planning.task_mut(task)?.algorithm = algorithm;
    if algorithm != RRT_CONNECT {
        let t = sim.world.time();
        sim.world.log.push(
            t,
            300,
            ctx.source,
            &format!("simOMPL.Algorithm.{name} is not implemented in gantry; the task plans with RRTConnect"),
        );
    }
    Ok(Vec::new())
}

/// `simOMPL.setCollisionPairs(task, pairs)`: entities (objects, collections,
/// `sim.handle_all`) two by two that must not collide along the path.
fn set_collision_pairs(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let task = a.handle(0)?;
    let list = handles(a, 1)?;
    if !list.len().is_multiple_of(2) {
        return Err(SimError::bad_argument(format!(
            "argument 2: collision pairs come two by two, got {} handles",
            list.len()
        )));
    }
    for &h in &list {
        sim.world.entity_shapes(h, &[])?;
    }
    sim.planning.task_mut(task)?.collision_pairs = list.chunks_exact(2).map(|p| [p[0], p[1]]).collect();
    Ok(Vec::new())
}

/// `simOMPL.setStartState(task, state)`.
fn set_start_state(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let state = a.numbers(1)?;
    let t = sim.planning.task_mut(a.handle(0)?)?;
    t.check_state(&state)?;
    t.start = Some(state);
    Ok(Vec::new())
}

/// `simOMPL.setGoalState(task, state)`: the only goal.
fn set_goal_state(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let state = a.numbers(1)?;
    let t = sim.planning.task_mut(a.handle(0)?)?;
    t.check_state(&state)?;
    t.goals = vec![state];
    Ok(Vec::new())
}

/// `simOMPL.addGoalState(task, state)`: one more goal; the path ends at whichever goal
/// the planner reaches first.
fn add_goal_state(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let state = a.numbers(1)?;
    let t = sim.planning.task_mut(a.handle(0)?)?;
    t.check_state(&state)?;
    t.goals.push(state);
    Ok(Vec::new())
}

/// `simOMPL.setStateValidityCheckingResolution(task, resolution)`: the longest step
/// between checked states along a motion, as a fraction of the space's extent
/// (default 0.01).
fn set_resolution(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let r = a.f64(1)?;
    if !(r > 0.0 && r <= 1.0) {
        return Err(SimError::bad_argument(format!(
            "argument 2: resolution must be in (0, 1], got {r}"
        )));
    }
    sim.planning.task_mut(a.handle(0)?)?.resolution = r;
    Ok(Vec::new())
}

/// `simOMPL.setVerboseLevel(task, level)`: accepted (gantry's planner logs nothing).
fn set_verbose_level(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    sim.planning.task(a.handle(0)?)?;
    a.int(1)?;
    Ok(Vec::new())
}

/// `simOMPL.setup(task)`: checks that the task has spaces (planning sets itself up).
fn setup(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let t = sim.planning.task(a.handle(0)?)?;
    if t.spaces.is_empty() {
        return Err(SimError::bad_argument(format!(
            "task '{}' has no state space yet (simOMPL.setStateSpace)",
            t.name
        )));
    }
    Ok(Vec::new())
}

/// Runs `f` on task `h` with the world, the task taken out of the store meanwhile.
fn with_task<T>(
    sim: &mut Sim,
    h: Handle,
    f: impl FnOnce(&mut crate::planning::Task, &mut crate::world::World) -> Result<T, SimError>,
) -> Result<T, SimError> {
    let mut task = sim.planning.task(h)?.clone();
    let out = f(&mut task, &mut sim.world);
    *sim.planning.task_mut(h)? = task;
    out
}

/// `simOMPL.solve(task, maxTime)` → whether a path was found within `maxTime` seconds
/// (shortened for up to 5 s more).
fn solve(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let max_time = a.f64(1)?;
    let found = with_task(sim, a.handle(0)?, |t, w| crate::planning::solve(t, w, max_time, -1.0))?;
    Ok(vec![Value::Bool(found)])
}

/// `simOMPL.compute(task, maxTime, maxSimplificationTime=-1, stateCnt=0)` → `solved,
/// states`: solves, shortens the path (for at most `maxSimplificationTime` s; -1: a
/// default effort), and returns it with `stateCnt` states spread evenly along it (0:
/// as found).
fn compute(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let max_time = a.f64(1)?;
    let simplify = a.opt_f64(2, -1.0)?;
    let count = usize::try_from(a.opt_int(3, 0)?)
        .map_err(|_| SimError::bad_argument("argument 4: stateCnt must be 0 or more"))?;
    let found = with_task(sim, h, |t, w| crate::planning::solve(t, w, max_time, simplify))?;
    let path = sim
        .planning
        .task(h)?
        .interpolated(count.min(100_000))
        .unwrap_or_default();
    Ok(vec![Value::Bool(found), flat(&path)])
}

/// `simOMPL.getPath(task)` → the last path's states, flat.
fn get_path(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![flat(
        &sim.planning.task(a.handle(0)?)?.path.clone().unwrap_or_default(),
    )])
}

/// `simOMPL.interpolatePath(task, stateCnt=0)`: the last path, resampled to `stateCnt`
/// states evenly spread along it.
fn interpolate_path(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let count = usize::try_from(a.opt_int(1, 0)?)
        .map_err(|_| SimError::bad_argument("argument 2: stateCnt must be 0 or more"))?;
    let t = sim.planning.task_mut(a.handle(0)?)?;
    t.path = t.interpolated(count.min(100_000));
    Ok(Vec::new())
}

/// `simOMPL.getPathStateCount(task)` → states in the last path (0 without one).
fn get_path_state_count(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let n = sim.planning.task(a.handle(0)?)?.path.as_ref().map_or(0, Vec::len);
    Ok(vec![Value::Int(n as i64)])
}

/// `simOMPL.getPathState(task, index)` → state `index` (from 1) of the last path.
fn get_path_state(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let i = a.int(1)?;
    let path = sim.planning.task(a.handle(0)?)?.path.clone().unwrap_or_default();
    let state = usize::try_from(i - 1)
        .ok()
        .and_then(|k| path.get(k))
        .ok_or_else(|| SimError::bad_argument(format!("argument 2: index {i} is not in 1..={}", path.len())))?;
    Ok(vec![Value::floats(state)])
}

/// `simOMPL.hasSolution(task)` → whether the last solve found a path.
fn has_solution(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Bool(sim.planning.task(a.handle(0)?)?.path.is_some())])
}

/// `simOMPL.isStateValid(task, state)` → whether the state is within bounds and free
/// of the collision pairs' contacts (the scene is put back after the check).
fn is_state_valid(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let state = a.numbers(1)?;
    let valid = with_task(sim, a.handle(0)?, |t, w| crate::planning::is_valid(t, w, &state))?;
    Ok(vec![Value::Bool(valid)])
}

/// `simOMPL.readState(task)` → the scene's current state in the task's spaces.
fn read_state(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let t = sim.planning.task(a.handle(0)?)?;
    let mut out = Vec::new();
    for s in &t.spaces {
        crate::planning::read_state(s, &sim.world, &mut out)?;
    }
    Ok(vec![Value::floats(&out)])
}

/// `simOMPL.writeState(task, state)`: puts the scene in the state (objects placed,
/// joints set), as replaying a path does.
fn write_state(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let state = a.numbers(1)?;
    let t = sim.planning.task(a.handle(0)?)?;
    t.check_state(&state)?;
    let mut at = 0;
    for s in t.spaces.clone() {
        let n = s.kind.dimension();
        crate::planning::write_state(&s, &mut sim.world, &state[at..at + n])?;
        at += n;
    }
    Ok(Vec::new())
}

/// `simOMPL.printTaskInfo(task)`: the task's spaces, pairs and states, as a log line.
fn print_task_info(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let t = sim.planning.task(a.handle(0)?)?;
    let spaces: Vec<String> = t
        .spaces
        .iter()
        .map(|s| format!("{} ({:?} of {})", s.name, s.kind, s.object))
        .collect();
    let text = format!(
        "task '{}': spaces [{}], algorithm {}, collision pairs {:?}, start {:?}, goals {:?}, path states {}",
        t.name,
        spaces.join(", "),
        ALGORITHMS.get(t.algorithm as usize).unwrap_or(&"?"),
        t.collision_pairs,
        t.start,
        t.goals,
        t.path.as_ref().map_or(0, Vec::len)
    );
    let now = sim.world.time();
    sim.world.log.push(now, 450, ctx.source, &text);
    Ok(Vec::new())
}
