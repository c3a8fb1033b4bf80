//! `sim.checkProximitySensor`: a proximity sensor's detection restricted to one entity.

use super::{ApiError, ApiFn, ApiFunction, Args, CallContext, Ret};
use crate::Value;
use crate::math::{self, Vec3};
use crate::sensor::ProximityVolume;
use crate::world::{Detection, FIRST_COLLECTION_HANDLE, Handle, ObjectKind, World};

/// The functions this file implements, in alphabetical order.
pub(super) const FUNCTIONS: &[ApiFunction] = &[ApiFunction {
    name: "checkProximitySensor",
    call: ApiFn::World(check_proximity_sensor),
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
pub(super) fn check_proximity_sensor(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, ApiError> {
    let sensor = a.handle(0)?;
    let entity = a.handle(1)?;
    let volume = match &w.object(sensor)?.kind {
        ObjectKind::ProximitySensor(s) => ProximityVolume::from(&s.volume),
        other => {
            return Err(ApiError::new(format!(
                "object {sensor} is a {}, not a proximity sensor",
                other.name()
            )));
        }
    };
    let shapes = entity_shapes(w, entity)?;
    // Collider poses are only current after the query structures were refreshed (rapier
    // updates them when stepping, and scripts may have moved objects since).
    w.refresh_queries();
    Ok(match nearest(w, sensor, &volume, &shapes) {
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
fn entity_shapes(w: &World, entity: Handle) -> Result<Vec<Handle>, ApiError> {
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

/// The nearest point of `shapes` inside the sensor's volume. Each collider is tested
/// directly (no broad phase): the set is small, unlike a handled sensor's whole scene.
fn nearest(w: &World, sensor: Handle, volume: &ProximityVolume, shapes: &[Handle]) -> Option<Detection> {
    let physics = w.physics();
    let own_body = mount_body(w, sensor);
    let to_sensor = math::to_physics(&w.object(sensor).ok()?.world.inverse());
    let mut best: Option<(crate::sensor::ProximityHit, Handle)> = None;
    for &h in shapes {
        for &ch in w.colliders_of(h) {
            let Some(collider) = physics.world.colliders.get(ch) else {
                continue;
            };
            if own_body.is_some() && collider.parent() == own_body {
                continue;
            }
            let pose = to_sensor * *collider.position();
            if let Some(hit) = volume.detect(collider.shape(), &pose)
                && best.as_ref().is_none_or(|(b, _)| hit.distance < b.distance)
            {
                best = Some((hit, h));
            }
        }
    }
    best.map(|(hit, object)| Detection {
        distance: f64::from(hit.distance),
        point: math::vec_from_physics(hit.point),
        object,
        normal: Vec3::from(math::vec_from_physics(hit.normal)),
    })
}

/// The rapier body the sensor rides on: its own, or the nearest ancestor's.
fn mount_body(w: &World, h: Handle) -> Option<crate::rapier3d::prelude::RigidBodyHandle> {
    let physics = w.physics();
    let mut cur = Some(h);
    while let Some(c) = cur {
        if let Some(&(bi, _)) = physics.body_of.get(&c) {
            return physics.bodies.get(bi).map(|b| b.handle);
        }
        cur = w.object(c).ok().and_then(|o| o.parent);
    }
    None
}
