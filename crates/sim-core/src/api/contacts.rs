//! `sim.getContactInfo`: the contact points of the last simulation step
//! ([`crate::world::World::contacts`]).

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::world::World;

/// The contact functions.
pub const FUNCTIONS: &[ApiFunction] = &[ApiFunction {
    name: "getContactInfo",
    call: ApiFn::World(get_contact_info),
    cost: Cost::Quick,
}];

/// `sim.handle_all`.
const HANDLE_ALL: i64 = -2;

/// `sim.getContactInfo(dynamicPass, objectHandle, index)` → `collidingObjects,
/// contactPoint, reactionForce, normalVector` for the `index`-th (from 0) contact point
/// of the last step involving `objectHandle` (any object for `sim.handle_all`), or
/// nothing past the last one. The object asked for comes first; the point is in the
/// world frame, the force is the one the contact applied to the first object (N) and
/// the normal points from the first object to the second. gantry steps its physics once
/// per simulation step, so `dynamicPass` is `sim.handle_all` or 0.
fn get_contact_info(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let pass = a.int(0)?;
    if pass != HANDLE_ALL && pass != 0 {
        return Err(SimError::bad_argument(format!(
            "argument 1: dynamicPass must be sim.handle_all or 0 (gantry has one pass per step), got {pass}"
        )));
    }
    let h = a.handle(1)?;
    if h != HANDLE_ALL {
        w.object(h)?;
    }
    let index = a.int(2)?;
    let Some(c) = usize::try_from(index).ok().and_then(|i| w.contacts(h).get(i).copied()) else {
        if index < 0 {
            return Err(SimError::bad_argument(format!(
                "argument 3: index must be 0 or more, got {index}"
            )));
        }
        return Ok(Vec::new());
    };
    let (objects, force, normal) = if h != HANDLE_ALL && c.objects[1] == h && c.objects[0] != h {
        ([c.objects[1], c.objects[0]], -c.force, -c.normal)
    } else {
        (c.objects, c.force, c.normal)
    };
    Ok(vec![
        Value::Array(objects.iter().map(|&o| Value::Int(o)).collect()),
        Value::floats(c.point.as_slice()),
        Value::floats(force.as_slice()),
        Value::floats(normal.as_slice()),
    ])
}
