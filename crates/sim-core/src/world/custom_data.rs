//! Named values attached to objects, kept with the world: a model's user parameters
//! (CoppeliaSim 4.0-4.2's `sim.getScriptSimulationParameter`) and custom data blocks
//! (`sim.writeCustomDataBlock`). The two are separate namespaces, as in CoppeliaSim,
//! where a user parameter and a data block of the same name never meet.

use std::collections::BTreeMap;

use crate::Value;
use crate::world::Handle;

/// Values by object and name.
#[derive(Debug, Clone, Default)]
pub struct CustomData {
    values: BTreeMap<(Handle, String), Value>,
    /// Data blocks, as [`Value::Str`] or [`Value::Bytes`]: a block reads back with the
    /// type it was written with, so Lua text stays a string and a buffer a buffer.
    blocks: BTreeMap<(Handle, String), Value>,
}

impl CustomData {
    /// The value `name` of object `h`, if set.
    pub fn get(&self, h: Handle, name: &str) -> Option<&Value> {
        self.values.get(&(h, name.to_owned()))
    }

    /// Sets (or, with `Value::Nil`, clears) the value `name` of object `h`.
    pub fn set(&mut self, h: Handle, name: &str, value: Value) {
        if value == Value::Nil {
            self.values.remove(&(h, name.to_owned()));
        } else {
            self.values.insert((h, name.to_owned()), value);
        }
    }

    /// The data block `tag` of `owner` (an object, or `sim.handle_scene`), if written.
    pub fn block(&self, owner: Handle, tag: &str) -> Option<&Value> {
        self.blocks.get(&(owner, tag.to_owned()))
    }

    /// Writes the data block `tag` of `owner`. `data` is text or bytes; empty data or
    /// `Value::Nil` deletes the block (CoppeliaSim stores no empty block).
    pub fn write_block(&mut self, owner: Handle, tag: &str, data: Value) {
        let empty = match &data {
            Value::Str(s) => s.is_empty(),
            Value::Bytes(b) => b.is_empty(),
            _ => true,
        };
        if empty {
            self.blocks.remove(&(owner, tag.to_owned()));
        } else {
            self.blocks.insert((owner, tag.to_owned()), data);
        }
    }

    /// Deletes every data block of `owner`.
    pub fn clear_blocks(&mut self, owner: Handle) {
        self.blocks.retain(|(o, _), _| *o != owner);
    }

    /// The tags of `owner`'s data blocks, in byte order of the names.
    pub fn block_tags(&self, owner: Handle) -> Vec<&str> {
        self.blocks
            .range((owner, String::new())..)
            .take_while(|((o, _), _)| *o == owner)
            .map(|((_, tag), _)| tag.as_str())
            .collect()
    }

    /// Forgets everything attached to a removed object.
    pub fn remove_object(&mut self, h: Handle) {
        self.values.retain(|(owner, _), _| *owner != h);
        self.clear_blocks(h);
    }
}
