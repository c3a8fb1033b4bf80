//! gantry's simulated world: the object tree on rapier (`world`), the subsystems that
//! read and drive it (`sensor`, `vision`, `ik`, `drawing`, `graph`, `motion`,
//! `planning`) and [`Sim`], which owns them all and steps them in CoppeliaSim's order.
//!
//! The world and the sensors share one crate with [`Sim`] because they share the
//! world's private parts: which collider belongs to which object, where a sensor's
//! detection is stored, and the two phases of a step that only [`Sim::step`] may
//! assemble. What of a subsystem needs no world is a crate below this one, which
//! [`Sim`] can own: simUI's widget model (`gantry-ui`, re-exported whole as [`ui`]),
//! the planner with its spaces and tasks (`gantry-planning`) and the IK environments
//! with their solver (`gantry-ik`). The `planning` and `ik` modules here re-export
//! those crates and add what reads the scene; `vision` stays whole, because
//! [`vision::VisionStates`], which [`Sim`] owns, holds the renderer's caches that are
//! refreshed from the world. Above this crate, `gantry-sim-core` holds the `sim.*`
//! registry and re-exports these modules (docs/architecture.md, "Crates").
//!
//! The modules are floors; each imports only from the floors below it:
//! `gantry-scene`, `gantry-ui`, `gantry-planning`, `gantry-ik` → `world` → subsystems →
//! [`Sim`].
//!
//! Units are SI and angles radians throughout; poses are in the world frame unless a
//! function says otherwise.

pub use gantry_protocol::Value;
// The floors below, under the names the modules here use (`crate::scene::...`).
pub use gantry_scene::{error, handle, scene};
// simUI's model, a crate of its own with nothing of the world to add, under its old
// name here (`ik` and `planning` re-export theirs inside their modules).
pub use gantry_ui as ui;

// Leaves of this crate.
pub mod math;
pub mod mesh_cluster;
pub mod paths;
pub mod signals;
pub mod tubes;
// Objects and physics.
pub mod world;
// Subsystems on the world.
pub mod drawing;
pub mod graph;
pub mod ik;
pub mod motion;
pub mod planning;
pub mod sensor;
pub mod vision;
// The scene's IK groups, on the IK subsystem.
pub mod ik_groups;
// The aggregate and its step.
pub mod sim;

pub use error::SimError;
pub use handle::Handle;
pub use sim::Sim;
pub use world::World;
