//! Messages between scripts: `sim.broadcastMsg(message, options=0)` and the receivers'
//! `sysCall_msg(message, origin)`, as CoppeliaSim 4.3+ documents them.
//!
//! A broadcast reaches every other script at once, before the call returns: each script
//! that is running, whose `sysCall_init` has returned and whose cleanup has not run, and
//! that defined `sysCall_msg` by then, in scene order. The sender is left out. Each
//! receiver gets its own copy of the message (CoppeliaSim serialises it between Lua
//! states; here the copy keeps one receiver's changes from reaching the next), and the
//! sender's script handle as `origin` (`nil` for a remote client, which gantry does not
//! serve). The message must therefore be plain data: tables, strings, numbers, booleans.
//!
//! A receiver runs under the sender's hook budget, like a function called with
//! `sim.callScriptFunction`, and cannot block (`sim.step`, `sim.wait`, ...: it is not a
//! thread, as in CoppeliaSim). An error in a receiver is the receiver's: it is logged and
//! the receiver marked errored once no script runs, and the broadcast goes on to the
//! others; the sender does not see it.

use std::rc::Rc;

use mlua::{Lua, MultiValue, Value as LuaValue};

use crate::convert::{to_lua, to_value};
use crate::simulation::{REMOVED_SCRIPT, Shared, error_text};

/// `sim.broadcastMsg(message, options=0)`: delivers `message` to the other scripts'
/// `sysCall_msg` (see the module documentation).
///
/// # Errors
/// A message that is not a table of plain data, or options that are not a number. The
/// receivers' own errors are not returned.
pub(crate) fn broadcast(lua: &Lua, shared: &Rc<Shared>, args: &MultiValue) -> Result<(), String> {
    let message = match args.front() {
        Some(t @ LuaValue::Table(_)) => to_value(t).map_err(|e| format!("argument 1: {e}"))?,
        other => {
            return Err(format!(
                "argument 1: expected the message, a table such as {{id = 'name', data = {{...}}}}, got {}",
                other.map_or("nothing", LuaValue::type_name)
            ));
        }
    };
    match args.get(1) {
        None | Some(LuaValue::Nil | LuaValue::Integer(_)) => {}
        Some(LuaValue::Number(n)) if n.fract() == 0.0 => {}
        Some(other) => {
            return Err(format!(
                "argument 2: expected options, an integer (keep 0), got {}",
                other.type_name()
            ));
        }
    }
    let sender = shared.current_script.get();
    let origin = shared.current.get();
    let receivers: Vec<usize> = shared
        .msg_hooks
        .borrow()
        .iter()
        .enumerate()
        .filter(|(i, f)| f.is_some() && Some(*i) != sender)
        .map(|(i, _)| i)
        .collect();
    for i in receivers {
        // Looked up again: an earlier receiver may have removed or broken this one.
        let Some(f) = shared.msg_hooks.borrow().get(i).cloned().flatten() else {
            continue;
        };
        let Some((object, name)) = shared
            .envs
            .borrow()
            .get(i)
            .filter(|(o, _, _)| *o != REMOVED_SCRIPT)
            .map(|(o, _, n)| (*o, n.clone()))
        else {
            continue;
        };
        let copy = to_lua(lua, &message).map_err(|e| e.to_string())?;
        let origin = origin.map_or(LuaValue::Nil, LuaValue::Integer);
        let previous = (
            shared.current.get(),
            shared.current_script.get(),
            shared.current_name.borrow().clone(),
        );
        shared.current.set(Some(object));
        shared.current_script.set(Some(i));
        *shared.current_name.borrow_mut() = name;
        // A receiver runs inside this call, where a coroutine cannot yield: a threaded
        // sender is not pre-empted until the delivery is over.
        let slice_end = shared.slice_end.take();
        let r = f.call::<()>((copy, origin));
        shared.slice_end.set(slice_end);
        shared.current.set(previous.0);
        shared.current_script.set(previous.1);
        *shared.current_name.borrow_mut() = previous.2;
        if let Err(e) = r {
            if let Some(slot) = shared.msg_hooks.borrow_mut().get_mut(i) {
                *slot = None;
            }
            // Said where it happened: the receiver's log shows no hook of its own failing.
            let e = mlua::Error::runtime(format!("in sysCall_msg: {}", error_text(&e)));
            shared.msg_failures.borrow_mut().push((i, e));
        }
    }
    Ok(())
}
