//! Custom data blocks: `sim.writeCustomDataBlock`, `sim.readCustomDataBlock`,
//! `sim.readCustomDataBlockTags`, and CoppeliaSim 4.7's property spelling of the same
//! blocks, `sim.setBufferProperty`/`sim.getBufferProperty` on `customData.<tag>`.
//!
//! A block is named data attached to an object, or to the scene with
//! `sim.handle_scene`, stored in [`World::custom`](crate::world::World) apart from user
//! parameters. Data are text or bytes and read back as written. Blocks of a removed
//! object go with it.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::world::{Handle, World};

/// `sim.handle_scene`: the scene's own blocks.
const HANDLE_SCENE: Handle = -12;

/// The functions this file implements, in alphabetical order.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "getBufferProperty",
        call: ApiFn::World(get_buffer_property),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "readCustomDataBlock",
        call: ApiFn::World(read_custom_data_block),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "readCustomDataBlockTags",
        call: ApiFn::World(read_custom_data_block_tags),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setBufferProperty",
        call: ApiFn::World(set_buffer_property),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "writeCustomDataBlock",
        call: ApiFn::World(write_custom_data_block),
        cost: Cost::Quick,
    },
];

/// The custom-data tag a property name designates: `customData.<tag>`.
fn custom_data_tag<'a>(a: &Args<'a>, i: usize) -> Result<&'a str, SimError> {
    let name = a.str(i)?;
    match name.strip_prefix("customData.") {
        Some(tag) if !tag.is_empty() => Ok(tag),
        _ => Err(SimError::bad_argument(format!(
            "argument {}: gantry's buffer properties are the custom data blocks, 'customData.<tag>', not '{name}'",
            i + 1
        ))),
    }
}

/// `sim.setBufferProperty(target, 'customData.<tag>', data, options={})`: the block
/// `tag` of the object (or `sim.handle_scene`), as `sim.writeCustomDataBlock`; empty
/// data removes it.
fn set_buffer_property(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = owner(w, a, 0)?;
    let tag = custom_data_tag(a, 1)?;
    let data = match a.get(2) {
        v @ (Value::Str(_) | Value::Bytes(_)) => v.clone(),
        other => {
            return Err(SimError::bad_argument(format!(
                "argument 3: expected a buffer, got {}",
                other.type_name()
            )));
        }
    };
    w.custom.write_block(h, tag, data);
    Ok(Vec::new())
}

/// `sim.getBufferProperty(target, 'customData.<tag>', options={})` → the data; a
/// missing block is an error, or nil with `options.noError`.
fn get_buffer_property(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = owner(w, a, 0)?;
    let tag = custom_data_tag(a, 1)?;
    let no_error = matches!(a.get(2).get("noError"), Some(Value::Bool(true)));
    match w.custom.block(h, tag) {
        Some(v) => Ok(vec![v.clone()]),
        None if no_error => Ok(vec![Value::Nil]),
        None => Err(SimError::no_such_item(format!(
            "property 'customData.{tag}' does not exist"
        ))),
    }
}

/// Argument `i` as the owner of blocks: an existing object or `sim.handle_scene`.
fn owner(w: &World, a: &Args<'_>, i: usize) -> Result<Handle, SimError> {
    let h = a.handle(i)?;
    if h != HANDLE_SCENE {
        w.object(h)?;
    }
    Ok(h)
}

/// `sim.writeCustomDataBlock(objectHandle, tagName, data)`: stores `data` (text or
/// bytes) under `tagName`. Empty or nil data deletes the block; an empty `tagName`
/// deletes every block of the object.
fn write_custom_data_block(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = owner(w, a, 0)?;
    let tag = a.str(1)?;
    let data = match a.get(2) {
        v @ (Value::Str(_) | Value::Bytes(_) | Value::Nil) => v.clone(),
        other => {
            return Err(SimError::bad_argument(format!(
                "argument 3: expected string or buffer, got {}",
                other.type_name()
            )));
        }
    };
    if tag.is_empty() {
        w.custom.clear_blocks(h);
    } else {
        w.custom.write_block(h, tag, data);
    }
    Ok(Vec::new())
}

/// `sim.readCustomDataBlock(objectHandle, tagName)` → the data as written, or nil.
fn read_custom_data_block(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = owner(w, a, 0)?;
    let tag = a.str(1)?;
    Ok(vec![w.custom.block(h, tag).cloned().unwrap_or(Value::Nil)])
}

/// `sim.readCustomDataBlockTags(objectHandle)` → the tags as a table of strings (empty
/// when the object has no block), in byte order.
fn read_custom_data_block_tags(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = owner(w, a, 0)?;
    let tags = w.custom.block_tags(h).into_iter().map(Value::from).collect();
    Ok(vec![Value::Array(tags)])
}
