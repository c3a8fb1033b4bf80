//! Point projections and ray casts on one convex shape (sensor frame): parry's own queries
//! where they are exact, our f64 GJK (`gjk.rs`) for the projections where they are not.

use parry3d::math::{Pose, Vector};
use parry3d::shape::{Shape, ShapeType, SupportMap};

use super::gjk::{Probe, gjk_closest_points};
use super::simplex::Simplex;
use crate::math::{self, vec_from_physics};

/// Absolute GJK tolerance (m) for point projections.
const PROJECTION_TOL: f64 = 1.0e-10;
/// Absolute distance (m) under which a point counts as lying on a shape.
pub(super) const ON_SHAPE_TOL: f32 = 1.0e-6;

/// Whether parry projects points on this shape type analytically (exactly). The other
/// convex shapes (convex polyhedra, round shapes, other support maps) go through parry's f32
/// GJK, which stops at a relative gap of ~1e-3 and is not good enough:
/// `tests::convex::hull_and_round_cuboid_need_exact_projections` fails with it (detections
/// 1.1e-4 m and 1.3e-4 m beyond the oracle), so they get our f64 GJK.
fn has_analytic_projection(shape: &dyn Shape) -> bool {
    matches!(
        shape.shape_type(),
        ShapeType::Ball
            | ShapeType::Cuboid
            | ShapeType::Capsule
            | ShapeType::Cylinder
            | ShapeType::Cone
            | ShapeType::Triangle
            | ShapeType::Segment
    )
}

/// Whether parry casts rays on this shape type analytically (exactly). Its other ray casts
/// (cylinder, cone, convex polyhedron, round shapes) are GJK-based and can be a millimetre
/// early: `tests::volume::ray_on_a_cylinder_is_exact` fails with them (0.12417 m for the
/// exact 0.12524 m), so those shapes get a search on our projections instead (`first_hit`).
pub(super) fn has_analytic_ray_cast(shape: &dyn Shape) -> bool {
    matches!(
        shape.shape_type(),
        ShapeType::Ball | ShapeType::Cuboid | ShapeType::Capsule | ShapeType::Triangle
    )
}

/// Projection of `p` (sensor frame) on the convex shape, or `None` when `p` is inside it (or
/// on its surface, within GJK's tolerance).
pub(super) fn projection(shape: &dyn Shape, support_map: &dyn SupportMap, pose: &Pose, p: Vector) -> Option<Vector> {
    if has_analytic_projection(shape) {
        let proj = shape.project_point(pose, p, true);
        (!proj.is_inside).then_some(proj.point)
    } else {
        let p64 = vec_from_physics(p);
        let towards = vec_from_physics(pose.translation) - p64;
        let mut simplex = Simplex::default();
        let probe = Probe::Point(p64);
        gjk_closest_points(probe, support_map, pose, towards, PROJECTION_TOL, &mut simplex)
            .map(|(on_shape, _)| math::vec_to_physics(&on_shape))
    }
}

/// Distance (m) from `p` (sensor frame) to the convex shape, 0 inside.
pub(super) fn point_distance(shape: &dyn Shape, support_map: &dyn SupportMap, pose: &Pose, p: Vector) -> f32 {
    projection(shape, support_map, pose, p).map_or(0.0, |proj| (proj - p).length())
}

/// Whether `p` (sensor frame) lies on or in the convex shape, within [`ON_SHAPE_TOL`].
pub(super) fn on_shape(shape: &dyn Shape, support_map: &dyn SupportMap, pose: &Pose, p: Vector) -> bool {
    point_distance(shape, support_map, pose, p) <= ON_SHAPE_TOL + 1.0e-6 * p.length()
}
