//! The `sim.*` functions as scripts call them: every function of the API registry
//! ([`api::MODULES`]) bound to the simulation core, and the functions about scripts
//! that only the Lua host can serve (`sim.getScript`, `sim.callScriptFunction`,
//! `sim.removeScript`), with the other roles installing their own (messages, models,
//! simulation control, threads, `simRemoteApi`).
//!
//! No closure here captures host state: each function finds what it needs in the Lua
//! state's app data (see [`crate::app_state`]).

use std::cell::RefCell;
use std::rc::Rc;

use gantry_sim_core::api::{self, Args, CallContext, CallError};
use gantry_sim_core::sim::SimulationState;
use gantry_sim_core::{Handle, SimError, Value};
use mlua::{Function, Lua, MultiValue, Table, Value as LuaValue};
use smallvec::SmallVec;

use crate::app_state::state;
use crate::control;
use crate::convert::{to_lua, to_multi, to_value};
use crate::directory::{Directory, HANDLE_SELF};
use crate::listeners::{self, ListenerState};
use crate::lua_error::error_text;
use crate::messages;
use crate::models;
use crate::recording;
use crate::running::{Caller, Running};
use crate::sim_cell::SimCell;
use crate::threads;

/// Creates the API's global tables (`sim`, and `simIK`, `simUI`, `simVision` as they
/// exist, `simRemoteApi` with the front end's `listeners`): every function of
/// [`api::MODULES`] plus constants, and the host's own functions.
pub(crate) fn install(lua: &Lua, listeners: &Rc<RefCell<ListenerState>>) -> mlua::Result<()> {
    // CoppeliaSim raises API errors as plain strings prefixed with the caller's
    // position, which scripts concatenate and match on. An error raised from Rust would
    // reach Lua as userdata, so each function reports failure as a value and this
    // wrapper raises it with `error(msg, 2)` from the caller's point of view.
    let wrap: Function = lua
        .load(
            r#"
            local error = ...
            local function finish(ok, ...)
                if ok then return ... end
                error((...), 3)
            end
            return function(f) return function(...) return finish(f(...)) end end
            "#,
        )
        .set_name("@gantry/api.lua")
        .call(lua.globals().get::<Function>("error")?)?;
    let mut sim = None;
    for module in api::MODULES {
        let table = lua.create_table()?;
        for (name, f) in module.callable() {
            let f = *f;
            let qualified = format!("{}.{name}", module.name);
            let func = lua.create_function(move |lua, args: MultiValue| {
                // This runs for every API call a script makes, often dozens per step: no
                // heap allocation for the usual handful of arguments, and the caller's
                // name is borrowed, not copied (API functions never call back into Lua).
                let values = args
                    .iter()
                    .map(to_value)
                    .collect::<mlua::Result<SmallVec<[Value; 4]>>>()?;
                let running = state::<Running>(lua);
                let source = running.name.borrow();
                let ctx = CallContext {
                    script_object: running.object.get(),
                    source: &source,
                };
                let result = {
                    let core = state::<SimCell>(lua);
                    let mut sim = core
                        .try_borrow_mut()
                        .map_err(|_| mlua::Error::runtime(format!("the world is busy (in function '{qualified}')")))?;
                    f.invoke(&mut sim, &ctx, &Args::new(&values))
                };
                // The Lua wrapper turns (false, message) into a Lua string error.
                match result {
                    Ok(ret) => {
                        let mut out = MultiValue::with_capacity(ret.len() + 1);
                        out.push_back(LuaValue::Boolean(true));
                        for v in ret.iter() {
                            out.push_back(to_lua(lua, v)?);
                        }
                        Ok(out)
                    }
                    Err(e) => Ok(MultiValue::from_iter([
                        LuaValue::Boolean(false),
                        LuaValue::String(lua.create_string(e.in_function(&qualified))?),
                    ])),
                }
            })?;
            table.set(name, wrap.call::<Function>(func)?)?;
        }
        for (name, value) in module.constants {
            // `simOMPL.StateSpaceType.pose3d`: a dotted name lives in a nested table.
            match name.split_once('.') {
                None => table.set(*name, *value)?,
                Some((group, member)) => {
                    let inner = match table.raw_get::<Option<Table>>(group)? {
                        Some(t) => t,
                        None => {
                            let t = lua.create_table()?;
                            table.set(group, t.clone())?;
                            t
                        }
                    };
                    inner.set(member, *value)?;
                }
            }
        }
        lua.globals().set(module.name, table.clone())?;
        if module.name == "sim" {
            sim = Some(table);
        }
    }
    let sim = sim.ok_or_else(|| mlua::Error::runtime("the API has no sim module"))?;
    // `simRemoteApi.start` needs to know whether the simulation runs; the state lives
    // in the core, which the closure reaches through a weak reference (the Lua state
    // owns the closure, the simulation owns both).
    let core = Rc::downgrade(&state::<SimCell>(lua).0);
    let remote_api = listeners::install(
        lua,
        listeners,
        Rc::new(move || {
            core.upgrade()
                .and_then(|c| c.try_borrow().map(|s| s.state != SimulationState::Stopped).ok())
                .unwrap_or(true)
        }),
        &wrap,
    )?;
    lua.globals().set("simRemoteApi", remote_api)?;
    let (ros2, ros1) = crate::ros::module::install(lua, &wrap)?;
    lua.globals().set("simROS2", ros2)?;
    lua.globals().set("simROS", ros1)?;
    install_script_functions(lua, &sim, &wrap)?;
    messages::install(lua, &sim, &wrap)?;
    models::install(lua, &sim, &wrap)?;
    crate::launch::install(lua, &sim, &wrap)?;
    recording::install(lua, &sim, &wrap)?;
    control::install(lua, &sim)?;
    install_in_place(lua, &sim)?;
    threads::install(lua, &sim)
}

/// V-REP 3's `sim.invertMatrix(matrix)`: inverts the 12-value matrix table the script
/// passes, in place, and returns 1. Registry functions return new values; only the
/// host can write into a table the script holds.
fn install_in_place(lua: &Lua, sim: &Table) -> mlua::Result<()> {
    const IN_PLACE: &str = r#"
local sim, pcall, error = ...
sim.invertMatrix = function(matrix)
    local ok, inverse = pcall(sim.getMatrixInverse, matrix)
    if not ok then error(inverse, 2) end
    for i = 1, 12 do matrix[i] = inverse[i] end
    return 1
end
"#;
    let g = lua.globals();
    lua.load(IN_PLACE).set_name("@gantry/in_place.lua").call::<()>((
        sim.clone(),
        g.get::<Function>("pcall")?,
        g.get::<Function>("error")?,
    ))
}

/// `sim.callScriptFunction`, `sim.getScript`, `sim.removeScript` and
/// `sim.getScriptAssociatedWithObject`.
fn install_script_functions(lua: &Lua, sim: &Table, wrap: &Function) -> mlua::Result<()> {
    sim.set(
        "callScriptFunction",
        lua.create_function(move |lua, args: MultiValue| {
            let values = args.iter().map(to_value).collect::<mlua::Result<Vec<_>>>()?;
            match call_script_function(lua, &values) {
                Ok(ret) => {
                    let mut out = to_multi(lua, &ret)?;
                    out.push_front(LuaValue::Boolean(true));
                    Ok(out)
                }
                Err(e) => Ok(MultiValue::from_iter([
                    LuaValue::Boolean(false),
                    LuaValue::String(
                        lua.create_string(format!("{} (in function 'sim.callScriptFunction')", error_text(&e)))?,
                    ),
                ])),
            }
        })
        .and_then(|f| wrap.call::<Function>(f))?,
    )?;
    // A script's handle is the handle of the object it is attached to.
    sim.set(
        "getScript",
        lua.create_function(move |lua, args: MultiValue| {
            let values = args.iter().map(to_value).collect::<mlua::Result<Vec<_>>>()?;
            Ok(match script_handle(lua, &values) {
                Ok(h) => (true, LuaValue::Integer(h)),
                Err(e) => (
                    false,
                    LuaValue::String(lua.create_string(format!("{e} (in function 'sim.getScript')"))?),
                ),
            })
        })
        .and_then(|f| wrap.call::<Function>(f))?,
    )?;
    // Removal waits for the calling hook to return (a script may remove itself and go
    // on, as CoppeliaSim's does, until its function ends).
    sim.set(
        "removeScript",
        lua.create_function(move |lua, h: LuaValue| {
            let handle = match &h {
                LuaValue::Integer(i) => Some(*i),
                LuaValue::Number(n) if n.fract() == 0.0 => Some(*n as i64),
                _ => None,
            };
            let directory = state::<Directory>(lua);
            // The calling script itself, even when its object carries several scripts.
            let index = match handle {
                Some(HANDLE_SELF) => state::<Running>(lua).script.get(),
                Some(h) => directory.index_of(h),
                None => None,
            };
            Ok(match index {
                Some(i) => {
                    directory.request_removal(i);
                    (true, LuaValue::Nil)
                }
                None => (
                    false,
                    LuaValue::String(lua.create_string(match handle {
                        Some(h) => format!("argument 1: no script has handle {h} (in function 'sim.removeScript')"),
                        None => format!(
                            "argument 1: expected a script handle, got {} (in function 'sim.removeScript')",
                            h.type_name()
                        ),
                    })?),
                ),
            })
        })
        .and_then(|f| wrap.call::<Function>(f))?,
    )?;
    // CoppeliaSim 4.0-4.2: the script attached to an object, -1 when none.
    sim.set(
        "getScriptAssociatedWithObject",
        lua.create_function(move |lua, object: LuaValue| {
            let object = to_value(&object)?;
            Ok(script_handle(lua, &[Value::Int(1), object]).unwrap_or(-1))
        })?,
    )
}

/// `sim.getScript(scriptType, object = -1)`: the handle of the script attached to
/// `object` (a handle or a path), which in gantry is the object's handle, or -1 when
/// it has no script; `sim.getScript(sim.handle_self)` is the calling script's.
pub(crate) fn script_handle(lua: &Lua, args: &[Value]) -> Result<Handle, SimError> {
    let kind = args
        .first()
        .and_then(Value::as_i64)
        .ok_or_else(|| SimError::bad_argument("argument 1: expected integer (a script type or sim.handle_self)"))?;
    let caller = state::<Running>(lua).object.get();
    if kind == HANDLE_SELF {
        return caller.ok_or_else(|| {
            SimError::bad_argument("sim.handle_self names the calling script, and a remote client has none")
        });
    }
    let object = match args.get(1) {
        None | Some(Value::Nil) => return Ok(-1),
        Some(Value::Str(path)) => {
            let ctx = CallContext {
                script_object: caller,
                source: "getScript",
            };
            let core = state::<SimCell>(lua);
            let mut world = core
                .try_borrow_mut()
                .map_err(|_| SimError::refused("the world is busy"))?;
            let found = api::call(&mut world, &ctx, "getObject", &[Value::Str(path.clone())]).map_err(|e| match e {
                CallError::Failed { error, .. } => error,
                other => SimError::refused(other.to_string()),
            })?;
            found.first().and_then(Value::as_i64).unwrap_or(-1)
        }
        Some(v) => v
            .as_i64()
            .ok_or_else(|| SimError::bad_argument("argument 2: expected an object handle or path"))?,
    };
    Ok(if state::<Directory>(lua).attached(object) {
        object
    } else {
        -1
    })
}

/// `sim.callScriptFunction(name, scriptHandle, ...)`: calls a global function of the
/// script attached to object `scriptHandle` (also accepts CoppeliaSim's `name@alias`).
pub(crate) fn call_script_function(lua: &Lua, args: &[Value]) -> mlua::Result<Vec<Value>> {
    let name = match args.first() {
        Some(Value::Str(s)) => s.split('@').next().unwrap_or_default().to_owned(),
        _ => {
            return Err(mlua::Error::runtime("argument 1: expected string (the function name)"));
        }
    };
    let target = args
        .get(1)
        .and_then(Value::as_i64)
        .ok_or_else(|| mlua::Error::runtime("argument 2: expected a script handle"))?;
    let Some((_, callee)) = state::<Directory>(lua).find(target) else {
        return Err(mlua::Error::runtime(format!(
            "no script is attached to object {target}"
        )));
    };
    let f: Function = match callee.env.raw_get::<LuaValue>(name.as_str())? {
        LuaValue::Function(f) => f,
        _ => {
            return Err(mlua::Error::runtime(format!(
                "script {} has no function '{name}'",
                callee.name
            )));
        }
    };
    let call_args = to_multi(lua, &args[2.min(args.len())..])?;
    let running = state::<Running>(lua);
    // The callee's object and name for paths and logs; the thread mode stays the caller's.
    let previous = running.act_as(Caller {
        object: Some(callee.object),
        script: running.script.get(),
        name: callee.name,
    });
    let r = f.call::<MultiValue>(call_args);
    running.act_as(previous);
    r?.iter().map(to_value).collect()
}
