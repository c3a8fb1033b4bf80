//! Named values attached to objects, kept with the world: a model's user parameters
//! (CoppeliaSim 4.0-4.2's `sim.getScriptSimulationParameter`), custom data blocks
//! (`sim.writeCustomDataBlock`) and referenced handles (4.7+'s
//! `sim.setReferencedHandles`). They are separate namespaces, as in CoppeliaSim, where a
//! user parameter and a data block of the same name never meet.

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
    /// Referenced handles by object and tag.
    referenced: BTreeMap<(Handle, String), Vec<Handle>>,
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

    /// The values of object `h`, by name.
    pub fn values_of(&self, h: Handle) -> impl Iterator<Item = (&str, &Value)> {
        self.values
            .range((h, String::new())..)
            .take_while(move |((o, _), _)| *o == h)
            .map(|((_, name), v)| (name.as_str(), v))
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

    /// The handles `owner` references under `tag` (empty when none).
    pub fn referenced(&self, owner: Handle, tag: &str) -> &[Handle] {
        self.referenced.get(&(owner, tag.to_owned())).map_or(&[], Vec::as_slice)
    }

    /// Sets the handles `owner` references under `tag`; an empty list removes the tag.
    pub fn set_referenced(&mut self, owner: Handle, tag: &str, handles: Vec<Handle>) {
        if handles.is_empty() {
            self.referenced.remove(&(owner, tag.to_owned()));
        } else {
            self.referenced.insert((owner, tag.to_owned()), handles);
        }
    }

    /// The tags under which `owner` references handles, in byte order.
    pub fn referenced_tags(&self, owner: Handle) -> Vec<&str> {
        self.referenced
            .range((owner, String::new())..)
            .take_while(|((o, _), _)| *o == owner)
            .map(|((_, tag), _)| tag.as_str())
            .collect()
    }

    /// Forgets everything attached to a removed object. Other objects' references to it
    /// stay, and read as -1 (what CoppeliaSim gives for a removed object).
    pub fn remove_object(&mut self, h: Handle) {
        self.values.retain(|(owner, _), _| *owner != h);
        self.clear_blocks(h);
        self.referenced.retain(|(owner, _), _| *owner != h);
    }
}
