//! The near cap: when the nearest point `q` of a convex shape `S` inside the cone `K` is closer
//! than `offset` (`a`), the detection is at exactly `a` if `S ∩ K` reaches `|p| >= a`, and
//! nothing otherwise (see `convex.rs`).
//!
//! # Method and why it is exact
//!
//! Writing `C = S ∩ K` and `t_max` the largest `|p|` over `C`, the answer is `a` iff
//! `t_max >= a`, and then any point of `C` on the sphere `|p| = a` is a nearest detection. We
//! look for a witness `r ∈ C` with `|r| >= a`; the segment from the minimiser `q` to `r` stays
//! in `C` and crosses `|p| = a` exactly once (closed form). For the ray this is exact and
//! trivial (`(0, 0, a) ∈ S`). For the cone, `t_max` is attained at an extreme point of `C`,
//! which lies on `∂S`, either inside `K` or on the curve `∂S ∩ ∂K`, where
//! `|p| = z / cos(half_angle)` is linear. This makes the witness search exact for cuboids and
//! triangles (vertices inside `K`, edge/cone crossings, and the far vertex of each face plane's
//! conic section) and for balls (farthest point, or the exit point on the generator facing the
//! centre). Convex polyhedra use the same rule, exact when parry's faces are planar (parry
//! merges hull triangles up to ~1.5° apart into one face, so face candidates are projected back
//! onto the true hull). For the other smooth solids (cylinder, capsule, cone, round shapes,
//! generic support maps) maximising `|p|` over `C` is a non-convex problem; we use a fixed set
//! of probes (points of the near cap, support points and farthest-point iterations clipped to
//! `K`, exit points on 16 generators). They can only miss a solid whose part beyond `offset` is
//! a thin sliver between the probes (under a millimetre), i.e. an obstacle essentially inside
//! the dead zone; that case reports `None` (3 cases in 16 000 random tests, out of ~1 800
//! near-cap detections).
//!
//! parry has no query for the witness search (the farthest point of a convex shape inside a
//! cone is not a distance, projection or ray-cast problem), so that part is ours; the final
//! crossing of `|p| = a` is parry's ray–ball query.

use core::f32::consts::TAU;

use parry3d::math::{Pose, Vector};
use parry3d::query::Ray;
use parry3d::query::details::ray_toi_with_ball;
use parry3d::shape::{ConvexPolyhedron, Cuboid, Shape, SupportMap, Triangle, TypedShape};

use super::geom::Geom;
use super::hit::{ProximityHit, cap_hit, origin_hit};
use super::shape_query::{ON_SHAPE_TOL, on_shape, projection};

/// Number of generators (azimuths) probed by the generic near-cap search.
const CAP_PROBE_AZIMUTHS: usize = 16;

/// Near cap: `q ∈ S ∩ K` with `|q| < a` is the minimiser. Finds a point of `S ∩ K` at exactly
/// `|p| = a`, if any (see the module documentation for why the witnesses are exact).
pub(super) fn near_cap(
    geom: &Geom,
    shape: &dyn Shape,
    support_map: &dyn SupportMap,
    pose: &Pose,
    q: Vector,
) -> Option<ProximityHit> {
    let a = geom.near;
    if a <= 0.0 {
        // Only reached with the origin inside the solid: detection at the sensor itself.
        return Some(origin_hit());
    }
    if geom.is_ray() {
        // S ∩ axis is the segment [t*, t_out]: it reaches `a` iff (0, 0, a) is in S.
        let p = Vector::Z * a;
        return on_shape(shape, support_map, pose, p).then(|| cap_hit(p));
    }
    let reach = match shape.as_typed_shape() {
        TypedShape::Ball(ball) => ball_reach(geom, pose.translation, ball.radius),
        TypedShape::Cuboid(cuboid) => cuboid_reach(geom, cuboid, pose),
        TypedShape::Triangle(tri) => triangle_reach(geom, shape, support_map, tri, pose),
        TypedShape::ConvexPolyhedron(poly) => polyhedron_reach(geom, shape, poly, pose, q),
        _ => generic_reach(geom, shape, support_map, pose, q),
    }?;
    Some(cap_hit(crossing(q, reach, a)))
}

/// The point of the segment `[q, r]` at distance `a` from the origin, given `|q| < a <= |r|`
/// (unique because `|q + λ(r - q)|` is convex in `λ`). Snapped radially onto `|p| = a`.
fn crossing(q: Vector, r: Vector, a: f32) -> Vector {
    let v = r - q;
    // Where the ray from `q` along `v` leaves the ball `|p| <= a`: from inside, parry's
    // non-solid ray–ball query gives the exit time, here `λ` in units of `v`.
    let (_, exit) = ray_toi_with_ball(Vector::ZERO, a, &Ray::new(q, v), false);
    let p = match exit {
        Some(lambda) => q + v * lambda.clamp(0.0, 1.0),
        None => r,
    };
    let len = p.length();
    if len > 0.0 { p * (a / len) } else { Vector::Z * a }
}

/// Ball (centre `c`, radius `rho`, sensor frame): exact witness of `|p| >= a` in `S ∩ K`.
/// The farthest point of the ball is the only local maximum of `|p|` on it; if it is outside
/// `K`, the maximum over `S ∩ K` lies on `∂K`, on the generator facing the centre (the exit
/// distance `c·d + sqrt(rho² - |c|² + (c·d)²)` grows with `c·d`). That exit point is in closed
/// form: parry's ray casts give the entry point, and the exit only from inside the ball.
fn ball_reach(geom: &Geom, c: Vector, rho: f32) -> Option<Vector> {
    let dc = c.length();
    let farthest = if dc > 0.0 {
        c * ((dc + rho) / dc)
    } else {
        Vector::Z * rho
    };
    if geom.in_cone(farthest) {
        return (farthest.length() >= geom.near).then_some(farthest);
    }
    let d = geom.generator(c.y.atan2(c.x));
    let cd = c.dot(d);
    let disc = rho * rho - dc * dc + cd * cd;
    if disc < 0.0 {
        return None;
    }
    let t_out = cd + disc.sqrt();
    (t_out >= geom.near).then_some(d * t_out)
}

/// Polytope vertex witness: the vertex itself if it is in `K` and beyond the near cap.
fn vertex_reach(geom: &Geom, v: Vector) -> Option<Vector> {
    (geom.in_cone(v) && v.length() >= geom.near).then_some(v)
}

/// Crossings of the edge `[v0, v1]` with the lateral cone surface that are beyond the near
/// cap. Solves `z²·sin² = (x² + y²)·cos²` along the edge, keeping `z >= 0` (positive nappe).
fn edge_reach(geom: &Geom, v0: Vector, v1: Vector) -> Option<Vector> {
    let e = v1 - v0;
    let (s2, c2) = (geom.sin * geom.sin, geom.cos * geom.cos);
    let qa = e.z * e.z * s2 - c2 * (e.x * e.x + e.y * e.y);
    let qb = 2.0 * (v0.z * e.z * s2 - c2 * (v0.x * e.x + v0.y * e.y));
    let qc = v0.z * v0.z * s2 - c2 * (v0.x * v0.x + v0.y * v0.y);
    let mut roots = [f32::NAN; 2];
    let scale = qb.abs().max(qc.abs()).max(f32::MIN_POSITIVE);
    if qa.abs() <= 1.0e-7 * scale {
        if qb != 0.0 {
            roots[0] = -qc / qb;
        }
    } else {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc < 0.0 {
            return None;
        }
        // The numerically stable pair of roots.
        let tmp = -0.5 * (qb + qb.signum() * disc.sqrt());
        roots[0] = tmp / qa;
        if tmp != 0.0 {
            roots[1] = qc / tmp;
        }
    }
    roots.into_iter().find_map(|s| {
        if !(0.0..=1.0).contains(&s) {
            return None;
        }
        let p = v0 + e * s;
        (p.z >= 0.0 && p.length() >= geom.near && geom.in_cone_slack(p)).then_some(p)
    })
}

/// The point of the conic `{n·p = d} ∩ ∂K` farthest from the apex, when that section is a
/// bounded ellipse. On `∂K`, `|p| = z / cos`, so this is the maximum of `z` on the ellipse,
/// reached on the generator opposite to the plane normal's azimuth.
fn conic_far_vertex(geom: &Geom, n: Vector, d: f32) -> Option<Vector> {
    let (n, d) = if d < 0.0 { (-n, -d) } else { (n, d) };
    if d <= 0.0 {
        // Plane through the apex: the section is made of generators, handled by the edges.
        return None;
    }
    let rho = (n.x * n.x + n.y * n.y).sqrt();
    let min_rate = n.z * geom.cos - rho * geom.sin;
    if min_rate <= 0.0 {
        // Parabola or hyperbola: |p| is unbounded along it; the edges bound the face's arcs.
        return None;
    }
    Some(geom.generator((-n.y).atan2(-n.x)) * (d / min_rate))
}

/// [`conic_far_vertex`] of the face plane `n·p = d`, provided it is beyond the near cap and
/// `inside` accepts it (i.e. it lies on the face).
fn face_reach(geom: &Geom, n: Vector, d: f32, inside: impl Fn(Vector) -> bool) -> Option<Vector> {
    conic_far_vertex(geom, n, d).filter(|&p| p.length() >= geom.near && inside(p))
}

/// Exact near-cap witness for a cuboid (vertices, edges, faces).
fn cuboid_reach(geom: &Geom, cuboid: &Cuboid, pose: &Pose) -> Option<Vector> {
    let h = cuboid.half_extents;
    let corners: [Vector; 8] = core::array::from_fn(|i| {
        let sx = if i & 1 == 0 { -h.x } else { h.x };
        let sy = if i & 2 == 0 { -h.y } else { h.y };
        let sz = if i & 4 == 0 { -h.z } else { h.z };
        pose.transform_point(Vector::new(sx, sy, sz))
    });
    if let Some(v) = corners.iter().find_map(|&v| vertex_reach(geom, v)) {
        return Some(v);
    }
    // The 12 edges join corners differing in exactly one bit.
    for (i, &corner) in corners.iter().enumerate() {
        for bit in [1, 2, 4] {
            if i & bit == 0
                && let Some(p) = edge_reach(geom, corner, corners[i | bit])
            {
                return Some(p);
            }
        }
    }
    let tol = ON_SHAPE_TOL + 1.0e-6 * h.max_element();
    let inside = |p: Vector| {
        let l = pose.inverse_transform_point(p);
        l.x.abs() <= h.x + tol && l.y.abs() <= h.y + tol && l.z.abs() <= h.z + tol
    };
    for (axis, local_n) in Vector::AXES.into_iter().enumerate() {
        for sign in [-1.0, 1.0] {
            let n = pose.rotation * (local_n * sign);
            let d = n.dot(pose.translation) + h[axis];
            if let Some(p) = face_reach(geom, n, d, inside) {
                return Some(p);
            }
        }
    }
    None
}

/// Exact near-cap witness for a triangle (a thin solid).
fn triangle_reach(
    geom: &Geom,
    shape: &dyn Shape,
    support_map: &dyn SupportMap,
    tri: &Triangle,
    pose: &Pose,
) -> Option<Vector> {
    let v = [
        pose.transform_point(tri.a),
        pose.transform_point(tri.b),
        pose.transform_point(tri.c),
    ];
    if let Some(p) = v.iter().find_map(|&p| vertex_reach(geom, p)) {
        return Some(p);
    }
    for i in 0..3 {
        if let Some(p) = edge_reach(geom, v[i], v[(i + 1) % 3]) {
            return Some(p);
        }
    }
    // A degenerate triangle has no face of its own: its edges said it all.
    let n = pose.rotation * tri.normal()?;
    face_reach(geom, n, n.dot(v[0]), |p| on_shape(shape, support_map, pose, p))
}

/// Near-cap witness for a convex polyhedron: vertices, edges and face conics as for the
/// cuboid. parry merges hull triangles whose normals differ by up to about 1.5° into one
/// polygonal face and drops the crease between them, so a face plane is only approximately
/// the hull's surface: each face candidate is projected onto the true hull (the convex hull of
/// the points, which the support map describes) and clipped to the cone, which makes it an
/// exact witness, possibly reaching slightly less far than the true extreme point. The generic
/// probes follow as a last resort. Exact when the faces are planar.
fn polyhedron_reach(geom: &Geom, shape: &dyn Shape, poly: &ConvexPolyhedron, pose: &Pose, q: Vector) -> Option<Vector> {
    let points = poly.points();
    if let Some(p) = points.iter().find_map(|&p| vertex_reach(geom, pose.transform_point(p))) {
        return Some(p);
    }
    for edge in poly.edges() {
        let [i, j] = edge.vertices;
        let (Some(&a), Some(&b)) = (points.get(i as usize), points.get(j as usize)) else {
            continue;
        };
        if let Some(p) = edge_reach(geom, pose.transform_point(a), pose.transform_point(b)) {
            return Some(p);
        }
    }
    let adjacency = poly.vertices_adj_to_face();
    for face in poly.faces() {
        let on_face = adjacency
            .get(face.first_vertex_or_edge as usize)
            .and_then(|&vid| points.get(vid as usize));
        let Some(&on_face) = on_face else {
            continue;
        };
        let n = pose.rotation * face.normal;
        let Some(p) = conic_far_vertex(geom, n, n.dot(pose.transform_point(on_face))) else {
            continue;
        };
        if p.length() < geom.near {
            continue;
        }
        // Onto the hull (if not already in it), then back into the cone.
        let on_hull = projection(shape, poly, pose, p).unwrap_or(p);
        let witness = clip_to_cone(geom, q, on_hull);
        if witness.length() >= geom.near {
            return Some(witness);
        }
    }
    generic_reach(geom, shape, poly, pose, q)
}

/// Clips the segment `[q, r]` (with `q ∈ K`) to the cone: the feasible part is an interval
/// `[0, λmax]` because `K` is convex, found by bisection on the membership test.
fn clip_to_cone(geom: &Geom, q: Vector, r: Vector) -> Vector {
    if geom.in_cone(r) {
        return r;
    }
    let (mut lo, mut hi) = (0.0_f32, 1.0_f32);
    for _ in 0..32 {
        let mid = 0.5 * (lo + hi);
        if geom.in_cone_slack(q + (r - q) * mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    q + (r - q) * lo
}

/// Near-cap witness search for smooth convex solids without an exact rule (see the module
/// documentation). Every accepted candidate is a point of `S ∩ K`.
fn generic_reach(
    geom: &Geom,
    shape: &dyn Shape,
    support_map: &dyn SupportMap,
    pose: &Pose,
    q: Vector,
) -> Option<Vector> {
    let a = geom.near;
    let accept = |p: Vector| (p.length() >= a).then_some(p);
    let ring = |k: usize, polar: f32| {
        let phi = TAU * k as f32 / CAP_PROBE_AZIMUTHS as f32;
        let (sp, cp) = polar.sin_cos();
        let (s, c) = phi.sin_cos();
        Vector::new(sp * c, sp * s, cp)
    };

    // 1. Points of the near cap itself: axis, the minimiser's direction, two rings.
    let q_dir = q.normalize_or(Vector::Z);
    let cap_dirs = [q_dir, Vector::Z]
        .into_iter()
        .chain((0..CAP_PROBE_AZIMUTHS).map(|k| ring(k, 0.5 * geom.half_angle)))
        .chain((0..CAP_PROBE_AZIMUTHS).map(|k| ring(k, geom.half_angle)));
    for u in cap_dirs {
        if geom.in_cone_slack(u) && on_shape(shape, support_map, pose, u * a) {
            return Some(u * a);
        }
    }

    // 2. Support points (extreme points of S) and farthest-point iterations, clipped to K.
    let mut u = Vector::Z;
    for _ in 0..6 {
        let r = support_map.support_point(pose, u);
        if let Some(p) = accept(clip_to_cone(geom, q, r)) {
            return Some(p);
        }
        // Fixed points of u ↦ normalize(support(u)) are the local maxima of |p| over S; the
        // iteration increases |p| monotonically.
        let next = r.normalize_or_zero();
        if next == Vector::ZERO || next.dot(u) > 1.0 - 1.0e-7 {
            break;
        }
        u = next;
    }
    for k in 0..CAP_PROBE_AZIMUTHS {
        let r = support_map.support_point(pose, ring(k, geom.half_angle));
        if let Some(p) = accept(clip_to_cone(geom, q, r)) {
            return Some(p);
        }
    }

    // 3. Exit points of the shape on lateral generators (points of S ∩ ∂K). parry's ray casts
    // on these shapes can be inexact (see `shape_query::has_analytic_ray_cast`), so each candidate is
    // verified against the shape before use.
    let sphere = shape.compute_bounding_sphere(pose);
    let far = sphere.center.length() + sphere.radius + 1.0;
    for k in 0..CAP_PROBE_AZIMUTHS {
        let d = geom.generator(TAU * k as f32 / CAP_PROBE_AZIMUTHS as f32);
        let ray = Ray::new(d * far, -d);
        if let Some(toi) = shape.cast_ray(pose, &ray, far, true)
            && let Some(p) = accept(d * (far - toi))
            && on_shape(shape, support_map, pose, p)
        {
            return Some(p);
        }
    }
    None
}
