//! Named values attached to objects: a model's user parameters (CoppeliaSim 4.0-4.2's
//! `sim.getScriptSimulationParameter`), kept with the world so a stop restores them.

use std::collections::BTreeMap;

use crate::Value;
use crate::world::Handle;

/// Values by object and name.
#[derive(Debug, Clone, Default)]
pub struct CustomData {
    values: BTreeMap<(Handle, String), Value>,
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

    /// Forgets everything attached to a removed object.
    pub fn remove_object(&mut self, h: Handle) {
        self.values.retain(|(owner, _), _| *owner != h);
    }
}
