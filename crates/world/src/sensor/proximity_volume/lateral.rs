//! Case C of `convex.rs`: the nearest point of a convex shape `S` inside the cone `K` when it
//! lies on the cone's lateral surface.
//!
//! # Method and why it is exact
//!
//! The projection `p0` of the origin on `S` is outside `K`, so the minimiser `q` of `|p|` over
//! `S ∩ K` lies on the lateral surface of `K`: were `q` interior to `K`, it would be a local,
//! hence (convexity) global, minimiser of `|p|` over `S`, i.e. `p0`, which is not in `K`. We
//! find `t*` as the smallest `t` for which `S` touches the sector `Q_t = K ∩ B(t)`. Because
//! `Q_t = t·Q_1`, `g(t) = dist(S, Q_t)` is convex and non-increasing in `t`, and for any unit
//! `n`, `g(t) >= min_S(n·x) - t·h_{Q_1}(n)` (separating plane; `h` is the support function).
//! Starting from `t = |p0|` (a lower bound), each step runs GJK between `S` and `Q_t`, takes
//! the separating direction `n` and moves to the root of that affine lower bound,
//! `t ← min_S(n·x) / h_{Q_1}(n)`. Every iterate is a *certified lower bound* of `t*` whatever
//! the GJK accuracy; with the exact `n` this is Newton's method on a convex function, which
//! converges monotonically (quadratically in practice, 2–5 steps; GJK only needs an accuracy of
//! order `g²/t` at each step, so intermediate runs stop early). `h_{Q_1}(n) <= 0` with
//! `min_S(n·x) > 0` certifies that a plane through the apex separates `S` from the whole cone.
//! It stops once the error bound `g / h` falls below 1e-6 of the distance. The minimiser is
//! then the rim point of `Q_t*` facing the shape: its azimuth comes from the GJK witness on the
//! sector of one more full-precision run just below `t*`, and the reported point is
//! `t*·generator(azimuth)`. The normal is computed separately (`normal.rs`). Balls are solved
//! in closed form.
//!
//! When the contact is grazing (`h` small) the separating direction is too ill-conditioned for
//! f32 support points and Newton stalls with the gap open; the first-hit distance along the
//! generators, which is flat there, is then minimised over the azimuth by golden section near
//! the witness (each value a feasible point, i.e. an upper bound). A sampled minimisation over
//! the azimuth alone would not be exact in general: the first-hit distance along the generators
//! can be bimodal (a thin rod crossing the cone is hit near both sides) and arcs narrower than
//! the sampling step are missed.

use parry3d::math::{Pose, Vector};
use parry3d::query::Ray;
use parry3d::query::details::ray_toi_with_ball;
use parry3d::shape::{Shape, SupportMap};

use super::geom::{Geom, unit_sector_support_value};
use super::gjk::{Probe, gjk_closest_points, shape_support};
use super::hit::ProximityHit;
use super::normal::{facing_sensor, lateral_normal};
use super::shape_query::{ON_SHAPE_TOL, has_analytic_ray_cast, point_distance};
use super::simplex::Simplex;
use crate::math::{vec_from_physics, vec_to_physics};

/// Maximum number of lower-bound (Newton) steps of the lateral search. Convergence takes 2–5
/// steps in practice; the cap only guards against pathological grazing contacts.
const MAX_NEWTON_STEPS: usize = 40;
/// A Newton step shorter than this (m) is no progress.
const NEWTON_STEP_TOL: f64 = 1.0e-10;
/// The lateral search stops when the remaining error bound `g / h` on the distance (GJK gap
/// over the slope of `g`) falls below this fraction of the distance...
const TOUCH_REL: f64 = 1.0e-6;
/// ...or when the gap itself falls below this fraction of the distance: the f32 support points
/// are accurate to ~1e-7 of the scene scale, so smaller gaps are noise (grazing contacts,
/// where `h` is small, are ill-conditioned anyway)...
const NOISE_REL: f64 = 1.0e-7;
/// ...with the distance floored at this value (m) in both tests.
const TOUCH_SCALE_FLOOR: f64 = 0.01;
/// A stalled lateral search (see `lateral_minimum`) is accepted when its error bound `g / h`
/// is below this fraction of the (floored) distance; otherwise the azimuth search takes over.
const STALL_REL: f64 = 2.0e-5;
/// Half-width (rad) of the azimuth bracket of the lateral fallback search.
const AZIMUTH_BRACKET: f32 = 0.03;
/// Golden-section iterations of the lateral fallback (0.03 rad × 0.618^30 ≈ 1e-8 rad).
const GOLDEN_STEPS: usize = 30;

/// Case C: minimum of `|p|` over `S ∩ K` when it lies on the lateral surface of `K`
/// (`p0`, the projection of the origin on the shape, is outside `K`), by the certified Newton
/// iteration of the module documentation.
pub(super) fn lateral_minimum(
    geom: &Geom,
    shape: &dyn Shape,
    support_map: &dyn SupportMap,
    pose: &Pose,
    p0: Vector,
    limit: f32,
) -> Option<ProximityHit> {
    // A bounding-sphere test rejects most shapes that merely touch the volume's AABB corners
    // before any GJK work.
    let sphere = shape.compute_bounding_sphere(pose);
    if !geom.sphere_may_touch(sphere.center, sphere.radius, limit) {
        return None;
    }

    let limit = f64::from(limit);
    // Certified lower bound on t*, and the current separating direction (sector → shape).
    let mut t = f64::from(p0.length());
    let mut dir = vec_from_physics(p0) / t;
    // Witness on the sector of the latest GJK run (its azimuth is the minimiser's).
    let mut on_rim = vec_from_physics(p0);
    let mut simplex = Simplex::default();
    let mut simplex_radius = t;
    // GJK accuracy needed by the next step: the lower bound is off by O(t·δ²) for a direction
    // error δ, and δ² <= 2·tolerance / gap, so a tolerance of ~gap²/t keeps the convergence
    // quadratic without solving every intermediate GJK to full precision.
    let mut tolerance = 1.0e-3 * t;
    let mut retried = false;
    let mut converged = false;
    for _ in 0..MAX_NEWTON_STEPS {
        simplex.rescale_probe(t / simplex_radius);
        simplex_radius = t;
        let probe = Probe::Sector { geom, radius: t };
        let Some((on_shape, on_sector)) = gjk_closest_points(probe, support_map, pose, dir, tolerance, &mut simplex)
        else {
            // Touching: t is t* up to the GJK tolerance.
            converged = true;
            break;
        };
        on_rim = on_sector;
        let gap = on_shape - on_sector;
        let dist = gap.norm();
        let scale = t.max(TOUCH_SCALE_FLOOR);
        if dist <= NOISE_REL * scale {
            // Below this gap the direction of `gap` is dominated by the f32 rounding of the
            // support points: the shapes touch.
            converged = true;
            break;
        }
        dir = gap / dist;
        let h = unit_sector_support_value(geom, dir);
        if dist <= TOUCH_REL * scale * h {
            // Converged: g is convex with slope about -h near t*, so t* - t <= dist / h.
            converged = true;
            break;
        }
        // min over S of dir·x.
        let min_along = dir.dot(&shape_support(support_map, pose, -dir));
        if h <= 0.0 && min_along > 0.0 {
            // A plane through the apex separates the shape from the whole cone.
            return None;
        }
        // Root of the affine lower bound `min_S(n·x) - t·h` of g(t): a certified lower bound
        // of t* for any unit direction, so GJK inaccuracy can slow but never overshoot.
        let next = if h > 0.0 { min_along / h } else { t };
        if next > limit {
            return None;
        }
        if next <= t + NEWTON_STEP_TOL {
            // The gap is open but this direction certifies nothing better: GJK's answer was
            // not accurate enough. Retry once from scratch at full precision.
            if retried {
                // Still stalled, near the f32 noise floor: good enough if the error bound
                // t* - t <= g / h is small, else leave it to the fallback search below.
                converged = dist <= STALL_REL * scale * h;
                break;
            }
            retried = true;
            simplex = Simplex::default();
            tolerance = 0.0;
            continue;
        }
        t = next;
        tolerance = 0.05 * dist * dist / t;
    }
    // The azimuth of the minimiser: the witness on the sector, from one more GJK run just below
    // t* to full precision. The Newton steps only needed the separating direction, so their
    // GJK runs stopped early and their witnesses may sit on a wide chord of the rim.
    let just_below = t - (t * 1.0e-5).max(1.0e-9);
    simplex.rescale_probe(just_below / simplex_radius);
    let probe = Probe::Sector {
        geom,
        radius: just_below,
    };
    if let Some((_, on_sector)) = gjk_closest_points(probe, support_map, pose, dir, 0.0, &mut simplex) {
        on_rim = on_sector;
    }
    let mut t32 = t as f32;
    let on_rim = vec_to_physics(&on_rim);
    let mut azimuth = on_rim.y.atan2(on_rim.x);
    if !converged {
        // Newton stalled with the gap still open: a grazing contact, where the separating
        // direction is so ill-conditioned that f32 rounding spoils the dual lower bound. The
        // primal problem is well-conditioned there (the first-hit distance is flat around its
        // minimum): minimise it over the azimuth near the witness. Its values are feasible
        // points, i.e. upper bounds of t*.
        if let Some((refined, at)) = refine_on_generators(geom, shape, support_map, pose, azimuth, t32, limit as f32) {
            t32 = refined;
            azimuth = at;
        }
    }
    let point = geom.generator(azimuth) * t32;
    let normal = lateral_normal(shape, support_map, pose, point, vec_to_physics(&dir), sphere.radius);
    Some(ProximityHit {
        distance: t32,
        point,
        normal: facing_sensor(normal, point),
    })
}

/// Golden-section minimisation of the first-hit distance along the generators over the
/// azimuths `phi0 ± AZIMUTH_BRACKET`, for the lateral fallback. `lower` (m) is a lower bound of
/// the answer, `limit` (m) the largest distance of interest. Returns the best distance and its
/// azimuth, or `None` if no probed generator hits the shape.
fn refine_on_generators(
    geom: &Geom,
    shape: &dyn Shape,
    support_map: &dyn SupportMap,
    pose: &Pose,
    phi0: f32,
    lower: f32,
    limit: f32,
) -> Option<(f32, f32)> {
    const INV_GOLDEN: f32 = 0.618_034;
    let eval =
        |phi: f32| first_hit(shape, support_map, pose, geom.generator(phi), lower, limit).unwrap_or(f32::INFINITY);
    let (mut lo, mut hi) = (phi0 - AZIMUTH_BRACKET, phi0 + AZIMUTH_BRACKET);
    let (mut x1, mut x2) = (hi - INV_GOLDEN * (hi - lo), lo + INV_GOLDEN * (hi - lo));
    let (mut f1, mut f2) = (eval(x1), eval(x2));
    let mut best = (eval(phi0), phi0);
    for _ in 0..GOLDEN_STEPS {
        if f1 <= f2 {
            best = if f1 < best.0 { (f1, x1) } else { best };
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - INV_GOLDEN * (hi - lo);
            f1 = eval(x1);
        } else {
            best = if f2 < best.0 { (f2, x2) } else { best };
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + INV_GOLDEN * (hi - lo);
            f2 = eval(x2);
        }
    }
    for (f, x) in [(f1, x1), (f2, x2)] {
        if f < best.0 {
            best = (f, x);
        }
    }
    best.0.is_finite().then_some(best)
}

/// First point of the convex shape along the ray `t·d`, `t` in `[lower, limit]` (m), or
/// `None`. Exact parry ray casts where they exist; otherwise a search on the convex function
/// `t ↦ dist(t·d, S)`: golden section for its minimum, then bisection for the entry point.
fn first_hit(
    shape: &dyn Shape,
    support_map: &dyn SupportMap,
    pose: &Pose,
    d: Vector,
    lower: f32,
    limit: f32,
) -> Option<f32> {
    if has_analytic_ray_cast(shape) {
        return shape
            .cast_ray(pose, &Ray::new(d * lower, d), limit - lower, true)
            .map(|toi| lower + toi);
    }
    let eps = ON_SHAPE_TOL * 0.1;
    let f = |t: f32| point_distance(shape, support_map, pose, d * t);
    if f(lower) <= eps {
        return Some(lower);
    }
    const INV_GOLDEN: f32 = 0.618_034;
    let (mut lo, mut hi) = (lower, limit);
    let (mut x1, mut x2) = (hi - INV_GOLDEN * (hi - lo), lo + INV_GOLDEN * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    let mut inside = None;
    for _ in 0..40 {
        if f1 <= eps {
            inside = Some(x1);
            break;
        }
        if f2 <= eps {
            inside = Some(x2);
            break;
        }
        if f1 <= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - INV_GOLDEN * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + INV_GOLDEN * (hi - lo);
            f2 = f(x2);
        }
    }
    // Entry point: bisection between `lower` (outside) and a point inside.
    let (mut outside, mut inside) = (lower, inside?);
    for _ in 0..32 {
        let mid = 0.5 * (outside + inside);
        if f(mid) <= eps {
            inside = mid;
        } else {
            outside = mid;
        }
    }
    Some(inside)
}

/// Case C for a ball (centre `c`, radius `rho`, sensor frame). The plane through the axis and
/// the centre is a symmetry plane of the problem and the minimiser is unique, so it lies on the
/// generator at the centre's azimuth, where it is that generator's first hit (parry's ray–ball
/// query, in closed form). That generator is also the lateral one nearest to the centre: if it
/// misses the ball, the ball does not reach the cone's surface at all.
pub(super) fn ball_lateral(geom: &Geom, c: Vector, rho: f32, limit: f32) -> Option<ProximityHit> {
    let d = geom.generator(c.y.atan2(c.x));
    // The free function on the centre rather than `Ball::cast_ray` on the posed ball: the same
    // answer without the pose round trip, which cost 40 ns more per call (`--bench proximity`,
    // "cone, ball beside", 63 → 105 ns). A ball behind the sensor is missed; the origin inside
    // the ball is case A, never this one.
    let (_, t) = ray_toi_with_ball(c, rho, &Ray::new(Vector::ZERO, d), true);
    let t = t.filter(|&t| t <= limit)?;
    let point = d * t;
    Some(ProximityHit {
        distance: t,
        point,
        normal: facing_sensor(point - c, point),
    })
}
