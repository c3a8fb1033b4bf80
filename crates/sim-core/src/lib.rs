//! gantry's simulation core: the scene model and loader, the rapier world, the object
//! tree with names and handles, sensors, kinematics, and the one implementation of each
//! `sim.*` function over [`Value`]. Lua scripts and remote clients both call that same
//! code; nothing is written twice.
//!
//! The modules are floors; each imports only from the floors below it (see
//! [`sim`] for the picture, and docs/architecture.md):
//! leaves (`handle`, `math`, `error`, `signals`) → `scene` → `world` → subsystems
//! (`sensor`, `vision`, `ik`, `drawing`, `graph`, `ui`, `motion`) → [`Sim`] → `api`.
//!
//! Units are SI and angles radians throughout the API; poses are in the world frame
//! unless a function says otherwise.

pub use gantry_protocol::Value;
/// The physics engine, for benchmarks and tools that compare against bare rapier.
pub use rapier3d;

// Floor 1: leaves.
pub mod error;
pub mod handle;
pub mod math;
pub mod signals;
// Floor 2: the scene model.
pub mod scene;
// Floor 3: objects and physics.
pub mod world;
// Floor 4: subsystems on the world.
pub mod drawing;
pub mod graph;
pub mod ik;
pub mod motion;
pub mod sensor;
pub mod ui;
pub mod vision;
// Floor 5: the aggregate and its step.
pub mod sim;
// Floor 6: the `sim.*` registry.
pub mod api;

pub use error::SimError;
pub use handle::Handle;
pub use sim::Sim;
pub use world::World;
