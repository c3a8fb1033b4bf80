//! gantry's scene model: what a scene file says, before any physics exists. It holds
//! the loaders (TOML scenes, URDF robots, CoppeliaSim `.ttt`/`.ttm` files through
//! `gantry-coppelia-file`) and the small types every floor above shares: object
//! handles, poses and the world's error.
//!
//! It is the lowest floor of the simulation (docs/architecture.md, "Crates"): the world
//! (`gantry-world`) inserts a [`scene::SceneModel`] into rapier, and `gantry-sim-core`
//! re-exports these modules, so users name them `gantry_sim_core::scene` as before.
//!
//! Units are SI and angles radians; poses are in the parent's frame unless a type says
//! otherwise.

// Leaves.
pub mod error;
pub mod handle;
pub mod math;
// The scene model and its loaders.
pub mod scene;

pub use error::SimError;
pub use handle::Handle;
