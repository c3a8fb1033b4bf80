//! gantry's simulation core: the scene model and loader, the rapier world, the object
//! tree with names and handles, sensors, kinematics, and the one implementation of each
//! `sim.*` function over [`Value`]. Lua scripts and remote clients both call that same
//! code; nothing is written twice.
//!
//! Units are SI and angles radians throughout the API; poses are in the world frame
//! unless a function says otherwise.

pub mod math;
pub mod scene;

pub use gantry_protocol::Value;
/// The physics engine, for benchmarks and tools that compare against bare rapier.
pub use rapier3d;
pub mod api;
pub mod error;
pub mod ik;
pub mod sensor;
pub mod ui;
pub mod vision;
pub mod world;

pub use error::SimError;
pub use world::{Handle, World};
