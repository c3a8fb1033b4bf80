//! Sensors evaluated against the collision world: proximity sensors (the nearest point
//! within a ray, cone, pyramid, cylinder or disc volume) and batches of rays (laser
//! scanners, [`cast_rays`]).

mod proximity_volume;
mod rays;

pub use proximity_volume::{ProximityHit, ProximityVolume};
pub use rays::{MAX_RAYS, RayCastParams, RayHit, cast_rays};

use rapier3d::prelude::*;

use crate::error::SimError;
use crate::math::{self, Pose, Vec3};
use crate::scene::ProximityModel;
use crate::world::{Detection, Handle, ObjectKind, Physics, World};

impl From<&ProximityModel> for ProximityVolume {
    fn from(m: &ProximityModel) -> Self {
        match *m {
            ProximityModel::Ray { offset, range } => ProximityVolume::Ray {
                offset: offset as f32,
                range: range as f32,
            },
            ProximityModel::Cone {
                offset,
                range,
                half_angle,
            } => ProximityVolume::Cone {
                offset: offset as f32,
                range: range as f32,
                half_angle: half_angle as f32,
            },
            ProximityModel::Pyramid {
                offset,
                range,
                near_size,
                far_size,
            } => ProximityVolume::Pyramid {
                offset: offset as f32,
                range: range as f32,
                near_size: near_size.map(|w| w as f32),
                far_size: far_size.map(|w| w as f32),
            },
            ProximityModel::Cylinder {
                offset,
                range,
                radius,
                radius_far,
            } => ProximityVolume::Cylinder {
                offset: offset as f32,
                range: range as f32,
                radius: radius as f32,
                radius_far: radius_far as f32,
            },
            ProximityModel::Disc {
                offset,
                range,
                half_angle,
                thickness,
            } => ProximityVolume::Disc {
                offset: offset as f32,
                range: range as f32,
                half_angle: half_angle as f32,
                thickness: thickness as f32,
            },
        }
    }
}

/// Runs proximity sensor `h` against the current collision world, stores the result
/// in the object (`sim.readProximitySensor` reads it) and returns it.
///
/// # Errors
/// No such object, or not a proximity sensor.
pub fn handle_proximity_sensor(world: &mut World, h: Handle) -> Result<Option<Detection>, SimError> {
    let (volume, sensor_world) = sensor_volume(world, h)?;
    world.refresh_queries();
    let result = detect(world, world.physics(), h, &sensor_world, &volume);
    world.store_detection(h, result);
    Ok(result)
}

/// `sim.checkProximitySensor`: the nearest point of `shapes` inside sensor `h`'s volume,
/// without storing it (the sensor's last reading stays as it was). Each collider is
/// tested on its own, with no broad phase and no occlusion by other objects: the set is
/// small, unlike a handled sensor's whole scene. Detectability is the caller's choice
/// (an explicitly named shape is detected whatever its flag); the body the sensor is
/// mounted on is never detected, as in [`handle_proximity_sensor`].
///
/// # Errors
/// No such object, or not a proximity sensor.
pub fn check_proximity_sensor(world: &mut World, h: Handle, shapes: &[Handle]) -> Result<Option<Detection>, SimError> {
    let (volume, sensor_world) = sensor_volume(world, h)?;
    // Collider poses are only current after the query structures were refreshed (rapier
    // updates them when stepping, and scripts may have moved objects since).
    world.refresh_queries();
    let physics = world.physics();
    let volume = ProximityVolume::from(&volume);
    let own_body = mount_body(world, physics, h);
    let to_sensor = math::to_physics(&sensor_world.inverse());
    let mut best: Option<(ProximityHit, Handle)> = None;
    for &shape in shapes {
        for &ch in world.colliders_of(shape) {
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
                best = Some((hit, shape));
            }
        }
    }
    Ok(best.map(|(hit, object)| detection(hit, object)))
}

/// Handles every proximity sensor (the sensing phase of a step).
pub fn handle_all_proximity_sensors(world: &mut World) {
    for h in 0..world.len() as Handle {
        if matches!(world.object(h).map(|o| &o.kind), Ok(ObjectKind::ProximitySensor(_))) {
            let _ = handle_proximity_sensor(world, h);
        }
    }
}

/// Nearest detectable point in a sensor's volume, or `None`.
///
/// The body the sensor is mounted on is never detected: a sensor sees the world, not
/// its own robot (CoppeliaSim would report it when it pokes into the volume; BubbleRob's
/// nose sensor sits on its body's surface, where f32 contact noise would make that flicker).
fn detect(
    world: &World,
    physics: &Physics,
    sensor: Handle,
    sensor_world: &Pose,
    model: &ProximityModel,
) -> Option<Detection> {
    let volume = ProximityVolume::from(model);
    let own_body = mount_body(world, physics, sensor);
    let to_sensor = math::to_physics(&sensor_world.inverse());
    let aabb = volume.local_aabb().transform_by(&math::to_physics(sensor_world));
    let qp = physics.world.query_pipeline();
    let mut best: Option<(ProximityHit, Handle)> = None;
    for (ch, collider) in qp.intersect_aabb_conservative(aabb) {
        if own_body.is_some() && collider.parent() == own_body {
            continue;
        }
        let Some(owner) = world.collider_owner(ch) else {
            continue;
        };
        let detectable = matches!(&world.object(owner).map(|o| &o.kind), Ok(ObjectKind::Shape(s)) if s.detectable);
        if !detectable {
            continue;
        }
        let pose = to_sensor * *collider.position();
        if let Some(hit) = volume.detect(collider.shape(), &pose)
            && best.as_ref().is_none_or(|(b, _)| hit.distance < b.distance)
        {
            best = Some((hit, owner));
        }
    }
    best.map(|(hit, object)| detection(hit, object))
}

/// A hit in the sensor's frame as the world stores it.
fn detection(hit: ProximityHit, object: Handle) -> Detection {
    Detection {
        distance: f64::from(hit.distance),
        point: math::vec_from_physics(hit.point),
        object,
        normal: Vec3::from(math::vec_from_physics(hit.normal)),
    }
}

/// Proximity sensor `h`'s volume and world pose.
fn sensor_volume(world: &World, h: Handle) -> Result<(ProximityModel, Pose), SimError> {
    match world.object(h)? {
        o @ crate::world::Object {
            kind: ObjectKind::ProximitySensor(s),
            ..
        } => Ok((s.volume, o.world)),
        other => Err(SimError::WrongKind {
            handle: h,
            expected: "proximity sensor",
            actual: other.kind.name(),
        }),
    }
}

/// The rapier body an object rides on: its own, or the nearest ancestor's.
fn mount_body(world: &World, physics: &Physics, h: Handle) -> Option<RigidBodyHandle> {
    let mut cur = Some(h);
    while let Some(c) = cur {
        if let Some(&(bi, _)) = physics.body_of.get(&c) {
            return Some(physics.bodies[bi].handle);
        }
        cur = world.object(c).ok().and_then(|o| o.parent);
    }
    None
}
