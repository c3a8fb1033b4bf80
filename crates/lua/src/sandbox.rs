//! The sandbox scripts run in: what a scene's Lua code may reach, and what it may not.
//!
//! Scripts are student or downloaded code running inside the user's process, so they get
//! computation and the `sim` API, and nothing that reaches the machine:
//!
//! * no process or environment access, and files only through the confined `io`
//!   (`crate::script_io`): Lua's own `io`, `package`, `debug` (but for
//!   `debug.traceback`) and the `os` functions listed in [`REMOVED_OS`] are not loaded;
//!   `os.time`, `os.clock`, `os.date` and `os.difftime` remain;
//! * no loading of code other than the script's own file: the globals in
//!   [`REMOVED_GLOBALS`] are gone (so no bytecode; `require` returns the API's
//!   namespaces, [`REQUIRABLE`], or loads the user's modules as text from the scene's
//!   folder and the `--lua-path` folders, `crate::modules`), and script
//!   files themselves are compiled as text only ([`SOURCE_MODE`]), because Lua does not
//!   verify binary chunks and a crafted one can corrupt memory;
//! * no way to change what other scripts see: every script gets its own copy of the
//!   global tables (`script_env`), as in CoppeliaSim where each script has its own Lua
//!   state, and the one thing all scripts still share, the string metatable, is
//!   protected;
//! * no use of the shared collector against the others: `__gc` finalizers are refused
//!   (they would run at the collector's convenience, inside whichever script happens
//!   to allocate, or outside any time budget) and `collectgarbage` cannot stop or retune
//!   the collector;
//! * files written through the API only inside the scene's folder (`confine`); files
//!   opened with `io.open` read only from the scene's folder and the `--allow-files`
//!   folders, written only in the latter (`crate::script_io`);
//! * the network only through LuaSocket's TCP subset, listening where gantry listens
//!   and connecting out only when the user allows it (`crate::luasocket`).
//!
//! Time and memory are bounded elsewhere: the time budget by the hook in `budget.rs`,
//! memory by the state's cap set in `new_state`. Non-goal: protecting against a malicious Rust host or
//! against the scene's author, who chose the scripts.

use mlua::chunk::ChunkMode;
use mlua::{Lua, LuaOptions, StdLib, Table, Value as LuaValue};

use crate::limits::ScriptLimits;

/// Globals removed from the base library: each loads code from a file or from a string
/// (which may be bytecode), bypassing the checks on script files.
/// (`require` comes with the `package` library, which is not loaded; scripts get the
/// sandbox's own, see `add_require`.)
pub const REMOVED_GLOBALS: &[&str] = &["dofile", "loadfile", "load", "loadstring"];

/// `os` functions removed: they run programs, touch files, read the environment, end
/// the process or change its locale.
pub const REMOVED_OS: &[&str] = &["execute", "exit", "remove", "rename", "tmpname", "getenv", "setlocale"];

/// How script files are compiled: text only, never precompiled bytecode.
pub const SOURCE_MODE: ChunkMode = ChunkMode::Text;

/// Lua run once on the fresh state, before the API is installed: guards on the few
/// shared things that copying the globals per script cannot make private.
const HARDEN: &str = r#"
-- The string metatable is shared by every script (`s:upper()` goes through it). With
-- `__metatable` set, `getmetatable('')` returns false instead of the table, so no
-- script can swap its `__index` and change string methods for the others.
getmetatable('').__metatable = false

local rawsetmetatable, rawget, error, type, tostring = setmetatable, rawget, error, type, tostring
setmetatable = function(t, mt)
    -- Lua marks an object for finalization when its metatable has a `__gc` field at
    -- this moment (even a placeholder later replaced), so this one check covers it.
    if type(mt) == 'table' and rawget(mt, '__gc') ~= nil then
        error('setmetatable: __gc finalizers are not allowed in gantry scripts '
            .. '(the collector would run them outside the script\'s time budget)', 2)
    end
    return rawsetmetatable(t, mt)
end

local rawcollect = collectgarbage
local allowed = { collect = true, count = true, step = true, isrunning = true }
collectgarbage = function(opt, ...)
    if opt == nil or allowed[opt] then
        return rawcollect(opt, ...)
    end
    error("collectgarbage('" .. tostring(opt) .. "') is not allowed in gantry scripts: the "
        .. 'collector is shared by every script (allowed: collect, count, step, isrunning)', 2)
end
"#;

/// A Lua state with the safe standard libraries only (no `io`, no `package`, no
/// `debug`), without the globals and `os` functions listed above, with the shared
/// metatables guarded and the memory capped at `limits.memory`.
///
/// # Errors
/// Lua could not allocate the state.
pub(crate) fn new_state(limits: &ScriptLimits) -> mlua::Result<Lua> {
    // `new_with` refuses the unsafe libraries (debug, ffi) and, in this "safe" mode,
    // C modules; `package` is simply not loaded.
    let lua = Lua::new_with(safe_libs(), LuaOptions::default())?;
    harden(&lua, limits)?;
    Ok(lua)
}

/// The libraries scripts get (some trimmed below).
fn safe_libs() -> StdLib {
    StdLib::TABLE | StdLib::STRING | StdLib::MATH | StdLib::UTF8 | StdLib::COROUTINE | StdLib::OS
}

/// [`new_state`] for `gantry run --debug`: the same sandbox for scripts, plus Lua's
/// full `debug` library returned to the host alone (the debugger reads frames, locals
/// and upvalues with it). It is never a global: scripts cannot reach it, and without
/// `--debug` it is not loaded at all.
///
/// # Errors
/// Lua could not allocate the state.
pub(crate) fn new_debuggable_state(limits: &ScriptLimits) -> mlua::Result<(Lua, HostLibs)> {
    // SAFETY: mlua calls the debug library unsafe because Lua code holding it can break
    // mlua's invariants (registry, userdata metatables). Only the host's debugger chunk
    // (lua/debugger.lua) receives it, and it only reads and writes frames' locals and
    // upvalues; `package` stays unloaded, so no C module can be loaded either.
    #[expect(unsafe_code, reason = "the debug library, for the host's debugger only")]
    let lua = unsafe { Lua::unsafe_new_with(safe_libs() | StdLib::DEBUG, LuaOptions::default()) };
    let libs = HostLibs {
        debug: lua.globals().get("debug")?,
        load: lua.globals().get("load")?,
    };
    harden(&lua, limits)?;
    Ok((lua, libs))
}

/// What the host's debugger keeps of the libraries the sandbox takes from scripts.
pub(crate) struct HostLibs {
    /// Lua's `debug` library.
    pub(crate) debug: Table,
    /// `load`, to compile the expressions typed in the editor (as text only).
    pub(crate) load: mlua::Function,
}

/// Trims the fresh state's globals to the sandbox (see the module docs).
fn harden(lua: &Lua, limits: &ScriptLimits) -> mlua::Result<()> {
    let g = lua.globals();
    for name in REMOVED_GLOBALS {
        g.raw_set(*name, LuaValue::Nil)?;
    }
    let os: Table = g.get("os")?;
    for name in REMOVED_OS {
        os.raw_set(*name, LuaValue::Nil)?;
    }
    lua.load(HARDEN).set_name("@gantry/sandbox.lua").exec()?;
    // CoppeliaSim's `table.tostring`, before the scripts' copies of `table` are made.
    let table: Table = g.get("table")?;
    let math: Table = g.get("math")?;
    let string: Table = g.get("string")?;
    lua.load(include_str!("lua/table_tostring.lua"))
        .set_name("@gantry/table_tostring.lua")
        .call::<()>((
            g.get::<mlua::Function>("type")?,
            g.get::<mlua::Function>("tostring")?,
            g.get::<mlua::Function>("pairs")?,
            g.get::<mlua::Function>("ipairs")?,
            table.get::<mlua::Function>("sort")?,
            table.get::<mlua::Function>("concat")?,
            string.get::<mlua::Function>("format")?,
            math.get::<mlua::Function>("floor")?,
        ))?;
    // `_S`: the table where CoppeliaSim 4.x's own Lua code keeps a script's private
    // state, which public scripts use the same way (simROS2's examples keep a throttle's
    // last times in it). Each script gets its own copy, like every table here.
    g.raw_set("_S", lua.create_table()?)?;
    // CoppeliaSim's Matrix and Vector classes (`require 'matrix'`), pure Lua.
    lua.load(include_str!("lua/matrix.lua"))
        .set_name("@gantry/matrix.lua")
        .exec()?;
    // `debug.traceback` only: the templates of CoppeliaSim 4.3-4.5 threaded scripts
    // report a coroutine's error with `error(debug.traceback(co, msg), 2)`. The rest of
    // the debug library reaches other scripts' locals and the registry.
    let debug = lua.create_table()?;
    debug.set(
        "traceback",
        lua.create_function(|lua, args: mlua::MultiValue| {
            let mut it = args.into_iter();
            match it.next().unwrap_or(LuaValue::Nil) {
                // A coroutine's stack cannot be walked without the debug library; its
                // message alone already names file and line.
                LuaValue::Thread(_) => Ok(it.next().unwrap_or(LuaValue::Nil)),
                LuaValue::String(m) => {
                    let level = match it.next() {
                        Some(LuaValue::Integer(l)) => usize::try_from(l).unwrap_or(1),
                        _ => 1,
                    };
                    Ok(LuaValue::String(lua.traceback(Some(&m.to_string_lossy()), level)?))
                }
                LuaValue::Nil => Ok(LuaValue::String(lua.traceback(None, 1)?)),
                // Lua returns a message that is not a string untouched.
                other => Ok(other),
            }
        })?,
    )?;
    g.raw_set("debug", debug)?;
    lua.set_memory_limit(limits.memory)?;
    Ok(())
}

/// A fresh global table for one script: a copy of the state's globals in which every
/// table (`sim`, `string`, `math`, ...) is itself copied, and `_G` is the script's own
/// table. A script that assigns `sim.getObject` or `string.format`, even with
/// `rawset`, changes only its own copy, as in CoppeliaSim, where each script has its
/// own Lua state. Functions are shared: they hold no state a script can reach.
///
/// Call it after the API is installed: later changes to the globals are not seen.
///
/// # Errors
/// Out of memory.
pub(crate) fn script_env(lua: &Lua) -> mlua::Result<Table> {
    let globals = lua.globals();
    // Original table -> its copy, so shared and cyclic references stay shared and
    // cyclic within the copy, and `_G` maps to the new table itself.
    let copies = lua.create_table()?;
    let env = lua.create_table()?;
    copies.raw_set(&globals, &env)?;
    copy_into(lua, &globals, &env, &copies)?;
    Ok(env)
}

/// Copies every entry of `from` into `to`, tables through `copies` (see [`script_env`]).
fn copy_into(lua: &Lua, from: &Table, to: &Table, copies: &Table) -> mlua::Result<()> {
    for pair in from.pairs::<LuaValue, LuaValue>() {
        let (k, v) = pair?;
        let v = match v {
            LuaValue::Table(t) => LuaValue::Table(copy_table(lua, &t, copies)?),
            other => other,
        };
        to.raw_set(k, v)?;
    }
    Ok(())
}

fn copy_table(lua: &Lua, t: &Table, copies: &Table) -> mlua::Result<Table> {
    if let Some(done) = copies.raw_get::<Option<Table>>(t)? {
        return Ok(done);
    }
    let copy = lua.create_table()?;
    copies.raw_set(t, &copy)?;
    copy_into(lua, t, &copy, copies)?;
    // Library tables have no metatables; a table that had one keeps it (shared), as
    // copying metatables could change what its metamethods see.
    if let Some(mt) = t.metatable() {
        copy.set_metatable(Some(mt))?;
    }
    Ok(copy)
}

/// The modules `require` returns: the API's namespaces, as in CoppeliaSim 4.6+ where
/// scripts begin with `sim = require 'sim'`.
pub const REQUIRABLE: &[&str] = &[
    "Matrix",
    "sim",
    "simIK",
    "simOMPL",
    "simROS",
    "simROS2",
    "simRemoteApi",
    "simUI",
    "simVision",
    "socket",
];

/// Other names `require` accepts, and the global each one returns: LuaSocket's C core,
/// which a few scripts require directly (see `crate::luasocket`), and CoppeliaSim's
/// `matrix` library, whose classes (`Matrix`, `Vector`, ...) every script has.
pub const REQUIRE_ALIASES: &[(&str, &str)] = &[("socket.core", "socket"), ("matrix", "Matrix")];

/// Gives a script's environment a `require` that returns the script's own copy of an
/// API namespace (or of the LuaSocket subset) and otherwise loads the user's module of
/// that name with `find` (see `crate::modules`), once per script: what the module
/// returns is cached (`true` when it returns nothing), and a module required again while
/// it is still loading (a cycle) is refused as Lua's `package.loaded` sentinel would,
/// instead of recursing until the stack overflows. Written in Lua and compiled with the
/// script's environment so that it closes over that environment only through Lua
/// (collectable with it).
/// `find(name, env)` returns the chunk of the user's module `name` compiled into `env`,
/// and its file (`crate::modules::finder`).
pub(crate) fn add_require(lua: &Lua, env: &Table, find: mlua::Function) -> mlua::Result<()> {
    const REQUIRE: &str = r#"
local allowed, aliases, error, type, tostring, find = ...
local loaded, loading = {}, {}
function require(name)
    if type(name) ~= 'string' then
        error("bad argument #1 to 'require' (string expected, got " .. type(name) .. ")", 2)
    end
    -- CoppeliaSim 4.6 also accepts versioned names such as 'sim-2'.
    local base = aliases[name] or name:match('^([%w_]+)%-%d+$') or name
    if allowed[base] then return _ENV[base] end
    local done = loaded[name]
    if done ~= nil then return done end
    if loading[name] then
        error("loop or previous error loading module '" .. name .. "'", 2)
    end
    loading[name] = true
    -- A module that fails stays marked, so requiring it again names the earlier error.
    -- The finder's refusals come back as a message, raised here as Lua's own are.
    local chunk, path = find(name, _ENV)
    if not chunk then error(path, 2) end
    local value = chunk(name, path)
    if value == nil then value = true end
    loaded[name] = value
    loading[name] = nil
    return value
end
"#;
    let allowed = lua.create_table()?;
    for (i, name) in REQUIRABLE.iter().enumerate() {
        allowed.raw_set(i + 1, *name)?;
        allowed.raw_set(*name, true)?;
    }
    let aliases = lua.create_table()?;
    for (name, global) in REQUIRE_ALIASES {
        aliases.raw_set(*name, *global)?;
    }
    let g = lua.globals();
    lua.load(REQUIRE)
        .set_name("@gantry/require.lua")
        .set_environment(env.clone())
        .call::<()>((
            allowed,
            aliases,
            g.get::<mlua::Function>("error")?,
            g.get::<mlua::Function>("type")?,
            g.get::<mlua::Function>("tostring")?,
            find,
        ))
}

/// Gives a script's environment V-REP 3's global names for the API, looked up when a
/// script reads a global it has not defined: `simGetObjectHandle` is `sim.getObjectHandle`,
/// the constant `sim_handle_all` is `sim.handle_all`, and ROS 1's plugin functions
/// `simExtRosInterface_publish` are `simROS.publish`. Pre-4.0 scripts (and 4.x scripts
/// that kept a few old calls) run with the one implementation of each function; names
/// the script defines itself are untouched, and the lookup reads the script's own
/// `sim`, so a script that replaces one of its functions sees its replacement.
pub(crate) fn add_vrep3_names(lua: &Lua, env: &Table) -> mlua::Result<()> {
    const NAMES: &str = r#"
local env, setmetatable, type, rawget, lower = ...
setmetatable(env, {
    __metatable = false,
    __index = function(_, k)
        if type(k) ~= 'string' then return nil end
        local sim = rawget(env, 'sim')
        if type(sim) ~= 'table' then return nil end
        local c = k:match('^sim_(.+)$')
        if c then return sim[c] end
        local ros = k:match('^simExtRosInterface_(.+)$')
        if ros then
            local m = rawget(env, 'simROS')
            return type(m) == 'table' and m[ros] or nil
        end
        local f = k:match('^sim(%u%w*)$')
        if f then return sim[lower(f:sub(1, 1)) .. f:sub(2)] end
        return nil
    end,
})
"#;
    let g = lua.globals();
    let string: Table = g.get("string")?;
    lua.load(NAMES).set_name("@gantry/vrep3_names.lua").call::<()>((
        env.clone(),
        g.get::<mlua::Function>("setmetatable")?,
        g.get::<mlua::Function>("type")?,
        g.get::<mlua::Function>("rawget")?,
        string.get::<mlua::Function>("lower")?,
    ))
}
