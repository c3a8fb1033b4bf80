//! Proximity and force sensors, collections, distance and collision checks.

use super::{Args, CallContext, Ret};
use crate::Value;
use crate::error::SimError;
use crate::world::{Collection, CollectionItem, FIRST_COLLECTION_HANDLE, ItemKind, ObjectKind, World};

fn detection_values(last: Option<Option<crate::world::Detection>>) -> Ret {
    match last {
        Some(Some(d)) => vec![
            Value::Int(1),
            Value::Float(d.distance),
            Value::floats(d.point.as_slice()),
            Value::Int(d.object),
            Value::floats(d.normal.as_slice()),
        ],
        // Always five values (4.3+), so callers can unpack them unconditionally:
        // 0 when nothing was detected, -1 before the sensor was ever handled.
        other => vec![
            Value::Int(if other.is_some() { 0 } else { -1 }),
            Value::Float(0.0),
            Value::floats(&[0.0; 3]),
            Value::Int(-1),
            Value::floats(&[0.0; 3]),
        ],
    }
}

/// `sim.readProximitySensor(h)` → `res, dist, point, obj, normal` from the last handling.
/// Point and normal are in the sensor frame.
pub(super) fn read_proximity_sensor(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    match &w.object(h)?.kind {
        ObjectKind::ProximitySensor(s) => Ok(detection_values(s.last)),
        other => Err(SimError::WrongKind {
            handle: h,
            expected: "proximity sensor",
            actual: other.name(),
        }),
    }
}

/// `sim.handleProximitySensor(h)` → same as read, after sensing now. `sim.handle_all`
/// handles every sensor and returns the first one's result shape with zeros.
pub(super) fn handle_proximity_sensor(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    if h == -2 || h == -3 {
        crate::sensor::handle_all_proximity_sensors(w);
        return Ok(detection_values(Some(None)));
    }
    let d = crate::sensor::handle_proximity_sensor(w, h)?;
    Ok(detection_values(Some(d)))
}

/// `sim.readForceSensor(h)` → `result, [fx, fy, fz], [tx, ty, tz]` (N, N·m, sensor frame).
/// `result` bit 0 is set once a reading exists.
pub(super) fn read_force_sensor(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    match &w.object(h)?.kind {
        ObjectKind::ForceSensor(r) => Ok(vec![
            Value::Int(i64::from(r.valid)),
            Value::floats(r.force.as_slice()),
            Value::floats(r.torque.as_slice()),
        ]),
        other => Err(SimError::WrongKind {
            handle: h,
            expected: "force sensor",
            actual: other.name(),
        }),
    }
}

/// `sim.createCollection(options=0)` → collection handle, or V-REP 3's
/// `sim.createCollection(name, options)`, whose name `sim.getCollectionHandle` finds.
/// Names are unique among live collections, as in V-REP.
pub(super) fn create_collection(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let name = match a.get(0) {
        Value::Str(name) => {
            a.opt_int(1, 0)?;
            if w.collection_named(name).is_some() {
                return Err(SimError::bad_argument(format!(
                    "argument 1: a collection named '{name}' already exists"
                )));
            }
            name.clone()
        }
        _ => {
            a.opt_int(0, 0)?;
            String::new()
        }
    };
    w.collections.push(Some(Collection {
        name,
        items: Vec::new(),
    }));
    Ok(vec![Value::Int(
        FIRST_COLLECTION_HANDLE + w.collections.len() as i64 - 1,
    )])
}

/// `sim.getCollectionHandle(name)` (V-REP 3, 4.0-4.2) → the handle of the collection
/// created with that name; with the `@silentError` suffix, -1 when there is none.
pub(super) fn get_collection_handle(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let raw = a.str(0)?;
    let (name, silent) = match raw.strip_suffix("@silentError") {
        Some(n) => (n, true),
        None => (raw, false),
    };
    match w.collection_named(name) {
        Some(h) => Ok(vec![Value::Int(h)]),
        None if silent => Ok(vec![Value::Int(-1)]),
        None => Err(SimError::no_such_item(format!("collection does not exist: '{name}'"))),
    }
}

/// `sim.getCollectionName(collectionHandle)` (V-REP 3, 4.0-4.2) → the collection's
/// name; an unnamed collection (`sim.createCollection(options)`) has the empty name.
pub(super) fn get_collection_name(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    match w.collection(h) {
        Some(c) => Ok(vec![Value::Str(c.name.clone())]),
        None => Err(SimError::no_such_item(format!("collection {h} does not exist"))),
    }
}

/// `sim.destroyCollection(h)`.
pub(super) fn destroy_collection(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let slot = usize::try_from(h - FIRST_COLLECTION_HANDLE)
        .ok()
        .and_then(|i| w.collections.get_mut(i));
    match slot {
        Some(c @ Some(_)) => {
            *c = None;
            Ok(Vec::new())
        }
        _ => Err(SimError::no_such_item(format!("collection {h} does not exist"))),
    }
}

/// `sim.addItemToCollection(coll, what, obj, options)`: `what` is `sim.handle_single`,
/// `handle_all`, `handle_tree` or `handle_chain`; options bit 0 removes instead of adds,
/// bit 1 leaves out the tree base / chain tip.
/// `sim.getCollectionObjects(collectionHandle)` → the handles of the objects the
/// collection holds now, in handle order.
pub(super) fn get_collection_objects(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let handles = w.collection_objects(a.handle(0)?)?;
    Ok(vec![Value::Array(handles.into_iter().map(Value::Int).collect())])
}

pub(super) fn add_item_to_collection(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let c = a.handle(0)?;
    let kind = match a.int(1)? {
        -8 => ItemKind::Single,
        -2 => ItemKind::All,
        -6 => ItemKind::Tree,
        -7 => ItemKind::Chain,
        other => {
            return Err(SimError::bad_argument(format!(
                "argument 2: {other} is not sim.handle_single, handle_all, handle_tree or handle_chain"
            )));
        }
    };
    let object = a.opt_int(2, -1)?;
    if kind != ItemKind::All {
        w.object(object)?;
    }
    let options = a.opt_int(3, 0)?;
    let slot = usize::try_from(c - FIRST_COLLECTION_HANDLE)
        .ok()
        .and_then(|i| w.collections.get_mut(i));
    let Some(Some(coll)) = slot else {
        return Err(SimError::no_such_item(format!("collection {c} does not exist")));
    };
    coll.items.push(CollectionItem {
        kind,
        object,
        remove: options & 1 != 0,
        exclude_base: options & 2 != 0,
    });
    Ok(Vec::new())
}

/// `sim.checkDistance(e1, e2, threshold=0)` → `result, [p1, p2, d], [obj1, obj2]`
/// with world-frame points. `e2 = sim.handle_all` means every measurable shape not in e1.
/// A threshold (metres) of 0 or less, or infinite, means none; NaN is refused rather
/// than silently read as "none".
pub(super) fn check_distance(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let threshold = a.opt_f64(2, 0.0)?;
    if threshold.is_nan() {
        return Err(SimError::bad_argument(
            "argument 3: the threshold must be a number, got NaN",
        ));
    }
    w.refresh_queries();
    let set1 = w.entity_shapes(a.handle(0)?, &[])?;
    let set2 = w.entity_shapes(a.handle(1)?, &set1)?;
    Ok(match w.distance(&set1, &set2, threshold) {
        Some(r) => vec![
            Value::Int(1),
            Value::floats(&[r.p1.x, r.p1.y, r.p1.z, r.p2.x, r.p2.y, r.p2.z, r.distance]),
            Value::Array(vec![Value::Int(r.objects[0]), Value::Int(r.objects[1])]),
        ],
        None => vec![
            Value::Int(0),
            Value::floats(&[0.0; 7]),
            Value::Array(vec![Value::Int(-1), Value::Int(-1)]),
        ],
    })
}

/// `sim.checkCollision(e1, e2)` → `result, [obj1, obj2]`.
pub(super) fn check_collision(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    w.refresh_queries();
    let set1 = w.entity_collidables(a.handle(0)?, &[])?;
    let set2 = w.entity_collidables(a.handle(1)?, &set1)?;
    Ok(match w.collision(&set1, &set2) {
        Some([x, y]) => vec![Value::Int(1), Value::Array(vec![Value::Int(x), Value::Int(y)])],
        None => vec![Value::Int(0), Value::Array(vec![Value::Int(-1), Value::Int(-1)])],
    })
}
