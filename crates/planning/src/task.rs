//! A motion-planning task as `simOMPL` builds it: state spaces, collision pairs, start
//! and goal states, and the last path found. Planning it against the scene is the
//! world's part (`gantry_world::planning::solve`), which puts the scene in each state
//! it checks.

use gantry_scene::{Handle, SimError};

use crate::metric::Metric;
use crate::rng::Rng;
use crate::space::StateSpace;

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

    /// The task's distance and interpolation over its spaces.
    pub fn metric(&self) -> Metric<'_> {
        Metric { spaces: &self.spaces }
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

    /// The last path with `count` states spread evenly along it (by the task's
    /// distance), or as found when `count` is 0 or below the path's own count.
    pub fn interpolated(&self, count: usize) -> Option<Vec<Vec<f64>>> {
        let path = self.path.as_ref()?;
        if count <= path.len() || path.len() < 2 {
            return Some(path.clone());
        }
        let metric = self.metric();
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
