//! CoppeliaSim's property flags on objects: model properties (`sim.setModelProperty`),
//! object properties (`sim.setObjectProperty`) and object special properties
//! (`sim.setObjectSpecialProperty`).
//!
//! Model properties are overrides: a flag set on a model base applies to everything
//! below it, and an object's effective flags are its own OR'ed with those of every model
//! above it (CoppeliaSim's "cumulative" model property). gantry acts on the two that
//! change the physics: `not_dynamic` makes the model's shapes static (what V-REP 3
//! scripts toggle to move a robot kinematically) and `not_respondable` takes them out
//! of contacts. The others (visibility, detection, rendering, collision and distance
//! checks) and the object and special properties are kept and reported back, so
//! scripts that read, combine and write them work; gantry's sensors and checks do not
//! consult them (docs/api-notes.md).

use super::World;
use super::object::{Handle, ObjectKind};
use crate::error::SimError;

use super::property_flags::{model_property, object_special_property};
use model_property::{NOT_DYNAMIC, NOT_MODEL, NOT_RESPONDABLE, OVERRIDES};

impl World {
    /// An object's own model property (`sim.getModelProperty`): its override flags, with
    /// `sim.modelproperty_not_model` set when it is no model base.
    ///
    /// # Errors
    /// No such object.
    pub fn model_property(&self, h: Handle) -> Result<i64, SimError> {
        let o = self.object(h)?;
        let own = self.edit.model_props.get(&h).copied().unwrap_or(0);
        Ok(if o.model_base { own } else { own | NOT_MODEL })
    }

    /// Sets an object's model property (`sim.setModelProperty`). Any
    /// `sim.modelproperty_not_model` bit makes the object no model base, none makes it
    /// one. A change of `not_dynamic` or `not_respondable` rebuilds the physics of the
    /// object's subtree at once, so the model falls, or stops, from the next step.
    ///
    /// # Errors
    /// No such object, or bits CoppeliaSim does not define.
    pub fn set_model_property(&mut self, h: Handle, property: i64) -> Result<(), SimError> {
        self.object(h)?;
        if property & !(OVERRIDES | NOT_MODEL) != 0 {
            return Err(SimError::BadArgument(format!(
                "model property {property:#x} has bits sim.modelproperty_* does not define"
            )));
        }
        let before = self.cumulative_model_property(h);
        let flags = property & OVERRIDES;
        if flags == 0 {
            self.edit.model_props.remove(&h);
        } else {
            self.edit.model_props.insert(h, flags);
        }
        self.objects[h as usize].model_base = property & NOT_MODEL == 0;
        let physics = NOT_DYNAMIC | NOT_RESPONDABLE;
        if (before ^ self.cumulative_model_property(h)) & physics != 0 {
            self.rebuild_physics(&[h]);
        }
        self.bump();
        Ok(())
    }

    /// An object's effective override flags: its own model property OR'ed with that of
    /// every object above it.
    pub fn cumulative_model_property(&self, h: Handle) -> i64 {
        cumulative(
            &self.edit.model_props,
            |x| self.objects.get(x as usize).and_then(|o| o.parent),
            h,
        )
    }

    /// An object's property flags (`sim.getObjectProperty`), 0 unless set.
    ///
    /// # Errors
    /// No such object.
    pub fn object_property(&self, h: Handle) -> Result<i64, SimError> {
        self.object(h)?;
        Ok(self.edit.object_props.get(&h).copied().unwrap_or(0))
    }

    /// Sets an object's property flags (`sim.setObjectProperty`); they concern
    /// CoppeliaSim's editor (selection, collapsing) and are kept and reported back.
    ///
    /// # Errors
    /// No such object, or a negative value.
    pub fn set_object_property(&mut self, h: Handle, property: i64) -> Result<(), SimError> {
        self.object(h)?;
        if property < 0 {
            return Err(SimError::BadArgument(format!("object property {property} is negative")));
        }
        self.edit.object_props.insert(h, property);
        Ok(())
    }

    /// An object's special property flags (`sim.getObjectSpecialProperty`): what it was
    /// given, else for a shape its scene flags (collidable, measurable, detectable) and
    /// renderable, and nothing for other objects.
    ///
    /// # Errors
    /// No such object.
    pub fn special_property(&self, h: Handle) -> Result<i64, SimError> {
        use object_special_property::{COLLIDABLE, DETECTABLE_ALL, MEASURABLE, RENDERABLE};
        let o = self.object(h)?;
        let default = match &o.kind {
            ObjectKind::Shape(s) => {
                let flag = |on: bool, bit: i64| if on { bit } else { 0 };
                flag(s.collidable, COLLIDABLE)
                    | flag(s.measurable, MEASURABLE)
                    | flag(s.detectable, DETECTABLE_ALL)
                    | RENDERABLE
            }
            _ => 0,
        };
        Ok(self.edit.special_props.get(&h).copied().unwrap_or(default))
    }

    /// Sets an object's special property flags (`sim.setObjectSpecialProperty`).
    ///
    /// # Errors
    /// No such object, or a negative value.
    pub fn set_special_property(&mut self, h: Handle, property: i64) -> Result<(), SimError> {
        self.object(h)?;
        if property < 0 {
            return Err(SimError::BadArgument(format!(
                "object special property {property} is negative"
            )));
        }
        self.edit.special_props.insert(h, property);
        Ok(())
    }
}

impl World {
    /// A parameter kept only to be read back (see `EditState::stored_params`): what
    /// [`World::set_stored_param`] last set, if anything.
    ///
    /// # Errors
    /// No such object.
    pub fn stored_param(&self, h: Handle, id: i64) -> Result<Option<i64>, SimError> {
        self.object(h)?;
        Ok(self.edit.stored_params.get(&(h, id)).copied())
    }

    /// Keeps a parameter that changes nothing in gantry's simulation, so that it reads
    /// back; `None` forgets it.
    ///
    /// # Errors
    /// No such object.
    pub fn set_stored_param(&mut self, h: Handle, id: i64, value: Option<i64>) -> Result<(), SimError> {
        self.object(h)?;
        match value {
            Some(v) => self.edit.stored_params.insert((h, id), v),
            None => self.edit.stored_params.remove(&(h, id)),
        };
        Ok(())
    }
}

/// `h`'s own flags in `own` OR'ed with those of its ancestors.
pub(super) fn cumulative(
    own: &std::collections::HashMap<Handle, i64>,
    parent: impl Fn(Handle) -> Option<Handle>,
    h: Handle,
) -> i64 {
    if own.is_empty() {
        return 0;
    }
    let mut flags = 0;
    let mut cur = Some(h);
    while let Some(x) = cur {
        flags |= own.get(&x).copied().unwrap_or(0);
        cur = parent(x);
    }
    flags
}
