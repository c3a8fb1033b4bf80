//! gantry's simulation core: the one implementation of each `sim.*` function over
//! [`Value`] (`api`), on top of the scene model (`gantry-scene`) and the world with its
//! subsystems (`gantry-world`), which it re-exports. Lua scripts and remote clients
//! both call that same code; nothing is written twice.
//!
//! The modules are floors; each imports only from the floors below it (see
//! [`sim`] for the picture, and docs/architecture.md):
//! leaves (`handle`, `math`, `error`, `signals`) → `scene` → `world` → subsystems
//! (`sensor`, `vision`, `ik`, `drawing`, `graph`, `ui`, `motion`, `planning`) → [`Sim`]
//! → `api`. The first two are the crate `gantry-scene`, the next three `gantry-world`,
//! except the parts of subsystems that need no world, crates below it that `Sim` owns:
//! `ui` is the crate `gantry-ui`, and `ik` and `planning` re-export `gantry-ik` and
//! `gantry-planning` beside what reads the scene. Cargo enforces the direction between
//! crates and `tools/layers.py` within them.
//!
//! Units are SI and angles radians throughout the API; poses are in the world frame
//! unless a function says otherwise.

pub use gantry_protocol::Value;
/// The physics engine, for benchmarks and tools that compare against bare rapier.
pub use rapier3d;

// Floors 1 and 2: leaves and the scene model (crate gantry-scene).
pub use gantry_scene::{error, handle, scene};
// Floors 3 to 5: objects and physics, the subsystems, the aggregate (crate gantry-world).
pub use gantry_world::{
    drawing, graph, ik, ik_groups, math, motion, paths, planning, sensor, signals, sim, tubes, ui, vision, world,
};
// Floor 6: the `sim.*` registry.
pub mod api;

pub use error::SimError;
pub use handle::Handle;
pub use sim::Sim;
pub use world::World;
