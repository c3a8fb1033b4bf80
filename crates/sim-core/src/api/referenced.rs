//! Referenced handles (CoppeliaSim 4.7+): lists of objects an object names under a tag,
//! `sim.setReferencedHandles`, `sim.getReferencedHandles`, `sim.getReferencedHandle` and
//! `sim.getReferencedHandlesTags`. Models keep their parts this way (an IK helper script
//! reads `sim.getReferencedHandle(self, 'ik.tip')`), and scene files carry them, so an
//! imported model's scripts find what they were saved with. Stored with the world's
//! other per-object data ([`CustomData`](crate::world::CustomData)).

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::world::{Handle, World};

/// The functions this file implements, in alphabetical order.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "getReferencedHandle",
        call: ApiFn::World(get_referenced_handle),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getReferencedHandles",
        call: ApiFn::World(get_referenced_handles),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getReferencedHandlesTags",
        call: ApiFn::World(get_referenced_handles_tags),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setReferencedHandles",
        call: ApiFn::World(set_referenced_handles),
        cost: Cost::Quick,
    },
];

/// The optional tag argument at `i`: CoppeliaSim's default is the empty tag.
fn tag<'a>(a: &Args<'a>, i: usize) -> Result<&'a str, SimError> {
    match a.get(i) {
        Value::Nil => Ok(""),
        _ => a.str(i),
    }
}

/// The handles `owner` references under `tag`, a removed object's as -1 (as CoppeliaSim
/// reports them).
fn live(w: &World, owner: Handle, tag: &str) -> Vec<Handle> {
    w.custom
        .referenced(owner, tag)
        .iter()
        .map(|&h| if w.object(h).is_ok() { h } else { -1 })
        .collect()
}

/// `sim.setReferencedHandles(objectHandle, handles, tag='')`: replaces the list under the
/// tag; an empty list removes it. Every handle must name an object.
fn set_referenced_handles(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let owner = a.handle(0)?;
    w.object(owner)?;
    let Value::Array(items) = a.get(1) else {
        return Err(SimError::bad_argument("argument 2: a table of object handles"));
    };
    let mut handles = Vec::with_capacity(items.len());
    for (k, v) in items.iter().enumerate() {
        let h = v
            .as_i64()
            .ok_or_else(|| SimError::bad_argument(format!("argument 2: item {} is not a handle", k + 1)))?;
        w.object(h)?;
        handles.push(h);
    }
    let tag = tag(a, 2)?.to_owned();
    w.custom.set_referenced(owner, &tag, handles);
    Ok(Vec::new())
}

/// `sim.getReferencedHandles(objectHandle, tag='')` → the handles (an empty table when the
/// tag holds none).
fn get_referenced_handles(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let owner = a.handle(0)?;
    w.object(owner)?;
    let handles = live(w, owner, tag(a, 1)?);
    Ok(vec![Value::Array(handles.into_iter().map(Value::Int).collect())])
}

/// `sim.getReferencedHandle(objectHandle, tag='')` → the first handle under the tag, or
/// -1 when there is none.
fn get_referenced_handle(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let owner = a.handle(0)?;
    w.object(owner)?;
    let first = live(w, owner, tag(a, 1)?).first().copied().unwrap_or(-1);
    Ok(vec![Value::Int(first)])
}

/// `sim.getReferencedHandlesTags(objectHandle)` → the tags that hold handles, sorted.
fn get_referenced_handles_tags(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let owner = a.handle(0)?;
    w.object(owner)?;
    let tags = w.custom.referenced_tags(owner);
    Ok(vec![Value::Array(
        tags.into_iter().map(|t| Value::Str(t.to_owned())).collect(),
    )])
}
