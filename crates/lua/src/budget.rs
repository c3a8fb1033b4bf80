//! The time budget: Lua's one global hook interrupts any code that runs past the
//! running hook's deadline (see [`crate::running`]), pre-empts a script thread whose
//! time slice is over (see [`crate::threads`]) and, with the debugger, sees every new
//! line (see [`crate::debugger`]).
//!
//! Once interrupted, a script stays interrupted until the hook call returns: `pcall`,
//! `xpcall` and `coroutine.resume` re-raise the interrupt, so a loop that catches errors
//! cannot defeat the budget.

use std::time::Instant;

use mlua::{Function, HookTriggers, Lua, Table, VmState};

use crate::app_state::state;
use crate::debugger::DebugHost;
use crate::running::Running;
use crate::threads::Threads;

/// Installs the hook and the `pcall` family that re-raises an interrupt. `debugging`:
/// the debugger's [`DebugHost`] is in the app data and wants line events.
pub(crate) fn install(lua: &Lua, debugging: bool) -> mlua::Result<()> {
    // A global hook: mlua gives it to every thread it creates, and Lua copies it into
    // the coroutines scripts create, so no coroutine escapes the budget.
    let triggers = if debugging {
        HookTriggers::new().every_nth_instruction(4096).every_line()
    } else {
        HookTriggers::new().every_nth_instruction(4096)
    };
    lua.set_global_hook(triggers, move |lua, debug| {
        if debug.event() == mlua::debug::DebugEvent::Line {
            return match lua.app_data_ref::<DebugHost>() {
                Some(d) => d.on_line(lua, debug),
                None => Ok(VmState::Continue),
            };
        }
        let now = Instant::now();
        let running = state::<Running>(lua);
        if running.interrupted.get() || now > running.deadline.get() {
            running.interrupted.set(true);
            let src = debug.source();
            let place = match (src.short_src.as_deref(), debug.current_line()) {
                (Some(file), Some(line)) => format!("{file}:{line}: "),
                _ => String::new(),
            };
            let msg = format!(
                "{place}script interrupted: it ran past its time budget of {:?} (an infinite loop in a hook?)",
                running.budget
            );
            // Errors raised by a hook carry no traceback of their own; add one so the
            // loop can be found like any other runtime error.
            let traceback = lua.traceback(Some(&msg), 0).map(|s| s.to_string_lossy()).unwrap_or(msg);
            Err(mlua::Error::runtime(traceback))
        } else if state::<Threads>(lua).preemption_due(lua, running.script.get(), now) {
            // Yields only the script's thread itself, and only at a point where Lua
            // can yield (mlua checks; where it cannot, the thread runs on and the
            // budget above still applies). It is resumed at the next step.
            Ok(VmState::Yield)
        } else {
            Ok(VmState::Continue)
        }
    })?;
    let interrupted = lua.create_function(move |lua, ()| Ok(state::<Running>(lua).interrupted.get()))?;
    lua.load(
        r#"
        local interrupted, rawpcall, rawxpcall, rawresume, error = ...
        local function check(...)
            if interrupted() then error("script interrupted: it ran past its time budget", 0) end
            return ...
        end
        pcall = function(...) return check(rawpcall(...)) end
        xpcall = function(...) return check(rawxpcall(...)) end
        coroutine.resume = function(...) return check(rawresume(...)) end
        "#,
    )
    .set_name("@gantry/budget.lua")
    .call::<()>((
        interrupted,
        lua.globals().get::<Function>("pcall")?,
        lua.globals().get::<Function>("xpcall")?,
        lua.globals().get::<Table>("coroutine")?.get::<Function>("resume")?,
        lua.globals().get::<Function>("error")?,
    ))
}
