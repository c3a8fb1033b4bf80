//! `sim.setLightParameters`, `sim.getLightParameters`: gantry's scenes have no light
//! objects (its renderers use fixed lighting, and the lights of a CoppeliaSim scene file
//! are imported as dummies), so no handle names a light and both functions say so
//! instead of pretending.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::error::SimError;
use crate::world::World;

/// The light functions.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "getLightParameters",
        call: ApiFn::World(light_parameters),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setLightParameters",
        call: ApiFn::World(light_parameters),
        cost: Cost::Quick,
    },
];

/// Both functions: an error naming the object and why it cannot be a light.
fn light_parameters(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let kind = w.object(h)?.kind.name();
    Err(SimError::refused(format!(
        "object {h} is a {kind}, not a light: gantry scenes have no light objects (its renderers use fixed lighting, and a CoppeliaSim scene's lights are imported as dummies)"
    )))
}
