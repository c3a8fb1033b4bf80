//! Batch ray casts against the scene's collision geometry (`sim.castRays`): the direct
//! path to a laser scanner, with no image rendered in between.
//!
//! Rays start at the origin of a frame object and run along directions given in that
//! object's frame; each reports the distance to its first hit along the ray, in metres,
//! and the shape hit. They see exactly what rapier collides with (the colliders, not the
//! visuals): a cylinder is a true cylinder here where a depth sensor sees its
//! tessellation.
//!
//! Non-goals: reflectivity, beam divergence and noise. A caller wanting a noisy scan adds
//! it to the distances.

use rapier3d::prelude::*;

use crate::error::SimError;
use crate::math::{self, Vec3};
use crate::world::{Handle, ObjectKind, World};

/// What the rays of one batch may hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayCastParams {
    /// The farthest hit reported along each ray, m; finite and > 0.
    pub max_distance: f64,
    /// The root of an object tree the rays pass through, such as the scanner's own
    /// model, so that a scanner inside its housing does not see the housing.
    pub ignored_tree: Option<Handle>,
    /// Hit only shapes marked detectable (what proximity sensors see) instead of every
    /// shape with collision geometry (what a depth sensor sees, the floor included).
    pub detectable_only: bool,
}

/// The first hit of one ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayHit {
    /// From the ray's origin to the hit, m. A ray starting inside a shape hits it at 0.
    pub distance: f64,
    /// The shape hit.
    pub object: Handle,
}

/// Most rays in one batch: 64 scans of 16 x 1,800 beams. A bound on what one call may
/// allocate, not a performance limit.
pub const MAX_RAYS: usize = 1 << 21;

/// Casts one ray per direction from the origin of `frame`, directions in `frame`'s
/// coordinates (any length but zero; they are normalised), and writes one entry per ray
/// into `hits` (cleared first): the first hit within `params.max_distance`, or `None`.
///
/// The cost per ray is one walk down rapier's bounding-volume tree (no allocation per
/// ray; `hits` is the caller's and keeps its capacity between calls). Colliders are
/// brought to the poses of objects moved through the API since the last step first.
/// Deterministic: the same world and rays give the same hits.
///
/// # Errors
/// [`SimError::NoSuchObject`] for an unknown `frame` or ignored tree, and
/// [`SimError::BadArgument`] for a maximum distance that is not finite and positive, a
/// direction that is zero or not finite (named by its index from 1), or more than
/// [`MAX_RAYS`] rays.
pub fn cast_rays(
    world: &mut World,
    frame: Handle,
    directions: &[[f64; 3]],
    params: &RayCastParams,
    hits: &mut Vec<Option<RayHit>>,
) -> Result<(), SimError> {
    let origin = world.object(frame)?.world;
    if let Some(root) = params.ignored_tree {
        world.object(root)?;
    }
    if !(params.max_distance.is_finite() && params.max_distance > 0.0) {
        return Err(SimError::bad_argument(format!(
            "maximum distance must be finite and > 0 m, got {}",
            params.max_distance
        )));
    }
    if directions.len() > MAX_RAYS {
        return Err(SimError::bad_argument(format!(
            "{} rays in one call, at most {MAX_RAYS}",
            directions.len()
        )));
    }
    // Checked before anything is cast, so a bad batch leaves `hits` as it was.
    for (k, d) in directions.iter().enumerate() {
        let n = Vec3::from(*d).norm();
        if !(n.is_finite() && n > 0.0) {
            return Err(SimError::bad_argument(format!(
                "direction {} is {{{}, {}, {}}}: it must be finite and not zero",
                k + 1,
                d[0],
                d[1],
                d[2]
            )));
        }
    }
    world.refresh_queries();
    let blocked = blocked_colliders(world, params);
    let physics = world.physics();
    let cylinders = cylinders(world, &blocked);
    // Cylinders are cast in closed form below: parry casts them by GJK iterations,
    // which took a third of a 3-D scan of a scene with one pillar.
    let predicate = |c: ColliderHandle, collider: &Collider| {
        collider.shape().as_cylinder().is_none() && blocked.binary_search(&c.into_raw_parts()).is_err()
    };
    let mut pipeline = physics.world.query_pipeline();
    if !blocked.is_empty() || !cylinders.is_empty() {
        pipeline = pipeline.with_filter(QueryFilter {
            predicate: Some(&predicate),
            ..QueryFilter::default()
        });
    }
    let from = math::vec_to_physics(&origin.translation.vector);
    let max = params.max_distance as f32;
    hits.clear();
    hits.extend(directions.iter().map(|d| {
        // Into the world frame and normalised, so that a hit's time of impact is its
        // distance in metres.
        let dir = math::vec_to_physics(&(origin.rotation * Vec3::from(*d).normalize()));
        let ray = Ray::new(from, dir);
        // Solid: a ray that starts inside a shape is blocked at once, as a beam would be.
        let mut best = pipeline
            .cast_ray(&ray, max, true)
            .map(|(ch, toi)| (toi, world.collider_owner(ch)));
        for c in &cylinders {
            let limit = best.map_or(max, |b| b.0);
            if c.aabb.cast_local_ray(&ray, limit, true).is_none() {
                continue;
            }
            if let Some(toi) = c.entry(&ray)
                && toi < limit
            {
                best = Some((toi, Some(c.object)));
            }
        }
        best.and_then(|(toi, object)| {
            object.map(|object| RayHit {
                distance: f64::from(toi),
                object,
            })
        })
    }));
    Ok(())
}

/// A cylinder collider, cast in closed form.
struct CylinderCollider {
    /// The collider's world pose: parry's cylinder lies along its local Y axis.
    pose: Pose,
    half_height: f32,
    radius: f32,
    aabb: Aabb,
    object: Handle,
}

impl CylinderCollider {
    /// Where `ray` (world frame) enters the cylinder, 0 if it starts inside, in the
    /// ray's units (metres for a unit direction).
    fn entry(&self, ray: &Ray) -> Option<f32> {
        let local = ray.inverse_transform_by(&self.pose);
        // In f64: the squares of a few metres would keep only millimetres in f32.
        let (o, d) = (local.origin.as_dvec3(), local.dir.as_dvec3());
        let (r, hh) = (f64::from(self.radius), f64::from(self.half_height));
        let across = |x: f64, z: f64| x * x + z * z <= r * r;
        if across(o.x, o.z) && o.y.abs() <= hh {
            return Some(0.0);
        }
        let mut best = f64::INFINITY;
        // The side: |(o + t d)_xz| = r, entering (the smaller root), within the height.
        let a = d.x * d.x + d.z * d.z;
        let b = 2.0 * (o.x * d.x + o.z * d.z);
        let c = o.x * o.x + o.z * o.z - r * r;
        let disc = b * b - 4.0 * a * c;
        if a > 0.0 && disc >= 0.0 {
            let t = (-b - disc.sqrt()) / (2.0 * a);
            if t >= 0.0 && (o.y + t * d.y).abs() <= hh {
                best = t;
            }
        }
        // The caps.
        if d.y != 0.0 {
            for y in [-hh, hh] {
                let t = (y - o.y) / d.y;
                if t >= 0.0 && t < best && across(o.x + t * d.x, o.z + t * d.z) {
                    best = t;
                }
            }
        }
        best.is_finite().then_some(best as f32)
    }
}

/// The cylinder colliders the rays may hit (not blocked, with an owner), in the
/// collider set's order.
fn cylinders(world: &World, blocked: &[(u32, u32)]) -> Vec<CylinderCollider> {
    world
        .physics()
        .world
        .colliders
        .iter()
        .filter(|(ch, _)| blocked.binary_search(&ch.into_raw_parts()).is_err())
        .filter_map(|(ch, c)| {
            let cylinder = c.shape().as_cylinder()?;
            Some(CylinderCollider {
                pose: *c.position(),
                half_height: cylinder.half_height,
                radius: cylinder.radius,
                aabb: c.compute_aabb(),
                object: world.collider_owner(ch)?,
            })
        })
        .collect()
}

/// The colliders the rays must pass through, as raw handle parts sorted for binary
/// search (`ColliderHandle` has no order of its own): those of the
/// ignored tree and, for `detectable_only`, of shapes not marked detectable. Empty in
/// the common case, when the pipeline then runs without a predicate.
fn blocked_colliders(world: &World, params: &RayCastParams) -> Vec<(u32, u32)> {
    if params.ignored_tree.is_none() && !params.detectable_only {
        return Vec::new();
    }
    let mut in_tree = vec![false; world.len()];
    let mut blocked = Vec::new();
    // Parents come before children in `handles`, so one pass marks a whole tree.
    for &h in world.handles() {
        let Ok(o) = world.object(h) else {
            continue;
        };
        let parent_in_tree = o
            .parent
            .and_then(|p| usize::try_from(p).ok())
            .and_then(|p| in_tree.get(p))
            .copied()
            .unwrap_or(false);
        let ignored = params.ignored_tree == Some(h) || parent_in_tree;
        if let Some(slot) = usize::try_from(h).ok().and_then(|i| in_tree.get_mut(i)) {
            *slot = ignored;
        }
        let undetectable = params.detectable_only && !matches!(&o.kind, ObjectKind::Shape(s) if s.detectable);
        if ignored || undetectable {
            blocked.extend(world.colliders_of(h).iter().map(|c| c.into_raw_parts()));
        }
    }
    blocked.sort_unstable();
    blocked
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cylinder of radius 0.5 and height 2 along Y, at the origin.
    fn unit() -> CylinderCollider {
        CylinderCollider {
            pose: Pose::IDENTITY,
            half_height: 1.0,
            radius: 0.5,
            aabb: Aabb::new(Vector::new(-0.5, -1.0, -0.5), Vector::new(0.5, 1.0, 0.5)),
            object: 0,
        }
    }

    #[test]
    fn cylinders_are_entered_through_the_side_or_a_cap() {
        let c = unit();
        let ray = |o: [f32; 3], d: [f32; 3]| Ray::new(Vector::from(o), Vector::from(d).normalize());
        // Side, head on and at 45 degrees to the axis (entering at height 3 - 2.5 = 0.5).
        assert_eq!(c.entry(&ray([3.0, 0.0, 0.0], [-1.0, 0.0, 0.0])), Some(2.5));
        let t = c.entry(&ray([3.0, 3.0, 0.0], [-1.0, -1.0, 0.0])).expect("hit");
        assert!((t - 2.5 * 2f32.sqrt()).abs() < 1e-5, "{t}");
        // The top cap from above, and a ray over the top that misses.
        assert_eq!(c.entry(&ray([0.2, 5.0, 0.0], [0.0, -1.0, 0.0])), Some(4.0));
        assert_eq!(c.entry(&ray([3.0, 1.5, 0.0], [-1.0, 0.0, 0.0])), None);
        // Pointing away, and starting inside (blocked at once).
        assert_eq!(c.entry(&ray([3.0, 0.0, 0.0], [1.0, 0.0, 0.0])), None);
        assert_eq!(c.entry(&ray([0.1, 0.2, 0.0], [1.0, 0.0, 0.0])), Some(0.0));
    }
}
