//! Motion planning on the scene (`simOMPL`): the planner, state spaces and tasks are the
//! crate `gantry-planning`, re-exported here; this file puts the scene in a task's states
//! and checks them with the world's collision queries.
//!
//! A state is valid when it lies within the spaces' bounds and, with the scene put in
//! that state, no collision pair collides. A motion is valid when the states along it,
//! at most `resolution` x the space's extent apart (OMPL's state validity checking
//! resolution, 1 % by default), are. The scene is put back as it was after planning.

use std::time::{Duration, Instant};

pub use gantry_planning::*;

use crate::error::SimError;
use crate::math::Pose;
use crate::world::{Handle, World};

/// Space `space`'s part of the scene's current configuration, appended to `out`.
///
/// # Errors
/// The object or joint is gone.
pub fn read_state(space: &StateSpace, world: &World, out: &mut Vec<f64>) -> Result<(), SimError> {
    if space.moves_joint() {
        out.push(world.joint(space.object)?.position);
    } else {
        space.pose_state(&local_pose(space, world)?, out);
    }
    Ok(())
}

/// Puts the scene in space `space`'s part of a state, `s`.
///
/// # Errors
/// The object or joint is gone.
pub fn write_state(space: &StateSpace, world: &mut World, s: &[f64]) -> Result<(), SimError> {
    if space.moves_joint() {
        return world.set_joint_position(space.object, s[0]);
    }
    let mut p = local_pose(space, world)?;
    space.set_pose_state(&mut p, s);
    let frame = reference_frame(space, world)?;
    world.set_world_pose(space.object, frame * p)
}

/// Whether `state` is valid in the scene (bounds, collision pairs); the scene is put
/// back as it was.
///
/// # Errors
/// A bad state, or an object of the task that is gone.
pub fn is_valid(task: &Task, world: &mut World, state: &[f64]) -> Result<bool, SimError> {
    task.check_state(state)?;
    let mut scene = SceneProblem::new(task, world, Instant::now() + Duration::from_secs(1))?;
    let valid = scene.valid(state);
    scene.restore()?;
    Ok(valid)
}

/// Plans task `task` from its start to a goal for at most `max_time` seconds, then
/// shortens the path for at most `simplify_time` seconds (a negative time: a default
/// effort). Returns whether a path was found; it is kept in [`Task::path`].
///
/// # Errors
/// No start or goal, states of the wrong size, an invalid start or goals, or an
/// object of the task that is gone.
pub fn solve(task: &mut Task, world: &mut World, max_time: f64, simplify_time: f64) -> Result<bool, SimError> {
    let start = task.start.clone().ok_or_else(|| {
        SimError::BadArgument(format!(
            "task '{}' has no start state (simOMPL.setStartState)",
            task.name
        ))
    })?;
    if task.goals.is_empty() {
        return Err(SimError::BadArgument(format!(
            "task '{}' has no goal state (simOMPL.setGoalState)",
            task.name
        )));
    }
    task.check_state(&start)?;
    for g in &task.goals {
        task.check_state(g)?;
    }
    if !(max_time.is_finite() && max_time > 0.0) {
        return Err(SimError::BadArgument(format!(
            "maxTime must be positive, got {max_time}"
        )));
    }
    // The seconds at most one call may take, whatever a script asks: the planner runs
    // on the simulation thread.
    let max_time = max_time.min(600.0);
    let deadline = Instant::now() + Duration::from_secs_f64(max_time);
    let mut rng = task.rng.clone();
    let mut scene = SceneProblem::new(task, world, deadline)?;
    let outcome = (|| {
        if !scene.valid(&start) {
            return Err(SimError::BadArgument(format!(
                "task '{}': the start state is in collision or out of bounds",
                task.name
            )));
        }
        let goals: Vec<Vec<f64>> = task.goals.iter().filter(|g| scene.valid(g)).cloned().collect();
        if goals.is_empty() {
            return Err(SimError::BadArgument(format!(
                "task '{}': every goal state is in collision or out of bounds",
                task.name
            )));
        }
        let range = 0.2 * scene.extent;
        let mut path = rrt_connect::plan(&mut scene, &start, &goals, range, &mut rng);
        if let Some(path) = path.as_mut() {
            let simplify = if simplify_time < 0.0 {
                5.0
            } else {
                simplify_time.min(600.0)
            };
            scene.deadline = Instant::now() + Duration::from_secs_f64(simplify);
            rrt_connect::shortcut(&mut scene, path, 200, &mut rng);
        }
        Ok(path)
    })();
    scene.restore()?;
    task.rng = rng;
    let path = outcome?;
    let found = path.is_some();
    task.path = path;
    Ok(found)
}

/// The frame space `space`'s object positions are in.
fn reference_frame(space: &StateSpace, world: &World) -> Result<Pose, SimError> {
    Ok(if space.reference < 0 {
        Pose::identity()
    } else {
        world.object(space.reference)?.world
    })
}

/// Space `space`'s object's pose in the space's reference frame.
fn local_pose(space: &StateSpace, world: &World) -> Result<Pose, SimError> {
    Ok(reference_frame(space, world)?.inverse() * world.object(space.object)?.world)
}

/// The planning problem over the scene: states are written into the world and checked
/// with its collision queries.
struct SceneProblem<'a> {
    metric: Metric<'a>,
    world: &'a mut World,
    pairs: Vec<(Vec<Handle>, Vec<Handle>)>,
    saved: Vec<f64>,
    extent: f64,
    step: f64,
    deadline: Instant,
}

impl<'a> SceneProblem<'a> {
    fn new(task: &'a Task, world: &'a mut World, deadline: Instant) -> Result<Self, SimError> {
        let mut saved = Vec::new();
        for sp in &task.spaces {
            read_state(sp, world, &mut saved)?;
        }
        let mut pairs = Vec::new();
        for [a, b] in &task.collision_pairs {
            let first = world.entity_shapes(*a, &[])?;
            let second = world.entity_shapes(*b, &first)?;
            pairs.push((first, second));
        }
        let extent: f64 = task.spaces.iter().map(|s| s.weight * s.extent()).sum();
        Ok(Self {
            metric: task.metric(),
            world,
            pairs,
            saved,
            extent,
            step: (task.resolution * extent).max(1e-9),
            deadline,
        })
    }

    fn valid(&mut self, s: &[f64]) -> bool {
        let mut within = true;
        for (sp, part) in self.metric.parts(s) {
            within &= sp.within(part);
        }
        if !within {
            return false;
        }
        for (sp, part) in self.metric.parts(s) {
            if write_state(sp, self.world, part).is_err() {
                return false;
            }
        }
        if self.pairs.is_empty() {
            return true;
        }
        self.world.refresh_queries();
        self.pairs.iter().all(|(a, b)| self.world.collision(a, b).is_none())
    }

    fn restore(self) -> Result<(), SimError> {
        let saved = self.saved.clone();
        for (sp, part) in self.metric.parts(&saved) {
            write_state(sp, self.world, part)?;
        }
        self.world.refresh_queries();
        Ok(())
    }
}

impl rrt_connect::Problem for SceneProblem<'_> {
    fn sample(&mut self, rng: &mut Rng) -> Vec<f64> {
        let mut out = Vec::new();
        for sp in self.metric.spaces {
            sp.sample(rng, &mut out);
        }
        out
    }

    fn distance(&self, a: &[f64], b: &[f64]) -> f64 {
        self.metric.distance(a, b)
    }

    fn interpolate(&self, a: &[f64], b: &[f64], t: f64) -> Vec<f64> {
        self.metric.interpolate(a, b, t)
    }

    fn motion_valid(&mut self, a: &[f64], b: &[f64]) -> bool {
        let n = (self.distance(a, b) / self.step).ceil().max(1.0) as usize;
        (1..=n).all(|k| {
            let s = self.interpolate(a, b, k as f64 / n as f64);
            self.valid(&s)
        })
    }

    fn out_of_time(&self) -> bool {
        Instant::now() >= self.deadline
    }
}
