//! A small GJK distance algorithm in f64 between one convex shape and a probe: a point (for
//! projections) or the sector `Q_t = K ∩ B(t)` (for the lateral search of `lateral.rs`).
//!
//! Why not parry's GJK (`parry3d::query::gjk::closest_points`): parry has no sector
//! (cone-shell) shape, and its GJK is f32 (parry's `Real`) and stops at a relative gap of
//! ~1e-3, while the lateral search needs separating directions accurate to ~1e-7 (see
//! `lateral.rs`). Run against a sector support map in place of this one, it fails eight of the
//! oracle tests (in `tests::convex`: `lateral_contact_on_a_face`,
//! `convex_shapes_against_oracle`, `random_convex_poses_against_oracle`,
//! `round_cuboid_against_oracle`, `round_cylinder_against_oracle`,
//! `thin_rod_crossing_the_cone`; in `tests::composite`: `compound_is_the_nearest_part`,
//! `trimesh_box_equals_cuboid`), with detections millimetres off their shape. The same goes for
//! point projections on the shapes parry projects with that GJK (see
//! `shape_query::has_analytic_projection`). Only the shape's support points come from parry, in
//! f32; everything else is f64 (nalgebra vectors).

use parry3d::math::Pose;
use parry3d::shape::SupportMap;

use super::geom::Geom;
use super::simplex::{CsoVertex, Simplex, closest_on_simplex, keep_face};
use crate::math::{Vec3, vec_from_physics, vec_to_physics};

/// Below this distance (m) GJK considers the two shapes touching.
const GJK_TOUCH: f64 = 1.0e-9;
/// GJK always stops when the duality gap on the distance is below this fraction of it.
const GJK_REL_GAP: f64 = 1.0e-12;
/// GJK iteration cap (it typically converges in fewer than 10 iterations).
const GJK_MAX_ITERS: usize = 64;

/// Support point of the shape (sensor frame) in direction `dir`: parry's own, in f32, widened
/// to f64. (Applying the pose in f64 instead, on parry's local support point, was tried and
/// is no better: over the 14 000 random cases of the comparison made when this moved to
/// parry, 6 detections were then more than 2 µm off their shape, against 1 with parry's
/// transform, and no test needs it.)
pub(super) fn shape_support(support_map: &dyn SupportMap, pose: &Pose, dir: Vec3) -> Vec3 {
    vec_from_physics(support_map.support_point(pose, vec_to_physics(&dir)))
}

/// The simple convex set GJK measures the shape against.
#[derive(Clone, Copy)]
pub(super) enum Probe<'a> {
    /// A single point (sensor frame, m).
    Point(Vec3),
    /// The sector `Q_t = K ∩ B(t)` with `t = radius` (m).
    Sector { geom: &'a Geom, radius: f64 },
}

impl Probe<'_> {
    /// Support point (sensor frame, m) of the probe in direction `dir`.
    fn support(&self, dir: Vec3) -> Vec3 {
        match *self {
            Self::Point(p) => p,
            Self::Sector { geom, radius } => {
                let (cos, sin) = (f64::from(geom.cos), f64::from(geom.sin));
                let len = dir.norm();
                if len <= 0.0 || !len.is_finite() {
                    return Vec3::zeros();
                }
                if dir.z >= len * cos {
                    // The direction points into the cone: a point of the spherical cap.
                    return dir * (radius / len);
                }
                let rxy = (dir.x * dir.x + dir.y * dir.y).sqrt();
                if rxy <= 0.0 {
                    // Straight backwards: the apex.
                    return Vec3::zeros();
                }
                // The rim point at the direction's azimuth, unless the apex is further.
                let k = radius * sin / rxy;
                let rim = Vec3::new(dir.x * k, dir.y * k, radius * cos);
                if dir.dot(&rim) > 0.0 { rim } else { Vec3::zeros() }
            }
        }
    }
}

/// Closest points `(x ∈ S, y ∈ probe)` between the shape and the probe, or `None` when they
/// touch or overlap (distance below [`GJK_TOUCH`]). `towards` is a guess of the direction from
/// the probe to the shape, used when `simplex` is empty; otherwise `simplex` (left by a
/// previous call, see [`Simplex::rescale_probe`]) warm-starts the iteration. On return it
/// holds the final simplex. The iteration stops once the distance is known within
/// `tolerance` (m); the error on the direction of `x - y` is then at most
/// `sqrt(2·tolerance / distance)`.
///
/// A plain GJK in f64 with Ericson's Voronoi-region sub-algorithm ("Real-Time Collision
/// Detection", 5.1.5–5.1.6), guarded against the flat simplices that thin shapes produce.
pub(super) fn gjk_closest_points(
    probe: Probe<'_>,
    support_map: &dyn SupportMap,
    pose: &Pose,
    towards: Vec3,
    tolerance: f64,
    simplex: &mut Simplex,
) -> Option<(Vec3, Vec3)> {
    let support = |d: Vec3| {
        let x = shape_support(support_map, pose, d);
        let y = probe.support(-d);
        CsoVertex { w: x - y, x, y }
    };
    if simplex.len == 0 {
        simplex.vertices[0] = support(-towards);
        simplex.len = 1;
    }
    // Warm start: the closest point of the inherited simplex.
    let found = closest_on_simplex(simplex)?;
    let mut bary = keep_face(simplex, &found);
    let mut v = found.0;
    for _ in 0..GJK_MAX_ITERS {
        let vv = v.norm_squared();
        if vv <= GJK_TOUCH * GJK_TOUCH {
            return None;
        }
        let s = support(-v);
        // Duality gap |v|·(|v| - lower bound): stop once the distance is known precisely
        // enough.
        let gap = vv - v.dot(&s.w);
        if gap <= GJK_REL_GAP * vv || gap <= tolerance * vv.sqrt() {
            break;
        }
        if simplex.vertices[..simplex.len].iter().any(|p| p.w == s.w) {
            // No new support point: the f32 support map cannot improve further.
            break;
        }
        simplex.vertices[simplex.len] = s;
        simplex.len += 1;
        let found = closest_on_simplex(simplex)?;
        if found.0.norm_squared() >= vv {
            // No progress (rounding): keep the previous answer.
            simplex.len -= 1;
            break;
        }
        bary = keep_face(simplex, &found);
        v = found.0;
    }
    let mut x = Vec3::zeros();
    let mut y = Vec3::zeros();
    for (p, &l) in simplex.vertices[..simplex.len].iter().zip(&bary) {
        x += p.x * l;
        y += p.y * l;
    }
    Some((x, y))
}
