//! ROS 1's parameter server for `simROS` scripts (`setParamDouble`, `getParamInt`,
//! `hasParam`, `deleteParam`, ...). ROS 2 has no parameter server (parameters belong to
//! nodes), so gantry keeps these in the simulation, shared by its scripts and kept across
//! stops, as a roscore would keep them across runs; nothing goes on the graph. Old
//! scripts that store a robot's initial pose or gains this way run, and read back what
//! they or another script set.

use mlua::{Lua, MultiValue, Value as LuaValue};

use super::error::RosError;
use super::lua_api::{Res, arg, lua_type, missing, string_arg};
use super::param_store::{MAX_PARAMS, Param};
use crate::app_state::state;
use crate::ros::host::RosHost;

/// A parameter name made global: relative names are taken in the root namespace, as a
/// node without a namespace would; `~` (a node's private names) has no node here.
fn full_name(args: &MultiValue) -> Result<String, RosError> {
    let name = string_arg(args, 0, "the parameter name")?;
    if name.is_empty() || name.contains('~') {
        return Err(RosError::ParamName(name));
    }
    Ok(if name.starts_with('/') {
        name
    } else {
        format!("/{name}")
    })
}

fn set(lua: &Lua, args: &MultiValue, value: Param) -> Res {
    let name = full_name(args)?;
    let host = state::<RosHost>(lua);
    let mut params = host.params.borrow_mut();
    if params.len() >= MAX_PARAMS && !params.contains_key(&name) {
        return Err(RosError::TooManyParams);
    }
    params.insert(name, value);
    Ok(vec![])
}

fn value_arg(args: &MultiValue) -> Result<&LuaValue, RosError> {
    arg(args, 1).ok_or_else(|| missing(1, "the value"))
}

/// [`RosError::Expected`] of the value (argument 2).
fn expected(expected: &'static str, got: String) -> RosError {
    RosError::Expected { arg: 2, expected, got }
}

fn number(args: &MultiValue) -> Result<f64, RosError> {
    match value_arg(args)? {
        LuaValue::Integer(i) => Ok(*i as f64),
        LuaValue::Number(n) => Ok(*n),
        v => Err(expected("a number", lua_type(v).to_owned())),
    }
}

pub(super) fn set_double(lua: &Lua, a: &MultiValue) -> Res {
    let v = number(a)?;
    set(lua, a, Param::Double(v))
}

pub(super) fn set_int(lua: &Lua, a: &MultiValue) -> Res {
    let v = number(a)?;
    if v.fract() != 0.0 || !v.is_finite() {
        return Err(expected("an integer", v.to_string()));
    }
    set(lua, a, Param::Int(v as i64))
}

pub(super) fn set_bool(lua: &Lua, a: &MultiValue) -> Res {
    let v = match value_arg(a)? {
        LuaValue::Boolean(b) => *b,
        v => return Err(expected("a boolean", lua_type(v).to_owned())),
    };
    set(lua, a, Param::Bool(v))
}

pub(super) fn set_string(lua: &Lua, a: &MultiValue) -> Res {
    let v = string_arg(a, 1, "the value")?;
    set(lua, a, Param::Str(v))
}

/// `getParam*(name, default)`: `true, value` when the parameter exists with a value of
/// that kind (numbers convert between int and double), else `false, default`.
fn get(lua: &Lua, args: &MultiValue, convert: fn(&Lua, &Param) -> Option<LuaValue>) -> Res {
    let name = full_name(args)?;
    let found = state::<RosHost>(lua)
        .params
        .borrow()
        .get(&name)
        .and_then(|p| convert(lua, p));
    Ok(match found {
        Some(v) => vec![LuaValue::Boolean(true), v],
        None => vec![LuaValue::Boolean(false), arg(args, 1).cloned().unwrap_or(LuaValue::Nil)],
    })
}

pub(super) fn get_double(lua: &Lua, a: &MultiValue) -> Res {
    get(lua, a, |_, p| match p {
        Param::Double(d) => Some(LuaValue::Number(*d)),
        Param::Int(i) => Some(LuaValue::Number(*i as f64)),
        _ => None,
    })
}

pub(super) fn get_int(lua: &Lua, a: &MultiValue) -> Res {
    get(lua, a, |_, p| match p {
        Param::Int(i) => Some(LuaValue::Integer(*i)),
        Param::Double(d) if d.fract() == 0.0 && d.is_finite() => Some(LuaValue::Integer(*d as i64)),
        _ => None,
    })
}

pub(super) fn get_bool(lua: &Lua, a: &MultiValue) -> Res {
    get(lua, a, |_, p| match p {
        Param::Bool(b) => Some(LuaValue::Boolean(*b)),
        _ => None,
    })
}

pub(super) fn get_string(lua: &Lua, a: &MultiValue) -> Res {
    get(lua, a, |lua, p| match p {
        // Creating a string fails only when the state is out of memory.
        Param::Str(s) => lua.create_string(s).ok().map(LuaValue::String),
        _ => None,
    })
}

pub(super) fn has_param(lua: &Lua, a: &MultiValue) -> Res {
    let name = full_name(a)?;
    let has = state::<RosHost>(lua).params.borrow().contains_key(&name);
    Ok(vec![LuaValue::Boolean(has)])
}

pub(super) fn delete_param(lua: &Lua, a: &MultiValue) -> Res {
    let name = full_name(a)?;
    state::<RosHost>(lua).params.borrow_mut().remove(&name);
    Ok(vec![])
}
