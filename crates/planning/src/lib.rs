//! Motion planning as CoppeliaSim's `simOMPL` plugin offers it: state spaces over the
//! scene's objects and joints, tasks with collision pairs, start and goal states, and a
//! sampling-based planner ([`rrt_connect`]) over any [`rrt_connect::Problem`].
//!
//! It sits below the world (`gantry-world`), whose `Sim` owns the [`Planning`] store,
//! and knows no physics: checking states against the scene's collision geometry, and
//! reading and writing the scene's configuration, are the world's part
//! (`gantry_world::planning`, which re-exports this crate, as `gantry_sim_core::planning`
//! does).
//!
//! gantry writes its planner rather than binding OMPL (a C++ library) or the `rrt`
//! crate (openrr's): the crate's path smoothing draws from the thread's random
//! generator, so plans would differ between runs, and it knows only the Euclidean
//! metric, not rotations or cyclic joints. The planner here is RRT-Connect, seeded per
//! task, with shortcut simplification; docs/api-notes.md lists what `simOMPL` serves.

mod metric;
mod rng;
pub mod rrt_connect;
mod space;
mod task;

pub use metric::Metric;
pub use rng::Rng;
pub use space::{SpaceKind, StateSpace};
pub use task::{ALGORITHMS, RRT_CONNECT, Task};

use gantry_scene::{Handle, SimError};

/// The first handle of a state space (beyond object handles, as CoppeliaSim's plugin
/// keeps its own handles).
const FIRST_SPACE: Handle = 3_000_000;
/// The first handle of a task.
const FIRST_TASK: Handle = 3_500_000;

/// The state spaces and tasks scripts created, gone with the simulation at stop.
#[derive(Debug, Clone, Default)]
pub struct Planning {
    spaces: Vec<Option<StateSpace>>,
    tasks: Vec<Option<Task>>,
}

impl Planning {
    /// Keeps a state space; returns its handle.
    pub fn add_space(&mut self, space: StateSpace) -> Handle {
        self.spaces.push(Some(space));
        FIRST_SPACE + self.spaces.len() as Handle - 1
    }

    /// The state space `h`.
    ///
    /// # Errors
    /// No such state space.
    pub fn space(&self, h: Handle) -> Result<&StateSpace, SimError> {
        slot(&self.spaces, h, FIRST_SPACE)
            .and_then(Option::as_ref)
            .ok_or_else(|| SimError::NoSuchItem(format!("state space {h} does not exist")))
    }

    /// Forgets state space `h` (tasks keep their copy).
    ///
    /// # Errors
    /// No such state space.
    pub fn remove_space(&mut self, h: Handle) -> Result<(), SimError> {
        self.space(h)?;
        self.spaces[(h - FIRST_SPACE) as usize] = None;
        Ok(())
    }

    /// Keeps a new task; returns its handle.
    pub fn add_task(&mut self, name: &str) -> Handle {
        // Seeded by its index, so a script's tasks plan the same in every run.
        let task = Task::new(name, self.tasks.len() as u64 + 1);
        self.tasks.push(Some(task));
        FIRST_TASK + self.tasks.len() as Handle - 1
    }

    /// The task `h`.
    ///
    /// # Errors
    /// No such task.
    pub fn task(&self, h: Handle) -> Result<&Task, SimError> {
        slot(&self.tasks, h, FIRST_TASK)
            .and_then(Option::as_ref)
            .ok_or_else(|| SimError::NoSuchItem(format!("task {h} does not exist")))
    }

    /// The task `h`, to change.
    ///
    /// # Errors
    /// No such task.
    pub fn task_mut(&mut self, h: Handle) -> Result<&mut Task, SimError> {
        self.task(h)?;
        self.tasks[(h - FIRST_TASK) as usize]
            .as_mut()
            .ok_or_else(|| SimError::NoSuchItem(format!("task {h} does not exist")))
    }

    /// Removes task `h`.
    ///
    /// # Errors
    /// No such task.
    pub fn remove_task(&mut self, h: Handle) -> Result<(), SimError> {
        self.task(h)?;
        self.tasks[(h - FIRST_TASK) as usize] = None;
        Ok(())
    }
}

fn slot<T>(items: &[T], h: Handle, first: Handle) -> Option<&T> {
    usize::try_from(h.checked_sub(first)?).ok().and_then(|i| items.get(i))
}
