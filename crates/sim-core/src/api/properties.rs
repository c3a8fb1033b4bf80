//! `sim.getModelProperty`, `sim.setModelProperty`, `sim.getObjectProperty`,
//! `sim.setObjectProperty`, `sim.getObjectSpecialProperty`,
//! `sim.setObjectSpecialProperty`: CoppeliaSim's property flags on objects
//! ([`crate::world::model_property`] says which of them gantry acts on).

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::world::World;

/// The functions of this file, sorted by name.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "getModelProperty",
        call: ApiFn::World(get_model_property),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectProperty",
        call: ApiFn::World(get_object_property),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectSpecialProperty",
        call: ApiFn::World(get_object_special_property),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setModelProperty",
        call: ApiFn::World(set_model_property),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setObjectProperty",
        call: ApiFn::World(set_object_property),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setObjectSpecialProperty",
        call: ApiFn::World(set_object_special_property),
        cost: Cost::Quick,
    },
];

/// `sim.getModelProperty(objectHandle)` → the object's own override flags, with
/// `sim.modelproperty_not_model` set when it is no model base.
fn get_model_property(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Int(w.model_property(a.handle(0)?)?)])
}

/// `sim.setModelProperty(objectHandle, property)`: `sim.modelproperty_not_dynamic`
/// makes every shape of the model static from the next step (cleared, they are
/// simulated again), `sim.modelproperty_not_respondable` takes them out of contacts,
/// and `sim.modelproperty_not_model` makes the object no model base.
fn set_model_property(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    w.set_model_property(a.handle(0)?, a.int(1)?)?;
    Ok(Vec::new())
}

/// `sim.getObjectProperty(objectHandle)` → the `sim.objectproperty_*` flags.
fn get_object_property(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Int(w.object_property(a.handle(0)?)?)])
}

/// `sim.setObjectProperty(objectHandle, property)`: editor flags, kept.
fn set_object_property(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    w.set_object_property(a.handle(0)?, a.int(1)?)?;
    Ok(Vec::new())
}

/// `sim.getObjectSpecialProperty(objectHandle)` → the `sim.objectspecialproperty_*`
/// flags (a shape is collidable, measurable, detectable and renderable until set).
fn get_object_special_property(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Int(w.special_property(a.handle(0)?)?)])
}

/// `sim.setObjectSpecialProperty(objectHandle, property)`: kept and reported back.
fn set_object_special_property(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    w.set_special_property(a.handle(0)?, a.int(1)?)?;
    Ok(Vec::new())
}
