//! One convex shape (a support map, or a mesh triangle) against the volume.
//!
//! # Method and why it is exact
//!
//! Let `K` be the infinite cone `{ p : angle(p, +Z) <= half_angle }` (convex because
//! `half_angle < π/2`; the ray is the degenerate cone of half-angle 0, i.e. the +Z half-line)
//! and, for a convex shape `S`, `C = S ∩ K`, convex as an intersection of convex sets. Being
//! convex, `C` is connected, so `{ |p| : p ∈ C }` is an interval `[t*, t_max]`, and
//! `S ∩ V = C ∩ { a <= |p| <= b }` (`a = offset`, `b = offset + range`) is non-empty iff that
//! interval meets `[a, b]`; the nearest distance is then `max(t*, a)`. Two sub-problems follow.
//!
//! 1. **`t*` = min of `|p|` over `C`** (a convex program). Three exhaustive cases:
//!    * A. the origin is inside `S`: `t* = 0`.
//!    * B. the projection `p0` of the origin on `S` lies in `K`: `p0` minimises `|p|` over all
//!      of `S`, hence over `C ⊂ S`: `t* = |p0|`. This is the fast path, a single projection.
//!      The normal is `-p0 / |p0|`, which lies in the normal cone of `S` at `p0`.
//!    * C. otherwise the minimiser lies on the lateral surface of `K` (`lateral.rs`).
//! 2. **Near cap**, when `t* < a`: the answer is `a` iff `t_max >= a` (`near_cap.rs`).
//!
//! For the ray, shapes with an exact parry ray cast skip all this: the solid ray cast from
//! the start of the segment is the answer.

use parry3d::math::{Pose, Vector};
use parry3d::query::Ray;
use parry3d::shape::{Shape, SupportMap, TypedShape};

use super::geom::Geom;
use super::hit::{ProximityHit, cap_hit};
use super::lateral::{ball_lateral, lateral_minimum};
use super::near_cap::near_cap;
use super::normal::facing_sensor;
use super::shape_query::{has_analytic_ray_cast, projection};

/// The ray volume on a shape with an exact parry ray cast: the solid cast from the start of
/// the segment gives the documented semantics directly (time 0 when it starts inside).
fn detect_by_ray_cast(geom: &Geom, shape: &dyn Shape, pose: &Pose, limit: f32) -> Option<ProximityHit> {
    let ray = Ray::new(Vector::Z * geom.near, Vector::Z);
    let hit = shape.cast_ray_and_get_normal(pose, &ray, limit - geom.near, true)?;
    let toi = hit.time_of_impact.max(0.0);
    let point = ray.point_at(toi);
    if toi <= 0.0 {
        // The segment starts inside the solid: detected at the offset, normal pointing back.
        return Some(cap_hit(point));
    }
    Some(ProximityHit {
        distance: geom.near + toi,
        point,
        normal: facing_sensor(hit.normal, point),
    })
}

/// Nearest detection of a convex shape (see the module documentation: cases A, B, C and the
/// near cap). `limit` (m) is the largest distance still of interest.
pub(super) fn detect_convex(
    geom: &Geom,
    shape: &dyn Shape,
    support_map: &dyn SupportMap,
    pose: &Pose,
    limit: f32,
) -> Option<ProximityHit> {
    if geom.is_ray() && has_analytic_ray_cast(shape) {
        return detect_by_ray_cast(geom, shape, pose, limit);
    }
    let Some(p0) = projection(shape, support_map, pose, Vector::ZERO) else {
        // Case A: t* = 0.
        return near_cap(geom, shape, support_map, pose, Vector::ZERO);
    };
    let d0 = p0.length();
    if !d0.is_finite() || d0 > limit {
        // Every point of the shape is at least d0 away.
        return None;
    }
    if geom.in_cone(p0) {
        // Case B, the fast path.
        if d0 >= geom.near {
            return Some(ProximityHit {
                distance: d0,
                point: p0,
                normal: if d0 > 0.0 { -p0 / d0 } else { -Vector::Z },
            });
        }
        return near_cap(geom, shape, support_map, pose, p0);
    }
    // Case C: the minimiser is on the lateral surface.
    let lateral = match shape.as_typed_shape() {
        TypedShape::Ball(ball) => ball_lateral(geom, pose.translation, ball.radius, limit),
        _ => lateral_minimum(geom, shape, support_map, pose, p0, limit),
    }?;
    if lateral.distance >= geom.near {
        Some(lateral)
    } else {
        near_cap(geom, shape, support_map, pose, lateral.point)
    }
}
