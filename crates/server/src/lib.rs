//! gantry's transports: the simulation thread and the network listeners that talk to it.
//!
//! One thread owns the world and Lua ([`sim_thread`]); transports send it requests over
//! a bounded channel and await replies. There is no shared mutable world.

pub mod auth;
pub mod dap;
pub mod debug;
pub mod http;
pub mod legacy;
pub mod legacy_commands;
pub mod replay;
pub mod runner;
pub mod sim_thread;
pub mod text;
pub mod zmq;
pub mod zmtp_conn;
pub mod zmtp_reply;

pub use auth::{AccessToken, TokenError};
pub use debug::{DebugHub, PausedAt};
pub use gantry_engine::{ClientId, HostCall, Observer, stepping};
pub use runner::{BoundAddrs, Running, ServeConfig, ServerError, Shutdown, Signals, run, start};
pub use sim_thread::{
    LoopControl, PacketOutcome, QUEUE_CAPACITY, RemoteOp, Request, RunSummary, SendError, SimConfig, SimHandle,
    SimView, channel, run_sim_thread, run_sim_thread_debugged, run_sim_thread_observed,
};
pub use text::TextConfig;
pub use zmq::ZmqConfig;
