//! gantry's Lua host: per-object scripts with CoppeliaSim's hooks over the shared
//! `sim` API, and the step order that ties scripts to the world.
//!
//! Files by role, lowest floor first (docs/architecture.md draws them; tools/layers.py
//! checks that imports point down and never circle): errors and conversions; the state
//! each role owns (`running`, `directory`, `threads`, `messages`, `control`, `models`,
//! kept in the Lua state's app data, and the LuaSocket subset's sockets); the debugger; the budget hook and the `sim.*`
//! functions (`host_api`); hooks and scripts; the simulation's life, its step and its
//! remote calls.

mod app_state;
mod budget;
mod control;
mod convert;
mod core_cell;
pub mod debugger;
mod directory;
mod hooks;
mod host_api;
mod launch;
mod limits;
pub mod listeners;
mod lua_error;
mod luasocket;
mod messages;
mod models;
mod recording;
mod remote;
mod remote_blocking;
pub mod ros;
mod ros_action_dispatch;
mod ros_dispatch;
mod running;
pub mod sandbox;
mod scripts;
mod simulation;
mod step;
mod threads;

pub use debugger::{DebugCommand, DebugEvent, DebugLink, DebugReply, DebugRequest, DebuggerError};

pub use hooks::Hook;
pub use limits::{NetworkParams, ScriptLimits};
pub use listeners::{ListenerError, ListenerStatus, Listeners};
pub use lua_error::ScriptError;
pub use luasocket::uses_luasocket;
pub use models::ModelLoadError;
pub use recording::RecordingRequest;
pub use remote::HookError;
pub use remote_blocking::{Blocking, BlockingId};
pub use scripts::ScriptState;
pub use simulation::{Simulation, check_syntax};
pub use step::StepBoundary;
