//! Composite shapes (compounds, triangle meshes, polylines) and height fields: the union of
//! their parts, each detected on its own.
//!
//! A composite is walked through parry's BVH in the composite's frame, pruning nodes whose
//! AABB misses the volume AABB or is farther than the best detection so far. Mesh triangles
//! and polyline segments are thin convex solids, so a closed mesh is a hollow surface, as in
//! CoppeliaSim.

use parry3d::bounding_volume::BoundingVolume;
use parry3d::math::{Pose, Vector};
use parry3d::partitioning::TraversalAction;
use parry3d::query::PointQuery;
use parry3d::shape::{CompositeShape, HeightField, Shape, Triangle, TypedShape};

use super::convex::detect_convex;
use super::geom::Geom;
use super::half_space::detect_half_space;
use super::hit::{ProximityHit, keep_nearest, limit};

/// Dispatches on the shape type and merges its detection into `best`. It lives with the
/// composites because they recurse into it for each of their parts.
pub(super) fn detect_shape(geom: &Geom, shape: &dyn Shape, pose: &Pose, best: &mut Option<ProximityHit>) {
    match shape.as_typed_shape() {
        TypedShape::HalfSpace(hs) => keep_nearest(best, detect_half_space(geom, hs, pose)),
        TypedShape::HeightField(hf) => detect_height_field(geom, hf, pose, best),
        _ => {
            if let Some(composite) = shape.as_composite_shape() {
                detect_composite(geom, composite, pose, best);
            } else if let Some(support_map) = shape.as_support_map() {
                let lim = limit(geom, best);
                keep_nearest(best, detect_convex(geom, shape, support_map, pose, lim));
            }
            // Anything else (voxels, custom shapes without a support map) is not supported.
        }
    }
}

/// Walks the composite's BVH (in the composite's frame), pruning nodes that miss the volume
/// AABB or cannot beat the best detection so far, and recurses into the parts.
pub(super) fn detect_composite(
    geom: &Geom,
    composite: &dyn CompositeShape,
    pose: &Pose,
    best: &mut Option<ProximityHit>,
) {
    let inv = pose.inverse();
    let sensor_local = inv.transform_point(Vector::ZERO);
    let volume_local = geom.aabb().transform_by(&inv);
    composite.bvh().traverse(|node| {
        let aabb = node.aabb();
        if !aabb.intersects(&volume_local) || aabb.distance_to_local_point(sensor_local, true) > limit(geom, best) {
            return TraversalAction::Prune;
        }
        if let Some(part) = node.leaf_data() {
            composite.map_part_at(part, &mut |part_pose, part_shape, _| {
                let part_pose = part_pose.map_or(*pose, |pp| *pose * *pp);
                detect_shape(geom, part_shape, &part_pose, best);
            });
        }
        TraversalAction::Continue
    });
}

/// Height fields are surfaces: each triangle under the volume AABB is a thin convex shape.
pub(super) fn detect_height_field(geom: &Geom, hf: &HeightField, pose: &Pose, best: &mut Option<ProximityHit>) {
    let volume_local = geom.aabb().transform_by(&pose.inverse());
    hf.map_elements_in_local_aabb(&volume_local, &mut |_, tri: &Triangle| {
        let lim = limit(geom, best);
        keep_nearest(best, detect_convex(geom, tri, tri, pose, lim));
    });
}
