//! The brute-force oracle the detector is compared with, and the invariants every detection
//! must satisfy.

use core::f32::consts::TAU;

use parry3d::math::{Pose, Vector};
use parry3d::query::{PointQuery, Ray};
use parry3d::shape::{Shape, Triangle};

use super::{TOL, cone_params, direction};
use crate::sensor::proximity_volume::{ProximityHit, ProximityVolume};

/// Brute-force oracle, independent of the detector's method: for a direction `u` of the
/// cone, the shape occupies `[t_in, t_out]` along the ray from the origin, and the nearest
/// volume point on that ray is `max(t_in, offset)` if it is `<= t_out` and
/// `<= offset + range`. The minimum over a dense (θ, φ) grid, including the rim
/// θ = half_angle, plus the directions of the shape's extreme points (so that vertices and
/// apexes pointing at the sensor are sampled), is refined around the best samples.
/// Every sample is a feasible point, so the oracle is an upper bound that converges to the
/// exact value. Valid for convex shapes (for surfaces, `t_in = t_out`).
///
/// The interval comes from parry's ray casts, verified with point projections (parry's
/// GJK-based ray casts on cylinders and the like can be a millimetre early); when the
/// verification fails it is recomputed by a golden-section/bisection search on the convex
/// function `t ↦ dist(t·u, S)`.
pub(super) fn oracle(vol: &ProximityVolume, shape: &dyn Shape, pose: &Pose) -> Option<f32> {
    const FAR: f32 = 50.0;
    const EPS: f32 = 1.0e-7;
    const STEP: f32 = 1.0e-6;
    let (a, b, alpha) = cone_params(vol);
    // parry's projections on round shapes go through its f32 GJK, which can be off by tens
    // of micrometres (and its ray casts by millimetres): measure them exactly instead.
    let round = round_distance(shape, pose, Vector::ZERO).is_some();
    let dist = |p: Vector| round_distance(shape, pose, p).unwrap_or_else(|| shape.distance_to_point(pose, p, true));
    let robust_interval = |u: Vector| -> Option<(f32, f32)> {
        let f = |t: f32| dist(u * t);
        let (mut lo, mut hi) = (0.0f32, 2.0 * b + 1.0);
        for _ in 0..60 {
            let m1 = lo + (hi - lo) * 0.382;
            let m2 = lo + (hi - lo) * 0.618;
            if f(m1) <= f(m2) {
                hi = m2;
            } else {
                lo = m1;
            }
        }
        let tm = 0.5 * (lo + hi);
        if f(tm) > EPS {
            return None;
        }
        let boundary = |mut inside: f32, mut outside: f32| {
            for _ in 0..60 {
                let mid = 0.5 * (inside + outside);
                if f(mid) <= EPS {
                    inside = mid;
                } else {
                    outside = mid;
                }
            }
            inside
        };
        let t_in = if f(0.0) <= EPS { 0.0 } else { boundary(tm, 0.0) };
        Some((t_in, boundary(tm, 2.0 * b + 1.0)))
    };
    // parry's point projection on convex polyhedra is GJK-based and can misreport points
    // as inside: use the exact half-space representation instead.
    let planes = hull_planes(shape, pose);
    let sphere = shape.compute_bounding_sphere(pose);
    let reach = sphere.center.length() + sphere.radius + 0.01;
    // The nearest volume point along `u`, or infinity.
    let eval_dir = |u: Vector| -> Option<f32> {
        if !planes.is_empty() {
            let (mut lo, mut hi) = (0.0f32, FAR);
            for &(n, d) in &planes {
                let nu = n.dot(u);
                if nu > 0.0 {
                    hi = hi.min(d / nu);
                } else if nu < 0.0 {
                    lo = lo.max(d / nu);
                } else if d < 0.0 {
                    return None;
                }
            }
            let d = lo.max(a);
            return (lo <= hi && d <= hi && d <= b).then_some(d);
        }
        if round {
            // No reliable ray cast either: search along the ray directly.
            let (t_in, t_out) = robust_interval(u)?;
            let d = t_in.max(a);
            return (d <= b && d <= t_out + STEP).then_some(d);
        }
        // Conservative advancement: stepping along the ray by the distance to the convex
        // shape never crosses it, so this moves an early ray-cast hit onto the surface.
        let settle = |mut t: f32, sign: f32| {
            for _ in 0..30 {
                let d = dist(u * t);
                if d <= EPS {
                    return Some(t);
                }
                t += sign * d;
            }
            None
        };
        let t_in = shape.cast_ray(pose, &Ray::new(Vector::ZERO, u), reach, true)?;
        let t_in = settle(t_in, 1.0).filter(|&t| t <= 0.0 || dist(u * (t - STEP)) > 0.0);
        let (t_in, t_out) = match t_in {
            None => robust_interval(u)?,
            // The exit point only matters when the entry is before the near cap.
            Some(t_in) if t_in >= a => (t_in, f32::INFINITY),
            Some(t_in) => {
                let back = shape.cast_ray(pose, &Ray::new(u * reach, -u), reach, true);
                let t_out = back
                    .and_then(|back| settle(reach - back, -1.0))
                    .filter(|&t| dist(u * (t + STEP)) > 0.0);
                match t_out {
                    Some(t_out) => (t_in, t_out),
                    None => robust_interval(u)?,
                }
            }
        };
        let d = t_in.max(a);
        (d <= b && d <= t_out + STEP).then_some(d)
    };
    let eval =
        |theta: f32, phi: f32| -> f32 { eval_dir(direction(theta.clamp(0.0, alpha), phi)).unwrap_or(f32::INFINITY) };
    let (nt, np) = (20usize, 240usize);
    let (dt, dp) = (alpha / nt as f32, TAU / np as f32);
    let mut samples = Vec::with_capacity((nt + 1) * np + 400);
    for i in 0..=nt {
        for j in 0..np {
            let (th, ph) = (i as f32 * dt, j as f32 * dp);
            samples.push((eval(th, ph), th, ph));
        }
    }
    if let Some(sm) = shape.as_support_map() {
        // Fibonacci sphere of support directions.
        for k in 0..400 {
            let z = 1.0 - 2.0 * (k as f32 + 0.5) / 400.0;
            let ph = k as f32 * 2.399_963;
            let w = Vector::new((1.0 - z * z).sqrt() * ph.cos(), (1.0 - z * z).sqrt() * ph.sin(), z);
            let sp = sm.support_point(pose, w);
            let u = sp.normalize_or_zero();
            let th = u.z.clamp(-1.0, 1.0).acos();
            if u != Vector::ZERO && th <= alpha {
                let ph = u.y.atan2(u.x);
                samples.push((eval(th, ph), th, ph));
                // The extreme point itself is a point of the shape: a feasible sample
                // even where a ray through a vertex or along an edge is numerically missed.
                let l = sp.length();
                if (a..=b).contains(&l) {
                    samples.push((l, th, ph));
                }
            }
        }
    }
    samples.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut best = f32::INFINITY;
    for &(f, th0, ph0) in samples.iter().take(5) {
        if !f.is_finite() {
            break;
        }
        let (mut th, mut ph, mut fb) = (th0, ph0, f);
        let (mut st, mut sp) = (dt, dp);
        for _ in 0..8 {
            let (c_th, c_ph) = (th, ph);
            for ki in -3..=3 {
                for kj in -3..=3 {
                    let t2 = (c_th + ki as f32 * st / 3.0).clamp(0.0, alpha);
                    let p2 = c_ph + kj as f32 * sp / 3.0;
                    let v = eval(t2, p2);
                    if v < fb {
                        (fb, th, ph) = (v, t2, p2);
                    }
                }
            }
            st /= 3.0;
            sp /= 3.0;
        }
        best = best.min(fb);
    }
    best.is_finite().then_some(best)
}

/// The supporting planes `(n, d)` (sensor frame, `n·p <= d` inside) of a convex
/// polyhedron's triangulated surface, whose intersection is exactly the hull. (parry's
/// polygonal faces merge nearly coplanar triangles, so their planes are not exact.) Empty
/// for other shapes.
fn hull_planes(shape: &dyn Shape, pose: &Pose) -> Vec<(Vector, f32)> {
    let Some(poly) = shape.as_convex_polyhedron() else {
        return Vec::new();
    };
    let (vertices, indices) = poly.to_trimesh();
    let world: Vec<Vector> = vertices.iter().map(|&v| pose.transform_point(v)).collect();
    let centroid = world.iter().copied().sum::<Vector>() / world.len() as f32;
    indices
        .iter()
        .filter_map(|t| {
            let [a, b, c] = t.map(|i| world[i as usize]);
            let n = (b - a).cross(c - a).try_normalize()?;
            let n = if n.dot(centroid - a) > 0.0 { -n } else { n };
            Some((n, n.dot(a)))
        })
        .collect()
}

/// Distance (m) from `p` to a round cuboid or round cylinder (0 inside), exactly: the distance
/// to the inner shape, which parry projects on analytically, minus the border. `None` for
/// other shapes.
fn round_distance(shape: &dyn Shape, pose: &Pose, p: Vector) -> Option<f32> {
    let (inner, border) = match (shape.as_round_cuboid(), shape.as_round_cylinder()) {
        (Some(r), _) => (r.inner_shape.distance_to_point(pose, p, true), r.border_radius),
        (_, Some(r)) => (r.inner_shape.distance_to_point(pose, p, true), r.border_radius),
        _ => return None,
    };
    Some((inner - border).max(0.0))
}

/// Distance from `p` to the shape (0 inside), exact where parry's projection is not
/// (convex polyhedra and round shapes go through parry's f32 GJK): face planes and the
/// triangulated surface for polyhedra, see [`round_distance`] for round cuboids and
/// cylinders.
fn exact_distance(shape: &dyn Shape, pose: &Pose, p: Vector) -> f32 {
    if let Some(poly) = shape.as_convex_polyhedron() {
        if hull_planes(shape, pose).iter().all(|&(n, d)| n.dot(p) <= d) {
            return 0.0;
        }
        let (vertices, indices) = poly.to_trimesh();
        let local = pose.inverse_transform_point(p);
        return indices
            .iter()
            .map(|t| {
                Triangle::new(
                    vertices[t[0] as usize],
                    vertices[t[1] as usize],
                    vertices[t[2] as usize],
                )
                .distance_to_local_point(local, true)
            })
            .fold(f32::INFINITY, f32::min);
    }
    round_distance(shape, pose, p).unwrap_or_else(|| shape.distance_to_point(pose, p, true))
}

/// Checks the invariants of a hit: distance = |point|, point in the volume, point on or in
/// the shape, unit normal facing the sensor.
pub(super) fn check_hit(vol: &ProximityVolume, shape: &dyn Shape, pose: &Pose, hit: &ProximityHit) {
    let len = hit.point.length();
    assert!((hit.distance - len).abs() <= 1.0e-6, "{hit:?}");
    match *vol {
        ProximityVolume::Cone {
            offset,
            range,
            half_angle,
        } => {
            assert!(hit.distance >= offset - 1.0e-6, "{hit:?}");
            assert!(hit.distance <= offset + range + 1.0e-6, "{hit:?}");
            if len > 1.0e-6 {
                let angle = (hit.point.z / len).clamp(-1.0, 1.0).acos();
                assert!(angle <= half_angle + 1.0e-4, "angle {angle} {hit:?}");
            }
        }
        ProximityVolume::Ray { offset, range } => {
            assert!(hit.point.x.abs() <= 1.0e-6 && hit.point.y.abs() <= 1.0e-6);
            assert!(hit.distance >= offset - 1.0e-6);
            assert!(hit.distance <= offset + range + 1.0e-6);
        }
        ProximityVolume::Pyramid { .. } | ProximityVolume::Cylinder { .. } | ProximityVolume::Disc { .. } => {
            panic!("polytope volumes have their own tests (polytope.rs)")
        }
    }
    let dist = exact_distance(shape, pose, hit.point);
    assert!(
        dist <= 3.0e-6,
        "point {:?} is {dist} m off the {:?}: {hit:?} {pose:?} {vol:?} {:?}",
        hit.point,
        shape.shape_type(),
        shape.as_cuboid()
    );
    assert!((hit.normal.length() - 1.0).abs() <= 1.0e-4, "{hit:?}");
    assert!(hit.normal.dot(hit.point) <= 1.0e-6, "normal not facing: {hit:?}");
}

/// Detects, checks invariants and compares with the oracle.
pub(super) fn assert_matches_oracle(vol: &ProximityVolume, shape: &dyn Shape, pose: &Pose) -> Option<ProximityHit> {
    let hit = vol.detect(shape, pose);
    let expected = oracle(vol, shape, pose);
    match (hit, expected) {
        (None, None) => {}
        (Some(h), Some(e)) => {
            check_hit(vol, shape, pose, &h);
            assert!(
                (h.distance - e).abs() <= TOL,
                "{:?}: detector {} vs oracle {e} (diff {:e}) for {pose:?}",
                shape.shape_type(),
                h.distance,
                h.distance - e
            );
        }
        (h, e) => panic!("{:?}: detector {h:?} vs oracle {e:?} for {pose:?}", shape.shape_type()),
    }
    hit
}
