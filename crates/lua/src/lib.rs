//! gantry's Lua host: per-object scripts with CoppeliaSim's hooks over the shared
//! `sim` API, driven by the engine, which owns the simulation and calls the hooks in
//! CoppeliaSim's order. What is Lua lives here: the bindings of the registry, the
//! sandbox, script threads, the debugger, LuaSocket, and the simROS/simROS2 bindings.
//!
//! Files by role, lowest floor first (docs/architecture.md draws them; tools/layers.py
//! checks that imports point down and never circle): errors and conversions; the state
//! each role owns (`running`, `directory`, `threads`, `messages`, `control`, `models`,
//! kept in the Lua state's app data, and the LuaSocket subset's sockets); the debugger; the budget hook and the `sim.*`
//! functions (`host_api`); hooks and scripts; the host ([`LuaHost`]), its part of a
//! step and its remote calls.

mod app_state;
mod budget;
mod control;
mod convert;
pub mod debugger;
mod directory;
mod file_rules;
mod hooks;
mod host;
mod host_api;
mod host_step;
mod launch;
mod limits;
pub mod listeners;
mod lua_error;
mod luasocket;
mod messages;
mod models;
mod modules;
mod recording;
mod remote;
mod remote_blocking;
pub mod ros;
mod ros_action_dispatch;
mod ros_dispatch;
mod running;
pub mod sandbox;
mod script_io;
mod scripts;
mod sim_cell;
mod threads;
mod waiting;

pub use debugger::{DebugCommand, DebugEvent, DebugLink, DebugReply, DebugRequest, DebuggerError};

pub use hooks::Hook;
pub use host::{LuaHost, ScriptRequests, check_syntax};
pub use host_step::StepBoundary;
pub use limits::{NetworkParams, ScriptLimits};
pub use listeners::{ListenerError, ListenerStatus, Listeners};
pub use lua_error::ScriptError;
pub use luasocket::uses_luasocket;
pub use models::LoadedModel;
pub use models::ModelLoadError;
pub use recording::RecordingRequest;
pub use remote::HookError;
pub use remote_blocking::{Blocking, BlockingId};
pub use scripts::ScriptState;
pub use sim_cell::SimCell;
pub use waiting::WaitService;
