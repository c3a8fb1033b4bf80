//! Blocking calls of remote clients: `sim.wait`, `sim.waitForSignal`,
//! `sim.moveToConfig` and `sim.moveToPose` called over ZMQ or from in-process Python,
//! as CoppeliaSim's examples do (`sim.moveToPose(params)` with the simulation stepping).
//!
//! Each call runs the same Lua function a threaded script calls, in a coroutine of its
//! own: where it would block (`sim.step()` inside), it yields, and the engine resumes
//! it after each step until it returns; the client gets its answer then. The engine
//! decides when to resume (after a step, never mid-step) and takes the steps a
//! stepping client's call needs; this file only runs the coroutines.
//!
//! Not served: Python callables as arguments (the 4.0-4.5 forms' callbacks). The
//! argument arrives as a string and the Lua function refuses it, naming the argument.

use gantry_sim_core::api::{CallError, ScriptHostFn};
use gantry_sim_core::{SimError, Value};
use mlua::thread::ThreadStatus;
use mlua::{Function, MultiValue, Table, Thread};

use crate::app_state::state;
use crate::convert::{to_multi, to_value};
use crate::host::LuaHost;
use crate::lua_error::error_text;
use crate::running::Running;
pub use crate::threads::BlockingId;

/// What starting or resuming a blocking call gave.
#[derive(Debug, PartialEq)]
pub enum Blocking {
    /// It returned (or failed): the client's answer.
    Done(Result<Vec<Value>, CallError>),
    /// It waits for a later step.
    Waiting,
}

impl LuaHost {
    /// Starts blocking call `id` of `f` with `args` and runs it up to its first wait.
    pub fn start_blocking(&mut self, id: BlockingId, f: ScriptHostFn, args: &[Value]) -> Blocking {
        let qualified = format!("sim.{}", f.name());
        let thread = (|| {
            let sim: Table = self.lua.globals().get("sim")?;
            let func: Function = sim.get(f.name())?;
            self.lua.create_thread(func)
        })();
        let thread = match thread {
            Ok(t) => t,
            Err(e) => return Blocking::Done(Err(CallError::failed(qualified, SimError::refused(e.to_string())))),
        };
        let lua_args = match to_multi(&self.lua, args) {
            Ok(a) => a,
            Err(e) => return Blocking::Done(Err(CallError::failed(qualified, SimError::bad_argument(e.to_string())))),
        };
        let out = self.resume_thread(f, &thread, lua_args);
        if out == Blocking::Waiting {
            self.blocking.running.push((id, f, thread));
        }
        out
    }

    /// Resumes every blocking call in progress once (the engine calls this after a
    /// step); returns the ones that ended, with their answers.
    pub fn resume_blocking(&mut self) -> Vec<(BlockingId, Result<Vec<Value>, CallError>)> {
        let calls = std::mem::take(&mut self.blocking.running);
        let mut ended = Vec::new();
        for (id, f, thread) in calls {
            match self.resume_thread(f, &thread, MultiValue::new()) {
                Blocking::Waiting => self.blocking.running.push((id, f, thread)),
                Blocking::Done(answer) => ended.push((id, answer)),
            }
        }
        ended
    }

    /// Drops every blocking call in progress (the simulation stopped, or the scene
    /// changed); returns their ids, to be answered with the reason.
    pub fn abort_blocking(&mut self) -> Vec<BlockingId> {
        self.blocking.running.drain(..).map(|(id, _, _)| id).collect()
    }

    /// Drops blocking call `id` (its client left).
    pub fn cancel_blocking(&mut self, id: BlockingId) {
        self.blocking.running.retain(|(i, _, _)| *i != id);
    }

    /// Whether any blocking call is in progress.
    pub fn has_blocking(&self) -> bool {
        !self.blocking.running.is_empty()
    }

    fn resume_thread(&mut self, f: ScriptHostFn, thread: &Thread, args: MultiValue) -> Blocking {
        // As for `sim.callScriptFunction`: Lua code run for a client gets a hook's time
        // budget, so that a runaway loop cannot hold the simulation thread.
        state::<Running>(&self.lua).restart_budget();
        let r = thread.resume::<MultiValue>(args);
        self.scripts.leave();
        let qualified = format!("sim.{}", f.name());
        match r {
            Err(e) => {
                // The Lua functions name themselves; keep one "(in function ...)".
                let text = error_text(&e);
                let suffix = format!(" (in function '{qualified}')");
                let text = text.split("\nstack traceback").next().unwrap_or(&text);
                let text = text.strip_suffix(suffix.as_str()).unwrap_or(text).to_owned();
                Blocking::Done(Err(CallError::failed(qualified, SimError::refused(text))))
            }
            Ok(_) if thread.status() == ThreadStatus::Resumable => Blocking::Waiting,
            Ok(values) => Blocking::Done(
                values
                    .iter()
                    .map(to_value)
                    .collect::<mlua::Result<Vec<_>>>()
                    .map_err(|e| CallError::failed(qualified, SimError::refused(e.to_string()))),
            ),
        }
    }
}
