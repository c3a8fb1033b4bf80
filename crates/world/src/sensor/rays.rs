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
    let predicate = |c: ColliderHandle, _: &Collider| blocked.binary_search(&c.into_raw_parts()).is_err();
    let physics = world.physics();
    let mut pipeline = physics.world.query_pipeline();
    if !blocked.is_empty() {
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
        // Solid: a ray that starts inside a shape is blocked at once, as a beam would be.
        pipeline
            .cast_ray(&Ray::new(from, dir), max, true)
            .and_then(|(ch, toi)| {
                world.collider_owner(ch).map(|object| RayHit {
                    distance: f64::from(toi),
                    object,
                })
            })
    }));
    Ok(())
}

/// The colliders the rays must pass through, as raw handle parts sorted for binary
/// search (`ColliderHandle` has no order of its own): those of the
/// ignored tree and, for `detectable_only`, of shapes not marked detectable. Empty in
/// the common case, when the pipeline then runs without a predicate.
fn blocked_colliders(world: &World, params: &RayCastParams) -> Vec<(u32, u32)> {
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
