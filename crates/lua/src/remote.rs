//! What clients outside the scene call of the Lua host, through the engine: the
//! functions only the Lua host serves (`sim.callScriptFunction`, `sim.getScript`, ...)
//! and named script functions such as `sysCall_packet`. A remote client has no
//! emitting object; script code it runs gets a hook's time budget. What it asks of the
//! simulation (a stop, a model loaded) waits in [`LuaHost::take_requests`].

use gantry_sim_core::SimError;
use std::borrow::Cow;

use gantry_sim_core::Value;
use gantry_sim_core::api::{self, CallError};
use mlua::{Function, MultiValue};

use crate::app_state::state;
use crate::convert::{to_multi, to_value};
use crate::directory::{Directory, HANDLE_SELF};
use crate::host::LuaHost;
use crate::host_api::{call_script_function, script_handle};
use crate::lua_error::error_text;
use crate::running::Running;
use crate::scripts::ScriptState;

impl LuaHost {
    /// A function the Lua host serves for remote clients (it needs the scripts).
    ///
    /// # Errors
    /// The CoppeliaSim-style error message.
    pub fn call_script_host(&mut self, f: api::ScriptHostFn, args: &[Value]) -> Result<Vec<Value>, CallError> {
        use api::ScriptHostFn;
        let in_function = |e: SimError| CallError::failed(format!("sim.{}", f.name()), e);
        match f {
            ScriptHostFn::GetScriptAssociatedWithObject => {
                script_handle(&self.lua, &[Value::Int(1), args.first().cloned().unwrap_or_default()])
                    .map(|h| vec![Value::Int(h)])
                    .map_err(in_function)
            }
            ScriptHostFn::RemoveScript => {
                let h = args.first().and_then(Value::as_i64);
                let index = h.map(|h| (h, state::<Directory>(&self.lua).index_of(h)));
                match index {
                    Some((_, Some(i))) => {
                        self.scripts.remove(i);
                        Ok(Vec::new())
                    }
                    Some((HANDLE_SELF, None)) => Err(SimError::bad_argument(
                        "sim.handle_self names the calling script, and a remote client has none",
                    )),
                    Some((h, None)) => Err(SimError::NoSuchItem(format!("argument 1: no script has handle {h}"))),
                    None => Err(SimError::bad_argument(format!(
                        "argument 1: expected a script handle, got {}",
                        args.first().map_or("nil", Value::type_name)
                    ))),
                }
                .map_err(in_function)
            }
            ScriptHostFn::LoadModel => match args.first() {
                Some(Value::Str(path)) => self
                    .load_model(std::path::Path::new(path))
                    .map_err(|e| in_function(e.into())),
                _ => Err(in_function(SimError::bad_argument(
                    "argument 1: expected the model file's path as a string",
                ))),
            }
            .map(|h| vec![Value::Int(h)]),
            ScriptHostFn::GetScript => script_handle(&self.lua, args)
                .map(|h| vec![Value::Int(h)])
                .map_err(in_function),
            ScriptHostFn::Wait
            | ScriptHostFn::WaitForSignal
            | ScriptHostFn::MoveToConfig
            | ScriptHostFn::MoveToPose => {
                // The engine runs these over several steps (`LuaHost::start_blocking`).
                Err(in_function(SimError::refused(
                    "this call blocks across steps and is served by the engine, not as a single call",
                )))
            }
            ScriptHostFn::CallScriptFunction => {
                // Script code running for a remote client is outside any hook, so it gets
                // a hook's time budget here; otherwise a loop in the called function
                // would hold the simulation thread until the idle deadline, an hour away.
                state::<Running>(&self.lua).restart_budget();
                let r = call_script_function(&self.lua, args);
                self.scripts.leave();
                r.map_err(|e| in_function(SimError::refused(error_text(&e))))
            }
        }
    }

    /// Calls a named global function of the scripts attached to `object` (or of every
    /// script, for `None`) with `args`; returns the first script's results. Used by the
    /// transports for hooks such as `sysCall_packet`.
    ///
    /// Returns `Ok(None)` when no script defines the function.
    ///
    /// # Errors
    /// The function raised an error (the script is then marked errored).
    pub fn call_hook_function(&mut self, function: &str, args: &[Value]) -> Result<Option<Vec<Value>>, HookError> {
        for k in 0..self.scripts.order.len() {
            let i = self.scripts.order[k];
            if self.scripts.list[i].state != ScriptState::Running {
                continue;
            }
            let Ok(Some(f)) = self.scripts.list[i].env.raw_get::<Option<Function>>(function) else {
                continue;
            };
            let lua_args = to_multi(&self.lua, args).map_err(|e| HookError::Conversion(e.to_string()))?;
            self.scripts.enter(i, Cow::Owned(function.to_owned()));
            let r = self.scripts.call_script::<MultiValue>(&f, lua_args);
            self.scripts.leave();
            let out = match r {
                Ok(values) => values
                    .iter()
                    .map(to_value)
                    .collect::<mlua::Result<Vec<_>>>()
                    .map(Some)
                    .map_err(|e| HookError::Conversion(e.to_string())),
                Err(e) => {
                    let text = error_text(&e);
                    self.scripts.fail(i, e);
                    Err(HookError::Raised(text))
                }
            };
            return out;
        }
        Ok(None)
    }
}

/// Why a script function called by a transport ([`LuaHost::call_hook_function`],
/// e.g. `sysCall_packet`) failed. The text is what the transport sends back.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HookError {
    /// The arguments or the results do not convert between Lua and [`Value`].
    #[error("{0}")]
    Conversion(String),
    /// The function raised this error (with file and line); its script is marked errored.
    #[error("{0}")]
    Raised(String),
}
