//! The hooks scripts define, the order gantry calls them in (CoppeliaSim's: children's
//! scripts before their parents'), and how the host calls into a script: directly, or
//! with the debugger through the protected call that stops at an uncaught error.

use gantry_sim_core::world::object_path::ObjectTree;
use gantry_sim_core::{Handle, World};
use mlua::{Function, Lua, Value as LuaValue};

/// The hooks a script may define.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Hook {
    /// `sysCall_init`.
    Init,
    /// `sysCall_actuation`.
    Actuation,
    /// `sysCall_sensing`.
    Sensing,
    /// `sysCall_cleanup`.
    Cleanup,
    /// `sysCall_beforeSimulation`: when a stopped simulation starts, before any
    /// `sysCall_init`.
    BeforeSimulation,
    /// `sysCall_afterSimulation`: when the simulation has ended, after every cleanup.
    AfterSimulation,
    /// `sysCall_suspend`: when the simulation pauses.
    Suspend,
    /// `sysCall_resume`: when a paused simulation resumes.
    Resume,
    /// `sysCall_nonSimulation`: regularly while the simulation is stopped.
    NonSimulation,
}

impl Hook {
    /// The global function name a script defines.
    pub(crate) fn name(self) -> &'static str {
        match self {
            Hook::Init => "sysCall_init",
            Hook::Actuation => "sysCall_actuation",
            Hook::Sensing => "sysCall_sensing",
            Hook::Cleanup => "sysCall_cleanup",
            Hook::BeforeSimulation => "sysCall_beforeSimulation",
            Hook::AfterSimulation => "sysCall_afterSimulation",
            Hook::Suspend => "sysCall_suspend",
            Hook::Resume => "sysCall_resume",
            Hook::NonSimulation => "sysCall_nonSimulation",
        }
    }
}

/// Every `sysCall_*` function gantry calls. A script defining another gets one
/// warning at load, naming it, instead of silently never being called.
pub const SUPPORTED_HOOKS: &[&str] = &[
    "sysCall_actuation",
    "sysCall_afterSimulation",
    "sysCall_beforeSimulation",
    "sysCall_cleanup",
    "sysCall_init",
    "sysCall_msg",
    "sysCall_nonSimulation",
    "sysCall_packet",
    "sysCall_resume",
    "sysCall_sensing",
    "sysCall_suspend",
    "sysCall_thread",
    "sysCall_threadmain",
    "sysCall_vision",
];

/// Script indices in hook order, for scripts attached to `objects` (by index): children's
/// scripts before their parents' (post-order over the tree), siblings in hierarchy
/// order; several scripts on one object keep their scene order.
pub(crate) fn hook_order(world: &World, objects: &[Handle]) -> Vec<usize> {
    let mut post = Vec::new();
    let mut stack: Vec<(Handle, bool)> = world.roots().iter().rev().map(|&h| (h, false)).collect();
    while let Some((h, visited)) = stack.pop() {
        if visited {
            post.push(h);
        } else {
            stack.push((h, true));
            stack.extend(world.children(h).iter().rev().map(|&c| (c, false)));
        }
    }
    let mut order = Vec::new();
    for h in post {
        order.extend(objects.iter().enumerate().filter(|(_, o)| **o == h).map(|(i, _)| i));
    }
    order
}

/// Calls script functions for the host.
pub(crate) struct HookCaller {
    lua: Lua,
    /// With the debugger: calls a script function in a protected call whose message
    /// handler stops at an uncaught error (see `debugger::install_protected_call`).
    debug_call: Option<Function>,
}

impl HookCaller {
    /// Calls through `debug_call` when there is one.
    pub(crate) fn new(lua: Lua, debug_call: Option<Function>) -> Self {
        Self { lua, debug_call }
    }

    /// Calls a script function: directly, or with the debugger through the protected
    /// call that stops at an uncaught error.
    pub(crate) fn call<R: mlua::FromLuaMulti>(&self, f: &Function, args: impl mlua::IntoLuaMulti) -> mlua::Result<R> {
        match &self.debug_call {
            None => f.call(args),
            Some(dc) => {
                let mut all = args.into_lua_multi(&self.lua)?;
                all.push_front(LuaValue::Function(f.clone()));
                dc.call(all)
            }
        }
    }

    /// The body a script thread's coroutine runs: with the debugger, inside the
    /// protected call (Lua 5.4 lets a coroutine yield across it).
    pub(crate) fn thread_body(&self, body: Function) -> mlua::Result<Function> {
        match &self.debug_call {
            Some(dc) => dc.bind(body),
            None => Ok(body),
        }
    }
}
