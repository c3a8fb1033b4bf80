//! gantry's engine: the one owner of a simulation, and the floor where every front end
//! meets it.
//!
//! An [`Engine`] owns the simulation (`Sim`: the world and its subsystems), the scene
//! model a stop rebuilds it from, and the Lua host that runs the scene's scripts. Seven
//! front ends reach it: the text channel, the ZMQ and legacy remote APIs, the viewer,
//! the debugger, ROS 2 (all through the server's simulation thread) and the in-process
//! Python client. Each turns what it receives into typed values at its edge (a function
//! name into an [`api::Target`](gantry_sim_core::api::Target), a loop function and its
//! arguments into a [`HostCall`]) and hands the engine one [`Input`] through
//! [`Engine::serve`], which answers with an [`Output`]. The engine owns the rules of the
//! loop: CoppeliaSim's step order with the scripts' hooks between its phases (`step`),
//! start, pause and stop (`lifecycle`), when a step may be taken ([`stepping`]: levels
//! and locks; [`pacing`]: real time), scene loading, and the stopped simulation's
//! periodic hooks. [`Observer`]s (the recorder, the ROS 2 graph, the viewer's frames)
//! see its inputs and steps.
//!
//! The engine has no I/O: no socket, no channel to a transport, no thread of its own.
//! The server's simulation thread and the Python client each drive one in their own
//! way (a request queue and a sleeping loop; calls on the caller's thread), with the
//! same rules because there is one copy of them.

mod blocking;
mod engine;
mod history;
mod host_call;
mod input;
mod lifecycle;
pub mod observer;
pub mod pacing;
mod scene;
mod scene_copy;
mod step;
pub mod stepping;

pub use blocking::BlockingReply;
pub use engine::{Due, Engine, EngineConfig, NON_SIMULATION_PERIOD, RELOAD_PERIOD, WhileWaiting};
pub use gantry_lua::StepBoundary;
pub use history::HISTORY_STEPS;
pub use host_call::{HostCall, LoopControl, RemoteOp};
pub use input::{Input, Output};
pub use observer::{InputAt, Observer, RecorderFactory, RecordingRefused};
pub use step::MidStep;
pub use stepping::{ClientId, Stepping, SteppingError};
