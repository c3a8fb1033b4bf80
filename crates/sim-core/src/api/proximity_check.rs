//! `sim.checkProximitySensor`: a proximity sensor's detection restricted to one entity.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::sensor;
use crate::world::{FIRST_COLLECTION_HANDLE, Handle, ObjectKind, World};

/// The functions this file implements, in alphabetical order.
pub(super) const FUNCTIONS: &[ApiFunction] = &[ApiFunction {
    name: "checkProximitySensor",
    call: ApiFn::World(check_proximity_sensor),
    cost: Cost::Long,
}];

/// `sim.handle_all`.
const HANDLE_ALL: Handle = -2;

/// `sim.checkProximitySensor(sensor, entity)` → `res, dist, point, obj, normal`, the shape
/// of `sim.readProximitySensor` (point and normal in the sensor frame, m): the nearest
/// point of `entity` (an object, a collection, or `sim.handle_all`) inside the sensor's
/// volume, `res` 1 if there is one and 0 otherwise.
///
/// As CoppeliaSim's, the check is silent: the sensor's last reading
/// (`sim.readProximitySensor`) is left as it was. Other objects do not occlude the entity
/// (each shape is tested on its own). An explicitly named shape is detected whatever its
/// `detectable` flag; the members of a collection or of `sim.handle_all` only when
/// detectable, as in `sim.handleProximitySensor`. The shapes of the body the sensor is
/// mounted on are never detected, as for handled sensors.
pub(super) fn check_proximity_sensor(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let sensor = a.handle(0)?;
    let entity = a.handle(1)?;
    let shapes = entity_shapes(w, entity)?;
    Ok(match sensor::check_proximity_sensor(w, sensor, &shapes)? {
        Some(d) => vec![
            Value::Int(1),
            Value::Float(d.distance),
            Value::floats(d.point.as_slice()),
            Value::Int(d.object),
            Value::floats(d.normal.as_slice()),
        ],
        // All five values even when nothing is seen, as `readProximitySensor` (4.3+), so
        // callers that unpack them do not get nils.
        None => vec![
            Value::Int(0),
            Value::Float(0.0),
            Value::floats(&[0.0; 3]),
            Value::Int(-1),
            Value::floats(&[0.0; 3]),
        ],
    })
}

/// The shapes an entity stands for: the object itself, or the detectable shapes of a
/// collection or of the whole scene.
fn entity_shapes(w: &World, entity: Handle) -> Result<Vec<Handle>, SimError> {
    let detectable = |h: &Handle| matches!(w.object(*h).map(|o| &o.kind), Ok(ObjectKind::Shape(s)) if s.detectable);
    Ok(if entity == HANDLE_ALL {
        w.handles().iter().copied().filter(detectable).collect()
    } else if entity >= FIRST_COLLECTION_HANDLE {
        w.collection_objects(entity)?.into_iter().filter(detectable).collect()
    } else {
        w.object(entity)?;
        vec![entity]
    })
}
