//! gantry's engine: the floor where the front ends meet the simulation.
//!
//! Six front ends reach a simulation: the text channel, the ZMQ and legacy remote
//! APIs, the viewer, the debugger (all through the server's simulation thread) and the
//! in-process Python client. Each turns what it receives into typed values at its edge
//! (a function name into an [`api::Target`](gantry_sim_core::api::Target), a loop
//! function and its arguments into a [`HostCall`]) and hands them to one [`Engine`],
//! which owns the rules of the loop: when a step may be taken ([`stepping`]: levels and
//! locks; [`pacing`]: real time), start, pause and stop with what follows for the
//! stepping clients, scene loading, and the stopped simulation's periodic hooks. A
//! [`Tap`] (the recorder) sees every input and step it carries out.
//!
//! The engine has no I/O: no socket, no channel to a transport, no thread of its own.
//! The server's simulation thread and the Python client each drive one in their own
//! way (a request queue and a sleeping loop; calls on the caller's thread), with the
//! same rules because there is one copy of them.

mod blocking;
mod engine;
mod host_call;
pub mod pacing;
pub mod stepping;
pub mod tap;

pub use blocking::BlockingReply;
pub use engine::{Due, Engine, EngineConfig, NON_SIMULATION_PERIOD, RELOAD_PERIOD};
pub use host_call::{HostCall, LoopControl, RemoteOp};
pub use stepping::{ClientId, Stepping, SteppingError};
pub use tap::{EngineInput, InputAt, MidStep, RecorderFactory, Tap};
