//! Dummy links (`sim.setLinkDummy`): two dummies whose frames the physics holds
//! together, CoppeliaSim's dynamic loop closure (suction pads, attachments, closed
//! chains).

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::world::World;

/// The functions of this file, in alphabetical order.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "getLinkDummy",
        call: ApiFn::World(get_link_dummy),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setLinkDummy",
        call: ApiFn::World(set_link_dummy),
        cost: Cost::Quick,
    },
];

/// `sim.setLinkDummy(dummyHandle, linkedDummyHandle)`: links the two dummies (-1
/// unlinks); a dummy has at most one link, so linking replaces any earlier one.
fn set_link_dummy(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let dummy = a.handle(0)?;
    let linked = a.int(1)?;
    w.set_link_dummy(dummy, (linked >= 0).then_some(linked))?;
    Ok(Vec::new())
}

/// `sim.getLinkDummy(dummyHandle)` → the linked dummy, or -1.
fn get_link_dummy(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let dummy = a.handle(0)?;
    w.object(dummy)?;
    Ok(vec![Value::Int(w.linked_dummy(dummy).unwrap_or(-1))])
}
