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

use std::cell::RefCell;

use mlua::{Function, Lua, MultiValue, Table, Value as LuaValue};

use crate::app_state::state;
use crate::convert::{to_lua, to_value};
use crate::directory::{Directory, REMOVED_SCRIPT};
use crate::lua_error::error_text;
use crate::running::{Caller, Running};
use crate::threads::Threads;

/// Who receives messages, and whose receiver failed.
#[derive(Default)]
pub(crate) struct Mailboxes {
    /// Each script's `sysCall_msg`, by script index, while it may receive messages
    /// (initialised, running, not cleaned up).
    receivers: RefCell<Vec<Option<Function>>>,
    /// Scripts whose `sysCall_msg` raised an error, to be marked errored once no
    /// script runs (the sender is still running when the receiver fails).
    failures: RefCell<Vec<(usize, mlua::Error)>>,
}

impl Mailboxes {
    /// Forgets every receiver and failure (the scene's scripts load again).
    pub(crate) fn clear(&self) {
        self.receivers.borrow_mut().clear();
        self.failures.borrow_mut().clear();
    }

    /// One more script, receiving nothing yet.
    pub(crate) fn push(&self) {
        self.receivers.borrow_mut().push(None);
    }

    /// Sets (or, with `None`, withdraws) script `i`'s receiver.
    pub(crate) fn set_receiver(&self, i: usize, f: Option<Function>) {
        if let Some(slot) = self.receivers.borrow_mut().get_mut(i) {
            *slot = f;
        }
    }

    /// The receivers' failures since the last call.
    pub(crate) fn take_failures(&self) -> Vec<(usize, mlua::Error)> {
        std::mem::take(&mut *self.failures.borrow_mut())
    }
}

/// Installs `sim.broadcastMsg` into `sim`, its failures raised through `wrap` (see
/// [`crate::host_api`]).
pub(crate) fn install(lua: &Lua, sim: &Table, wrap: &Function) -> mlua::Result<()> {
    sim.set(
        "broadcastMsg",
        lua.create_function(move |lua, args: MultiValue| {
            Ok(match broadcast(lua, &args) {
                Ok(()) => (true, LuaValue::Nil),
                Err(e) => (
                    false,
                    LuaValue::String(lua.create_string(format!("{e} (in function 'sim.broadcastMsg')"))?),
                ),
            })
        })
        .and_then(|f| wrap.call::<Function>(f))?,
    )
}

/// Why `sim.broadcastMsg` refused a message; the API wrapper adds the function's name.
#[derive(Debug, thiserror::Error)]
enum BroadcastError {
    /// The message table holds something that is not plain data (a function, a cycle).
    #[error("argument 1: {0}")]
    NotPlainData(mlua::Error),
    /// The message is not a table (the Lua type found).
    #[error("argument 1: expected the message, a table such as {{id = 'name', data = {{...}}}}, got {0}")]
    NotAMessage(&'static str),
    /// The options are not an integer (the Lua type found).
    #[error("argument 2: expected options, an integer (keep 0), got {0}")]
    BadOptions(&'static str),
    /// The message could not be copied into a receiver's Lua values.
    #[error("{0}")]
    Copy(mlua::Error),
}

/// `sim.broadcastMsg(message, options=0)`: delivers `message` to the other scripts'
/// `sysCall_msg` (see the module documentation).
///
/// # Errors
/// A message that is not a table of plain data, or options that are not a number. The
/// receivers' own errors are not returned.
fn broadcast(lua: &Lua, args: &MultiValue) -> Result<(), BroadcastError> {
    let message = match args.front() {
        Some(t @ LuaValue::Table(_)) => to_value(t).map_err(BroadcastError::NotPlainData)?,
        other => {
            return Err(BroadcastError::NotAMessage(
                other.map_or("nothing", LuaValue::type_name),
            ));
        }
    };
    match args.get(1) {
        None | Some(LuaValue::Nil | LuaValue::Integer(_)) => {}
        Some(LuaValue::Number(n)) if n.fract() == 0.0 => {}
        Some(other) => return Err(BroadcastError::BadOptions(other.type_name())),
    }
    let running = state::<Running>(lua);
    let mailboxes = state::<Mailboxes>(lua);
    let directory = state::<Directory>(lua);
    let threads = state::<Threads>(lua);
    let sender = running.script.get();
    let origin = running.object.get();
    let receivers: Vec<usize> = mailboxes
        .receivers
        .borrow()
        .iter()
        .enumerate()
        .filter(|(i, f)| f.is_some() && Some(*i) != sender)
        .map(|(i, _)| i)
        .collect();
    for i in receivers {
        // Looked up again: an earlier receiver may have removed or broken this one.
        let Some(f) = mailboxes.receivers.borrow().get(i).cloned().flatten() else {
            continue;
        };
        let Some(receiver) = directory.entry(i).filter(|e| e.object != REMOVED_SCRIPT) else {
            continue;
        };
        let copy = to_lua(lua, &message).map_err(BroadcastError::Copy)?;
        let origin = origin.map_or(LuaValue::Nil, LuaValue::Integer);
        let previous = running.act_as(Caller {
            object: Some(receiver.object),
            script: Some(i),
            name: receiver.name,
        });
        // A receiver runs inside this call, where a coroutine cannot yield: a threaded
        // sender is not pre-empted until the delivery is over.
        let slice_end = threads.take_slice_end();
        let r = f.call::<()>((copy, origin));
        threads.set_slice_end(slice_end);
        running.act_as(previous);
        if let Err(e) = r {
            mailboxes.set_receiver(i, None);
            // Said where it happened: the receiver's log shows no hook of its own failing.
            let e = mlua::Error::runtime(format!("in sysCall_msg: {}", error_text(&e)));
            mailboxes.failures.borrow_mut().push((i, e));
        }
    }
    Ok(())
}
