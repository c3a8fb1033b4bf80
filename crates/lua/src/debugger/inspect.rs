//! Reading and writing a stopped script's frames: the Rust face of `lua/debugger.lua`,
//! which holds Lua's real `debug` library on the host's side.

use mlua::{Function, Lua, MultiValue, Table, Thread, Value as LuaValue};

use super::link::DebuggerError;
use crate::sandbox::HostLibs;

/// Most entries listed for one table: a script's table may be huge; an editor pages.
pub(super) const MAX_ENTRIES: i64 = 1000;

/// A script frame as Lua reports it.
#[derive(Debug, Clone)]
pub(super) struct RawFrame {
    /// The chunk name (`@path`).
    pub(super) source: String,
    pub(super) line: u32,
    /// The function's name where Lua knows it (not for a hook called by the host).
    pub(super) name: Option<String>,
}

/// The functions of `lua/debugger.lua`.
pub(super) struct Inspector {
    /// Chunk names of the scene's scripts (`@path` -> true): which frames are scripts'.
    pub(super) scripts: Table,
    frames: Function,
    locals: Function,
    upvalues: Function,
    setlocal: Function,
    setupvalue: Function,
    compile: Function,
    run: Function,
    describe: Function,
    entries: Function,
}

impl Inspector {
    pub(super) fn new(lua: &Lua, libs: HostLibs) -> mlua::Result<Self> {
        let scripts = lua.create_table()?;
        let m: Table = lua
            .load(include_str!("../lua/debugger.lua"))
            .set_name("=gantry-debugger")
            .call((libs.debug, libs.load, scripts.clone()))?;
        Ok(Self {
            scripts,
            frames: m.get("frames")?,
            locals: m.get("locals")?,
            upvalues: m.get("upvalues")?,
            setlocal: m.get("setlocal")?,
            setupvalue: m.get("setupvalue")?,
            compile: m.get("compile")?,
            run: m.get("run")?,
            describe: m.get("describe")?,
            entries: m.get("entries")?,
        })
    }

    pub(super) fn frames(&self, co: &Thread) -> mlua::Result<Vec<RawFrame>> {
        let list: Vec<Table> = self.frames.call(co)?;
        list.into_iter()
            .map(|t| {
                Ok(RawFrame {
                    source: t.get::<String>("source")?,
                    line: t
                        .get::<Option<i64>>("line")?
                        .and_then(|l| u32::try_from(l).ok())
                        .unwrap_or(0),
                    name: t.get("name")?,
                })
            })
            .collect()
    }

    /// Locals (`upvalues: false`) or upvalues of frame `k` (from 1).
    pub(super) fn scope(&self, co: &Thread, k: usize, upvalues: bool) -> mlua::Result<Vec<(String, LuaValue)>> {
        let f = if upvalues { &self.upvalues } else { &self.locals };
        let (names, values): (Option<Vec<String>>, Option<Table>) = f.call((co, k))?;
        let names = names.unwrap_or_default();
        let mut out = Vec::with_capacity(names.len());
        for (i, n) in names.into_iter().enumerate() {
            let v = match &values {
                Some(t) => t.raw_get(i + 1)?,
                None => LuaValue::Nil,
            };
            out.push((n, v));
        }
        Ok(out)
    }

    /// Sets a local, else an upvalue, of frame `k`; false if it has neither by that name.
    pub(super) fn set(&self, co: &Thread, k: usize, name: &str, value: LuaValue, upvalue: bool) -> mlua::Result<bool> {
        let f = if upvalue { &self.setupvalue } else { &self.setlocal };
        f.call((co, k, name, value))
    }

    /// Compiles `code` for frame `k` of `co`, or for the script's globals `env` alone.
    pub(super) fn compile(
        &self,
        frame: Option<(&Thread, usize)>,
        env: &Table,
        code: &str,
    ) -> Result<Function, DebuggerError> {
        let (co, k) = match frame {
            Some((co, k)) => (LuaValue::Thread(co.clone()), LuaValue::Integer(k as i64)),
            None => (LuaValue::Nil, LuaValue::Nil),
        };
        let (f, err): (Option<Function>, Option<String>) = self
            .compile
            .call((co, k, env, code))
            .map_err(|e| DebuggerError::Lua(e.to_string()))?;
        f.ok_or_else(|| DebuggerError::Lua(err.unwrap_or_else(|| "cannot compile the expression".into())))
    }

    /// Runs a compiled expression in a coroutine of its own (see debugger.lua).
    pub(super) fn run(&self, f: Function) -> Result<MultiValue, DebuggerError> {
        let out: MultiValue = self
            .run
            .call(f)
            .map_err(|e| DebuggerError::Lua(crate::lua_error::error_text(&e)))?;
        let mut it = out.into_iter();
        match it.next() {
            Some(LuaValue::Boolean(true)) => Ok(it.collect()),
            _ => Err(DebuggerError::Lua(match it.next() {
                Some(LuaValue::String(s)) => s.to_string_lossy(),
                Some(LuaValue::Error(e)) => crate::lua_error::error_text(&e),
                Some(other) => format!("{other:?}"),
                None => "error".into(),
            })),
        }
    }

    /// The text and type name an editor shows.
    pub(super) fn describe(&self, v: &LuaValue) -> (String, String) {
        self.describe
            .call::<(String, String)>(v.clone())
            .unwrap_or_else(|e| (format!("<{e}>"), v.type_name().to_owned()))
    }

    /// A table's entries as (display name, value, key), at most [`MAX_ENTRIES`].
    pub(super) fn entries(&self, t: &Table) -> mlua::Result<Vec<(String, LuaValue, LuaValue)>> {
        let (names, values, keys): (Vec<String>, Table, Table) = self.entries.call((t, MAX_ENTRIES))?;
        let mut out = Vec::with_capacity(names.len());
        for (i, n) in names.into_iter().enumerate() {
            out.push((n, values.raw_get(i + 1)?, keys.raw_get(i + 1)?));
        }
        Ok(out)
    }
}
