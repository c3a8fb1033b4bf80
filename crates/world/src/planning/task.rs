//! A motion-planning task as `simOMPL` builds it: state spaces, collision pairs, start
//! and goal states, then a plan checked against the scene's own collision geometry.
//!
//! A state is valid when it lies within the spaces' bounds and, with the scene put in
//! that state, no collision pair collides. A motion is valid when the states along it,
//! at most `resolution` x the space's extent apart (OMPL's state validity checking
//! resolution, 1 % by default), are. The scene is put back as it was after planning.

use std::time::{Duration, Instant};

use crate::error::SimError;
use crate::world::{Handle, World};

use super::rng::Rng;
use super::rrt_connect::{self, Problem};
use super::space::StateSpace;

/// `simOMPL.Algorithm`'s names, in the order of their numbers.
pub const ALGORITHMS: &[&str] = &[
    "BiTRRT",
    "BITstar",
    "BKPIECE1",
    "CForest",
    "EST",
    "FMT",
    "KPIECE1",
    "LazyPRM",
    "LazyPRMstar",
    "LazyRRT",
    "LBKPIECE1",
    "LBTRRT",
    "PDST",
    "PRM",
    "PRMstar",
    "pRRT",
    "pSBL",
    "RRT",
    "RRTConnect",
    "RRTstar",
    "SBL",
    "SPARS",
    "SPARStwo",
    "STRIDE",
    "TRRT",
];

/// The number of `simOMPL.Algorithm.RRTConnect`, the planner gantry runs.
pub const RRT_CONNECT: i64 = 18;

/// One planning task.
#[derive(Debug, Clone)]
pub struct Task {
    /// The name given at creation.
    pub name: String,
    /// Its state spaces, in order (their values make up a state).
    pub spaces: Vec<StateSpace>,
    /// The `simOMPL.Algorithm` asked for.
    pub algorithm: i64,
    /// Pairs of entities (objects, collections, `sim.handle_all`) that must not collide.
    pub collision_pairs: Vec<[Handle; 2]>,
    /// The start state.
    pub start: Option<Vec<f64>>,
    /// The goal states (any one will do).
    pub goals: Vec<Vec<f64>>,
    /// The longest step between checked states along a motion, as a fraction of the
    /// space's extent.
    pub resolution: f64,
    /// The last path found, states in order.
    pub path: Option<Vec<Vec<f64>>>,
    /// The planners' random numbers, seeded per task so that plans repeat.
    pub rng: Rng,
}

impl Task {
    /// An empty task.
    pub fn new(name: &str, seed: u64) -> Self {
        Self {
            name: name.to_owned(),
            spaces: Vec::new(),
            algorithm: RRT_CONNECT,
            collision_pairs: Vec::new(),
            start: None,
            goals: Vec::new(),
            resolution: 0.01,
            path: None,
            rng: Rng::new(seed),
        }
    }

    /// Values a state has.
    pub fn dimension(&self) -> usize {
        self.spaces.iter().map(|s| s.kind.dimension()).sum()
    }

    /// Checks that `state` has the task's dimension and finite values.
    ///
    /// # Errors
    /// A state of the wrong length, or with a non-finite value.
    pub fn check_state(&self, state: &[f64]) -> Result<(), SimError> {
        if self.spaces.is_empty() {
            return Err(SimError::BadArgument(format!(
                "task '{}' has no state space yet (simOMPL.setStateSpace)",
                self.name
            )));
        }
        let n = self.dimension();
        if state.len() != n {
            return Err(SimError::BadArgument(format!(
                "task '{}': a state has {n} values, got {}",
                self.name,
                state.len()
            )));
        }
        if state.iter().any(|v| !v.is_finite()) {
            return Err(SimError::BadArgument(format!(
                "task '{}': state values must be finite",
                self.name
            )));
        }
        Ok(())
    }

    /// Whether `state` is valid in the scene (bounds, collision pairs); the scene is put
    /// back as it was.
    ///
    /// # Errors
    /// A bad state, or an object of the task that is gone.
    pub fn is_valid(&self, world: &mut World, state: &[f64]) -> Result<bool, SimError> {
        self.check_state(state)?;
        let mut scene = SceneProblem::new(self, world, Instant::now() + Duration::from_secs(1))?;
        let valid = scene.valid(state);
        scene.restore()?;
        Ok(valid)
    }

    /// Plans from the start to a goal for at most `max_time` seconds, then shortens the
    /// path for at most `simplify_time` seconds (a negative time: a default effort).
    /// Returns whether a path was found; it is kept in [`Task::path`].
    ///
    /// # Errors
    /// No start or goal, states of the wrong size, an invalid start or goals, or an
    /// object of the task that is gone.
    pub fn solve(&mut self, world: &mut World, max_time: f64, simplify_time: f64) -> Result<bool, SimError> {
        let start = self.start.clone().ok_or_else(|| {
            SimError::BadArgument(format!(
                "task '{}' has no start state (simOMPL.setStartState)",
                self.name
            ))
        })?;
        if self.goals.is_empty() {
            return Err(SimError::BadArgument(format!(
                "task '{}' has no goal state (simOMPL.setGoalState)",
                self.name
            )));
        }
        self.check_state(&start)?;
        for g in &self.goals {
            self.check_state(g)?;
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
        let mut rng = self.rng.clone();
        let mut scene = SceneProblem::new(self, world, deadline)?;
        let outcome = (|| {
            if !scene.valid(&start) {
                return Err(SimError::BadArgument(format!(
                    "task '{}': the start state is in collision or out of bounds",
                    self.name
                )));
            }
            let goals: Vec<Vec<f64>> = self.goals.iter().filter(|g| scene.valid(g)).cloned().collect();
            if goals.is_empty() {
                return Err(SimError::BadArgument(format!(
                    "task '{}': every goal state is in collision or out of bounds",
                    self.name
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
        self.rng = rng;
        let path = outcome?;
        let found = path.is_some();
        self.path = path;
        Ok(found)
    }

    /// The last path with `count` states spread evenly along it (by the task's
    /// distance), or as found when `count` is 0 or below the path's own count.
    pub fn interpolated(&self, count: usize) -> Option<Vec<Vec<f64>>> {
        let path = self.path.as_ref()?;
        if count <= path.len() || path.len() < 2 {
            return Some(path.clone());
        }
        let metric = Metric { spaces: &self.spaces };
        let lengths: Vec<f64> = path.windows(2).map(|w| metric.distance(&w[0], &w[1])).collect();
        let total: f64 = lengths.iter().sum();
        let mut out = Vec::with_capacity(count);
        let (mut seg, mut before) = (0, 0.0);
        for k in 0..count {
            let at = total * k as f64 / (count - 1) as f64;
            while seg + 1 < lengths.len() && before + lengths[seg] < at {
                before += lengths[seg];
                seg += 1;
            }
            let t = if lengths[seg] > 0.0 {
                ((at - before) / lengths[seg]).clamp(0.0, 1.0)
            } else {
                0.0
            };
            out.push(metric.interpolate(&path[seg], &path[seg + 1], t));
        }
        Some(out)
    }
}

/// The task's distance and interpolation over its spaces.
struct Metric<'a> {
    spaces: &'a [StateSpace],
}

impl Metric<'_> {
    fn parts<'s>(&self, s: &'s [f64]) -> impl Iterator<Item = (&StateSpace, &'s [f64])> {
        let mut at = 0;
        self.spaces.iter().map(move |sp| {
            let n = sp.kind.dimension();
            let part = &s[at..at + n];
            at += n;
            (sp, part)
        })
    }

    fn distance(&self, a: &[f64], b: &[f64]) -> f64 {
        self.parts(a)
            .zip(self.parts(b))
            .map(|((sp, x), (_, y))| sp.weight * sp.distance(x, y))
            .sum()
    }

    fn interpolate(&self, a: &[f64], b: &[f64], t: f64) -> Vec<f64> {
        let mut out = Vec::with_capacity(a.len());
        for ((sp, x), (_, y)) in self.parts(a).zip(self.parts(b)) {
            sp.interpolate(x, y, t, &mut out);
        }
        out
    }
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
            sp.read(world, &mut saved)?;
        }
        let mut pairs = Vec::new();
        for [a, b] in &task.collision_pairs {
            let first = world.entity_shapes(*a, &[])?;
            let second = world.entity_shapes(*b, &first)?;
            pairs.push((first, second));
        }
        let extent: f64 = task.spaces.iter().map(|s| s.weight * s.extent()).sum();
        Ok(Self {
            metric: Metric { spaces: &task.spaces },
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
            if sp.write(self.world, part).is_err() {
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
            sp.write(self.world, part)?;
        }
        self.world.refresh_queries();
        Ok(())
    }
}

impl Problem for SceneProblem<'_> {
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
