//! gantry's Lua host: per-object scripts with CoppeliaSim's hooks over the shared
//! `sim` API, and the step order that ties scripts to the world.

mod convert;
pub mod debugger;
mod limits;
pub mod listeners;
mod messages;
pub mod sandbox;
mod simulation;
mod threads;

pub use debugger::{DebugCommand, DebugEvent, DebugLink, DebugReply, DebugRequest};

pub use limits::ScriptLimits;
pub use listeners::{ListenerStatus, Listeners};
pub use simulation::{Hook, ScriptError, ScriptState, Simulation, StepBoundary, check_syntax};
