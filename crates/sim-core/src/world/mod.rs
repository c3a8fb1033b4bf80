//! The simulated world: the object tree (handles, aliases, parents, f64 poses), its
//! rapier counterpart, and CoppeliaSim's path lookup.

mod object;
pub mod object_path;
mod physics;
#[expect(clippy::module_inception, reason = "the World type's file is named after it, like rapier's rigid_body/rigid_body.rs")]
mod world;

pub use object::{Detection, ForceReading, Handle, Joint, Object, ObjectKind, ProximitySensor};
pub use world::World;
pub(crate) use physics::Physics;
