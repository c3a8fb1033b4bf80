//! The script debugger behind `gantry run --debug`: breakpoints, stepping and
//! inspection of the per-object Lua scripts, for any Debug Adapter Protocol client.
//!
//! Everything here runs on the simulation thread, inside the Lua host. A transport (the
//! server's DAP listener, the viewer) sends [`DebugCommand`]s through the channel of a
//! [`DebugLink`] and hears back [`DebugEvent`]s; it never touches Lua or the world.
//!
//! How a script stops: with `--debug`, the Lua state's one hook (which already enforces
//! the time budget every 4096 instructions) also fires on every new line. While no
//! breakpoint is set and no step is pending, a line event returns after one flag test
//! (the cost is measured in `tools/bench.sh`). When a line holds a breakpoint, or a step
//! is due, the hook does not return: it serves the transport's requests (stack, scopes,
//! variables, evaluate) right there, with the script's stack intact, until continue or
//! a step. Since that hook runs on the simulation thread, the **whole simulation** is
//! stopped meanwhile: no physics, no other script, no time; transports' requests queue.
//! An error a script does not catch stops it the same way, from the message handler of
//! the protected call that runs each hook (the stack is still there at that moment).
//!
//! In DAP terms there is one thread, the simulation: every script stops with it, and
//! which script and hook stopped shows in the stack frames.

mod inspect;
mod link;
mod protected_call;
mod state;

pub use link::{
    BreakpointSpec, BreakpointStatus, DebugCommand, DebugEvent, DebugLink, DebugReply, DebugRequest, DebuggerError,
    FrameInfo, ScopeInfo, StopReason, VariableInfo,
};
pub(crate) use protected_call::install as install_protected_call;
pub(crate) use state::DebugHost;
