//! Lua values to and from the API's [`Value`].
//!
//! Tables with keys `1..n` and nothing else become arrays; other tables become maps.
//! Strings that are valid UTF-8 become text, others bytes. Depth is bounded so a
//! self-referencing table cannot recurse forever.

use gantry_sim_core::Value;
use mlua::{Lua, MultiValue, Table, Value as LuaValue};

/// Deepest table nesting converted.
const MAX_DEPTH: usize = 32;

/// Converts a Lua value.
///
/// # Errors
/// Functions, userdata, threads, or nesting deeper than 32 levels.
pub fn to_value(v: &LuaValue) -> mlua::Result<Value> {
    convert(v, 0)
}

fn convert(v: &LuaValue, depth: usize) -> mlua::Result<Value> {
    Ok(match v {
        LuaValue::Nil => Value::Nil,
        LuaValue::Boolean(b) => Value::Bool(*b),
        LuaValue::Integer(i) => Value::Int(*i),
        LuaValue::Number(n) => Value::Float(*n),
        LuaValue::String(s) => {
            let bytes = s.as_bytes();
            match std::str::from_utf8(&bytes) {
                Ok(t) => Value::Str(t.to_owned()),
                Err(_) => Value::Bytes(bytes.to_vec()),
            }
        }
        LuaValue::Table(t) => {
            if depth >= MAX_DEPTH {
                return Err(mlua::Error::runtime(
                    "table nested too deeply (more than 32 levels, or a cycle)",
                ));
            }
            table(t, depth + 1)?
        }
        other => {
            return Err(mlua::Error::runtime(format!(
                "cannot pass a {} to the sim API",
                other.type_name()
            )));
        }
    })
}

fn table(t: &Table, depth: usize) -> mlua::Result<Value> {
    let n = t.raw_len();
    let mut count = 0usize;
    for pair in t.pairs::<LuaValue, LuaValue>() {
        pair?;
        count += 1;
    }
    if count == n {
        let mut out = Vec::with_capacity(n);
        for i in 1..=n {
            out.push(convert(&t.raw_get::<LuaValue>(i)?, depth)?);
        }
        Ok(Value::Array(out))
    } else {
        let mut out = Vec::with_capacity(count);
        for pair in t.pairs::<LuaValue, LuaValue>() {
            let (k, v) = pair?;
            out.push((convert(&k, depth)?, convert(&v, depth)?));
        }
        Ok(Value::Map(out))
    }
}

/// Converts an API value to Lua.
///
/// # Errors
/// Lua allocation failures (memory limit).
pub fn to_lua(lua: &Lua, v: &Value) -> mlua::Result<LuaValue> {
    Ok(match v {
        Value::Nil => LuaValue::Nil,
        Value::Bool(b) => LuaValue::Boolean(*b),
        Value::Int(i) => LuaValue::Integer(*i),
        Value::Float(f) => LuaValue::Number(*f),
        Value::Str(s) => LuaValue::String(lua.create_string(s)?),
        Value::Bytes(b) => LuaValue::String(lua.create_string(b)?),
        Value::Array(items) => {
            let t = lua.create_table_with_capacity(items.len(), 0)?;
            for (i, item) in items.iter().enumerate() {
                t.raw_set(i + 1, to_lua(lua, item)?)?;
            }
            LuaValue::Table(t)
        }
        Value::Map(pairs) => {
            let t = lua.create_table_with_capacity(0, pairs.len())?;
            for (k, v) in pairs {
                t.raw_set(to_lua(lua, k)?, to_lua(lua, v)?)?;
            }
            LuaValue::Table(t)
        }
    })
}

/// Converts several API values to Lua's multiple values.
///
/// # Errors
/// Lua allocation failures.
pub fn to_multi(lua: &Lua, values: &[Value]) -> mlua::Result<MultiValue> {
    values.iter().map(|v| to_lua(lua, v)).collect()
}
