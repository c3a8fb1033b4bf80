//! `sim.getConfigurationTree`, `sim.setConfigurationTree`: save the local poses and
//! joint positions of an object's subtree (or the whole scene) as bytes, and put them
//! back later, as PyRep does to reset a task. The blob is gantry's own (see
//! `world::configuration`); only a round trip is promised.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::world::{Handle, World};

/// `sim.handle_scene`: the whole scene.
const HANDLE_SCENE: Handle = -12;

/// The configuration tree functions, sorted by name.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "getConfigurationTree",
        call: ApiFn::World(get_configuration_tree),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setConfigurationTree",
        call: ApiFn::World(set_configuration_tree),
        cost: Cost::Quick,
    },
];

/// `sim.getConfigurationTree(objectHandle)` → bytes: the local pose of the object and of
/// every object below it, and the joints' positions; `sim.handle_scene` for the whole
/// scene.
fn get_configuration_tree(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let root = (h != HANDLE_SCENE).then_some(h);
    Ok(vec![Value::Bytes(w.configuration_tree(root)?)])
}

/// `sim.setConfigurationTree(data)`: puts back what `sim.getConfigurationTree` returned,
/// with the restored part's dynamics restarted at rest. Bytes that are not such a tree
/// (or name objects removed since) are refused and change nothing.
fn set_configuration_tree(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    w.set_configuration_tree(&a.bytes(0)?)?;
    Ok(Vec::new())
}
