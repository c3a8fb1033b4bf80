//! `sim.groupShapes`, `sim.ungroupShape`: making one compound shape of several and
//! splitting it again ([`crate::world::World::group_shapes`]).

use super::scene::handle_list;
use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::sim::Sim;

/// The grouping functions.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "groupShapes",
        call: ApiFn::Sim(group_shapes),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "ungroupShape",
        call: ApiFn::Sim(ungroup_shape),
        cost: Cost::Quick,
    },
];

/// `sim.groupShapes(shapeHandles, merge=false)` → the compound's handle. The shapes are
/// removed; the compound has the last shape's frame, alias and parent and the sum of
/// their masses. With `merge`, CoppeliaSim fuses the meshes into one; gantry keeps the
/// parts (its primitives stay exact), so a merged shape is a compound here too.
fn group_shapes(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let handles = handle_list(a, 0)?;
    a.opt_bool(1, false)?;
    let group = sim.world.group_shapes(&handles)?;
    sim.forget_removed();
    Ok(vec![Value::Int(group)])
}

/// `sim.ungroupShape(shapeHandle)` → the handles of the shapes the compound splits
/// into, one per part; a simple shape gives its own handle.
fn ungroup_shape(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let parts = sim.world.ungroup_shape(a.handle(0)?)?;
    sim.forget_removed();
    Ok(vec![Value::Array(parts.into_iter().map(Value::Int).collect())])
}
