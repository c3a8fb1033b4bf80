//! Exact detection volumes of CoppeliaSim-style proximity sensors.
//!
//! This module is pure geometry: given a sensor volume and one parry shape posed in the
//! sensor frame, it returns the point of the shape inside the volume that is nearest to the
//! sensor origin. Broad-phase culling (which shapes to test) is the caller's job; see
//! [`ProximityVolume::local_aabb`].
//!
//! # Frames and units
//!
//! Everything is expressed in the **sensor frame**: the origin is the sensor, it looks along
//! its local **+Z** axis. Lengths are metres, angles radians.
//!
//! # Volumes
//!
//! * [`ProximityVolume::Ray`]: the segment from `(0, 0, offset)` to `(0, 0, offset + range)`.
//! * [`ProximityVolume::Cone`]: the spherical-shell sector
//!   `V = { p : angle(p, +Z) <= half_angle, offset <= |p| <= offset + range }`,
//!   bounded by the lateral cone surface and two spherical caps of radii `offset` (near cap)
//!   and `offset + range` (far cap). Scene files usually give the *full* opening angle
//!   (e.g. 30°); pass half of it.
//!
//! # What is detected
//!
//! The detection is the point of `shape ∩ volume` nearest to the sensor origin, its distance
//! `|p|` and a unit normal. Shapes are taken as what parry says they are:
//!
//! * Volumetric primitives (ball, cuboid, cylinder, capsule, cone, convex polyhedron, round
//!   shapes, any other shape exposing a support map, half-spaces) are **solids**. When a solid
//!   fills the near cap (an obstacle closer than `offset` that also extends beyond it), the
//!   detection is at exactly `offset`, at a point inside the solid; there is no surface there,
//!   so the normal is `-point / |point|`, pointing back at the sensor (`-Z` for the ray). A
//!   solid entirely closer than `offset` is not detected. (CoppeliaSim only sees triangles and
//!   would report the nearest triangle point beyond the near cap, or nothing; we deliberately
//!   report the obstacle.)
//! * Triangle meshes, height fields and polylines are **surfaces**: each triangle (segment) is
//!   a thin solid, so a closed mesh is hollow, exactly as in CoppeliaSim.
//! * Compounds are the union of their parts.
//! * Shapes that are none of the above (voxels, custom shapes without a support map) are not
//!   supported: `detect` returns `None`.
//!
//! Normals are unit vectors in the sensor frame, pointing out of the shape and towards the
//! sensor side (`normal · point <= 0`). On a face it is the face normal; on an edge or a
//! vertex (where the surface normal is undefined) it is a vector of the normal cone, namely
//! the direction of the separating plane between the shape and the volume.
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
//!    * C. otherwise the minimiser `q` lies on the lateral surface of `K`: were `q` interior
//!      to `K`, it would be a local, hence (convexity) global, minimiser of `|p|` over `S`,
//!      i.e. `p0`, which is not in `K`. We find `t*` as the smallest `t` for which `S` touches
//!      the sector `Q_t = K ∩ B(t)`. Because `Q_t = t·Q_1`, `g(t) = dist(S, Q_t)` is convex and
//!      non-increasing in `t`, and for any unit `n`, `g(t) >= min_S(n·x) - t·h_{Q_1}(n)`
//!      (separating plane; `h` is the support function). Starting from `t = |p0|` (a lower
//!      bound), each step runs GJK between `S` and `Q_t`, takes the separating direction `n`
//!      and moves to the root of that affine lower bound, `t ← min_S(n·x) / h_{Q_1}(n)`.
//!      Every iterate is a *certified lower bound* of `t*` whatever the GJK accuracy; with the
//!      exact `n` this is Newton's method on a convex function, which converges monotonically
//!      (quadratically in practice, 2–5 steps; GJK only needs an accuracy of order `g²/t` at
//!      each step, so intermediate runs stop early). `h_{Q_1}(n) <= 0` with `min_S(n·x) > 0`
//!      certifies that a plane through the apex separates `S` from the whole cone. It stops
//!      once the error bound `g / h` falls below 1e-6 of the distance. The minimiser is then
//!      the rim point of `Q_t*` facing the shape: its azimuth comes from the GJK witness on the
//!      sector of one more full-precision run just below `t*`, and the reported point is
//!      `t*·generator(azimuth)`. The normal is computed separately (exact face normals for
//!      triangles and polyhedra, radial for balls, else the projection of nearby outside points,
//!      see `surface_normal`). Balls are solved in closed form.
//!      When the contact is grazing (`h` small) the separating direction is too ill-conditioned
//!      for f32 support points and Newton stalls with the gap open; the first-hit distance along
//!      the generators, which is flat there, is then minimised over the azimuth by golden
//!      section near the witness (each value a feasible point, i.e. an upper bound).
//!      A sampled minimisation over the azimuth alone would not be exact in general: the
//!      first-hit distance along the generators can be bimodal (a thin rod crossing the cone is
//!      hit near both sides) and arcs narrower than the sampling step are missed.
//! 2. **Near cap**, when `t* < a`: the answer is `a` iff `t_max >= a`, and then any point of
//!    `C` on the sphere `|p| = a` is a nearest detection. We look for a witness `r ∈ C` with
//!    `|r| >= a`; the segment from the minimiser `q` to `r` stays in `C` and crosses `|p| = a`
//!    exactly once (closed form). For the ray this is exact and trivial (`(0, 0, a) ∈ S`).
//!    For the cone, `t_max` is attained at an extreme point of `C`, which lies on `∂S`, either
//!    inside `K` or on the curve `∂S ∩ ∂K`, where `|p| = z / cos(half_angle)` is linear. This
//!    makes the witness search exact for cuboids and triangles (vertices inside `K`,
//!    edge/cone crossings, and the far vertex of each face plane's conic section) and for balls
//!    (farthest point, or the exit point on the generator facing the centre). Convex polyhedra
//!    use the same rule, exact when parry's faces are planar (parry merges hull triangles up to
//!    ~1.5° apart into one face, so face candidates are projected back onto the true hull).
//!    For the other smooth solids (cylinder, capsule, cone, round shapes, generic support
//!    maps) maximising `|p|` over `C` is a non-convex problem; we use a fixed set of probes
//!    (points of the near cap, support points and farthest-point iterations clipped to `K`,
//!    exit points on 16 generators). They can only miss a solid whose part beyond `offset` is
//!    a thin sliver between the probes (under a millimetre), i.e. an obstacle essentially
//!    inside the dead zone; that case reports `None` (3 cases in 16 000 random tests, out of
//!    ~1 800 near-cap detections).
//!
//! Composite shapes are handled part by part, walking parry's BVH and pruning nodes whose
//! AABB misses the volume AABB or is farther than the best detection so far. Half-spaces are
//! solved in closed form.
//!
//! # Numerics, accuracy and cost
//!
//! parry 0.31's own GJK runs in f32 with relative tolerances around 1e-3: on thin shapes
//! (triangles) it can report an intersection across a 1e-4-relative gap, its projections on
//! convex polyhedra can misreport outside points as inside, and its GJK-based ray casts
//! (cylinder, cone, convex polyhedron, round shapes) can return hits about a millimetre early
//! (see dimforge/parry PR #414). None of these is used: the lateral search and the projections
//! on shapes without an analytic projection use a small f64 GJK (only the local support points
//! come from parry in f32; poses are applied in f64), and parry's ray casts are only used
//! where they are analytic (ball, cuboid, capsule, triangle).
//!
//! Distances are exact to about 1e-6 of the distance (a micrometre at 1 m; 2e-5 of it at
//! worst when the search stalls on a curved–curved contact), points lie within a few
//! micrometres of the surface, normals within ~1e-5 rad on flat faces and ~1e-3 rad on curved
//! surfaces. The tests compare against an independent brute-force oracle; an ignored stress
//! test (`cargo test --release -- --ignored stress`) does so on thousands of random cases.
//! Cost (release build, one core): the fast path is one point projection, ~80 ns for
//! primitives; the lateral path ~0.1 µs for balls and 2–7 µs for other shapes; a mesh costs
//! that per triangle reaching the volume. Nothing allocates.

use core::f32::consts::{FRAC_PI_2, TAU};

use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::{Pose, Vector};
use parry3d::partitioning::TraversalAction;
use parry3d::query::{PointQuery, Ray};
use parry3d::shape::{
    CompositeShape, ConvexPolyhedron, Cuboid, HalfSpace, HeightField, Shape, ShapeType, SupportMap, Triangle,
    TypedShape,
};

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
/// First estimate of a lateral detection's normal: project the point moved this fraction of
/// its distance towards the sensor (see `surface_normal`).
const NORMAL_PROBE_REL: f32 = 1.0e-4;
/// Lever arm of the normal refinement, as a fraction of the shape's bounding radius.
const NORMAL_LEVER_REL: f32 = 0.05;
/// Below this distance (m) GJK considers the two shapes touching.
const GJK_TOUCH: f64 = 1.0e-9;
/// GJK always stops when the duality gap on the distance is below this fraction of it.
const GJK_REL_GAP: f64 = 1.0e-12;
/// Absolute GJK tolerance (m) for point projections.
const PROJECTION_TOL: f64 = 1.0e-10;
/// GJK iteration cap (it typically converges in fewer than 10 iterations).
const GJK_MAX_ITERS: usize = 64;
/// Half-width (rad) of the azimuth bracket of the lateral fallback search.
const AZIMUTH_BRACKET: f32 = 0.03;
/// Golden-section iterations of the lateral fallback (0.03 rad × 0.618^30 ≈ 1e-8 rad).
const GOLDEN_STEPS: usize = 30;
/// Relative slack when testing whether a witness point lies in the cone.
const CONE_SLACK: f32 = 1.0e-6;
/// Absolute distance (m) under which a point counts as lying on a shape.
const ON_SHAPE_TOL: f32 = 1.0e-6;
/// Number of generators (azimuths) probed by the generic near-cap search.
const CAP_PROBE_AZIMUTHS: usize = 16;

/// The detection volume of a CoppeliaSim-style proximity sensor, in the sensor frame (the
/// sensor sits at the origin and looks along +Z). Lengths in metres, angles in radians.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ProximityVolume {
    /// The segment from `(0, 0, offset)` to `(0, 0, offset + range)`.
    Ray {
        /// Distance (m) from the sensor origin to the start of the segment, `>= 0`.
        offset: f32,
        /// Length (m) of the segment, `> 0`.
        range: f32,
    },
    /// The points `p` with `angle(p, +Z) <= half_angle` and
    /// `offset <= |p| <= offset + range` (two spherical caps and the lateral cone surface).
    Cone {
        /// Radius (m) of the near spherical cap, `>= 0`; nothing closer is detected.
        offset: f32,
        /// Depth (m) of the volume, `> 0`; the far cap has radius `offset + range`.
        range: f32,
        /// Half of the full opening angle (rad), in `(0, π/2)`.
        half_angle: f32,
    },
}

/// The nearest detected point of a shape, in the sensor frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProximityHit {
    /// Distance (m) from the sensor origin to [`point`](Self::point), i.e. `|point|`.
    pub distance: f32,
    /// The detected point (m), sensor frame.
    pub point: Vector,
    /// Unit normal at the point, sensor frame, pointing out of the shape towards the sensor
    /// side (`normal · point <= 0`). For a detection clamped to the near cap (the point is
    /// inside a solid) it is `-point / |point|` (`-Z` when the point is the origin).
    pub normal: Vector,
}

impl ProximityVolume {
    /// Whether the parameters are usable: finite, `offset >= 0`, `range > 0` and, for the
    /// cone, `0 < half_angle < π/2` (radians). [`detect`](Self::detect) returns `None` for an
    /// invalid volume.
    pub fn is_valid(&self) -> bool {
        let (offset, range, half_angle) = self.params();
        offset.is_finite()
            && range.is_finite()
            && offset >= 0.0
            && range > 0.0
            && (matches!(self, Self::Ray { .. }) || (half_angle > 0.0 && half_angle < FRAC_PI_2))
    }

    /// Axis-aligned bounding box (m) of the volume in the sensor frame, for broad-phase culling
    /// by the caller. It is tight: the ray's box is the segment itself (zero width in X and Y),
    /// the cone's is `[-r, r]² × [offset·cos(half_angle), offset + range]` with
    /// `r = (offset + range)·sin(half_angle)`.
    pub fn local_aabb(&self) -> Aabb {
        let (offset, range, half_angle) = self.params();
        Geom::new(offset, offset + range, half_angle).aabb()
    }

    /// Nearest detection of one shape placed at `shape_pose` (the pose of the shape in the
    /// **sensor** frame), or `None` when no point of the shape lies in the volume, when the
    /// volume is invalid (see [`is_valid`](Self::is_valid)) or when the shape type is not
    /// supported (voxels, custom shapes without a support map).
    ///
    /// See the module documentation for the exact semantics (solids versus surfaces, the
    /// near cap) and the method.
    pub fn detect(&self, shape: &dyn Shape, shape_pose: &Pose) -> Option<ProximityHit> {
        if !self.is_valid() {
            return None;
        }
        let (offset, range, half_angle) = self.params();
        let geom = Geom::new(offset, offset + range, half_angle);
        let mut best = None;
        detect_shape(&geom, shape, shape_pose, &mut best);
        best
    }

    /// `(offset, range, half_angle)`, the ray being the cone of half-angle 0.
    fn params(&self) -> (f32, f32, f32) {
        match *self {
            Self::Ray { offset, range } => (offset, range, 0.0),
            Self::Cone {
                offset,
                range,
                half_angle,
            } => (offset, range, half_angle),
        }
    }
}

/// Precomputed volume: near/far cap radii (m) and the half-angle's trigonometry. A half-angle
/// of 0 is the ray: the cone degenerates to the +Z half-line and every formula below still
/// holds (the sector `Q_t` becomes the segment `[0, t]·Z`).
#[derive(Clone, Copy, Debug)]
struct Geom {
    /// Near cap radius `a` (m).
    near: f32,
    /// Far cap radius `b` (m).
    far: f32,
    half_angle: f32,
    cos: f32,
    sin: f32,
}

impl Geom {
    fn new(near: f32, far: f32, half_angle: f32) -> Self {
        let (sin, cos) = half_angle.sin_cos();
        Self {
            near,
            far,
            half_angle,
            cos,
            sin,
        }
    }

    fn is_ray(&self) -> bool {
        self.half_angle == 0.0
    }

    /// Whether `p` lies in the infinite cone `K` (apex included).
    fn in_cone(&self, p: Vector) -> bool {
        p.z >= p.length() * self.cos
    }

    /// [`Self::in_cone`] with a small relative slack, for witnesses computed on `∂K`.
    fn in_cone_slack(&self, p: Vector) -> bool {
        p.z >= p.length() * (self.cos - CONE_SLACK)
    }

    /// Unit direction of the lateral generator at azimuth `phi` (rad).
    fn generator(&self, phi: f32) -> Vector {
        let (s, c) = phi.sin_cos();
        Vector::new(self.sin * c, self.sin * s, self.cos)
    }

    /// Cheap rejection with a bounding sphere (centre `c`, radius `r`, sensor frame): false
    /// when the sphere is entirely farther than `limit` (m) or entirely outside the cone.
    fn sphere_may_touch(&self, c: Vector, r: f32, limit: f32) -> bool {
        let dc = c.length();
        if dc - r > limit {
            return false;
        }
        if dc <= r {
            return true;
        }
        let axis_angle = (c.z / dc).clamp(-1.0, 1.0).acos();
        axis_angle - (r / dc).asin() <= self.half_angle
    }

    /// The volume AABB (see [`ProximityVolume::local_aabb`]).
    fn aabb(&self) -> Aabb {
        let r = self.far * self.sin;
        Aabb::new(Vector::new(-r, -r, self.near * self.cos), Vector::new(r, r, self.far))
    }
}

/// Replaces `best` by `candidate` when the latter is strictly nearer.
fn keep_nearest(best: &mut Option<ProximityHit>, candidate: Option<ProximityHit>) {
    if let Some(c) = candidate
        && best.is_none_or(|b| c.distance < b.distance)
    {
        *best = Some(c);
    }
}

/// Largest distance (m) still worth finding: the far cap, or the best detection so far.
fn limit(geom: &Geom, best: &Option<ProximityHit>) -> f32 {
    best.map_or(geom.far, |b| b.distance.min(geom.far))
}

/// Dispatches on the shape type and merges its detection into `best`.
fn detect_shape(geom: &Geom, shape: &dyn Shape, pose: &Pose, best: &mut Option<ProximityHit>) {
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
fn detect_composite(geom: &Geom, composite: &dyn CompositeShape, pose: &Pose, best: &mut Option<ProximityHit>) {
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
fn detect_height_field(geom: &Geom, hf: &HeightField, pose: &Pose, best: &mut Option<ProximityHit>) {
    let volume_local = geom.aabb().transform_by(&pose.inverse());
    hf.map_elements_in_local_aabb(&volume_local, &mut |_, tri: &Triangle| {
        let lim = limit(geom, best);
        keep_nearest(best, detect_convex(geom, tri, tri, pose, lim));
    });
}

/// Closed form for a half-space `{ p : n·p <= c }` (sensor frame, `n` the outward normal).
fn detect_half_space(geom: &Geom, hs: &HalfSpace, pose: &Pose) -> Option<ProximityHit> {
    let n = pose.rotation * hs.normal;
    let c = n.dot(pose.translation);
    if c >= 0.0 {
        // The sensor is inside: t* = 0. The nearest volume point is on the near cap; prefer
        // the axis, else the cap direction minimising n·u, i.e. the rim point at the azimuth
        // of -n (exact: that is where the cap reaches deepest into the solid).
        let a = geom.near;
        if a <= 0.0 {
            return Some(origin_hit());
        }
        let mut dir = Vector::Z;
        if a * n.z > c {
            dir = geom.generator((-n.y).atan2(-n.x));
            if a * n.dot(dir) > c {
                return None;
            }
        }
        return Some(cap_hit(dir * a));
    }
    // Sensor outside at distance -c. Along a unit direction u the solid starts at
    // t = c / (n·u) when n·u < 0: minimise it by maximising -n·u over the cone's directions,
    // i.e. u = -n if that is in the cone, else the generator at the azimuth of -n.
    let w = -n;
    let (dir, depth_rate) = if w.z >= geom.cos {
        (w, 1.0)
    } else {
        let dir = geom.generator(w.y.atan2(w.x));
        (dir, w.dot(dir))
    };
    if depth_rate <= 0.0 {
        return None;
    }
    let t = -c / depth_rate;
    if t > geom.far {
        return None;
    }
    if t < geom.near {
        // The same direction stays inside the solid beyond t, so it reaches the near cap.
        return Some(cap_hit(dir * geom.near));
    }
    Some(ProximityHit {
        distance: t,
        point: dir * t,
        normal: n,
    })
}

/// Detection at the sensor origin (offset 0 and the origin inside a solid).
fn origin_hit() -> ProximityHit {
    ProximityHit {
        distance: 0.0,
        point: Vector::ZERO,
        normal: -Vector::Z,
    }
}

/// Detection clamped to the near cap at `point` (inside the solid): normal pointing back.
fn cap_hit(point: Vector) -> ProximityHit {
    let distance = point.length();
    ProximityHit {
        distance,
        point,
        normal: if distance > 0.0 { -point / distance } else { -Vector::Z },
    }
}

/// Whether parry projects points on this shape type analytically (exactly). The other
/// convex shapes go through parry's f32 GJK, which we replace by ours.
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
/// are GJK-based and can be a millimetre early (see the module documentation).
fn has_analytic_ray_cast(shape: &dyn Shape) -> bool {
    matches!(
        shape.shape_type(),
        ShapeType::Ball | ShapeType::Cuboid | ShapeType::Capsule | ShapeType::Triangle
    )
}

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

/// Projection of `p` (sensor frame) on the convex shape, or `None` when `p` is inside it (or
/// on its surface, within GJK's tolerance).
fn projection(shape: &dyn Shape, support_map: &dyn SupportMap, pose: &Pose, p: Vector) -> Option<Vector> {
    if has_analytic_projection(shape) {
        let proj = shape.project_point(pose, p, true);
        (!proj.is_inside).then_some(proj.point)
    } else {
        let p64 = D3::from(p);
        let towards = D3::from(pose.translation) - p64;
        let mut simplex = Simplex::default();
        let probe = Probe::Point(p64);
        gjk_closest_points(probe, support_map, pose, towards, PROJECTION_TOL, &mut simplex)
            .map(|(on_shape, _)| on_shape.to_f32())
    }
}

/// Distance (m) from `p` (sensor frame) to the convex shape, 0 inside.
fn point_distance(shape: &dyn Shape, support_map: &dyn SupportMap, pose: &Pose, p: Vector) -> f32 {
    projection(shape, support_map, pose, p).map_or(0.0, |proj| (proj - p).length())
}

/// Whether `p` (sensor frame) lies on or in the convex shape, within [`ON_SHAPE_TOL`].
fn on_shape(shape: &dyn Shape, support_map: &dyn SupportMap, pose: &Pose, p: Vector) -> bool {
    point_distance(shape, support_map, pose, p) <= ON_SHAPE_TOL + 1.0e-6 * p.length()
}

/// Nearest detection of a convex shape (see the module documentation, cases A, B, C and the
/// near cap). `limit` (m) is the largest distance still of interest.
fn detect_convex(
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

/// Case C: minimum of `|p|` over `S ∩ K` when it lies on the lateral surface of `K`
/// (`p0`, the projection of the origin on the shape, is outside `K`). See the module
/// documentation for the certified Newton iteration.
fn lateral_minimum(
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
    let mut dir = D3::from(p0) / t;
    // Witness on the sector of the latest GJK run (its azimuth is the minimiser's).
    let mut on_rim = D3::from(p0);
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
        let dist = gap.length();
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
        let min_along = dir.dot(shape_support(support_map, pose, -dir));
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
    let on_rim = on_rim.to_f32();
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
    let normal = lateral_normal(shape, support_map, pose, point, dir.to_f32(), sphere.radius);
    Some(ProximityHit {
        distance: t32,
        point,
        normal: facing_sensor(normal, point),
    })
}

/// Outward unit normal of the convex shape at its surface point `q` (sensor frame), for a
/// detection reached along the generator through `q` (so the points just before `q` on it are
/// outside the shape). `size` (m) is the shape's bounding radius.
///
/// The first estimate projects a point just before `q` back onto the shape; for a point `o`
/// outside a convex shape, `o - proj(o)` is exactly a normal at `proj(o)`. Its accuracy is
/// limited by the f32 rounding of the projection relative to the short offset (~1e-3 rad).
/// Two fixed-point steps then project `q + L·n` with a longer offset `L`: that point projects
/// back onto `q` exactly when `n` is the normal at `q`, and the iteration contracts the error by
/// `L / (L + radius of curvature)` per step while the rounding error falls to ~1e-6 rad.
fn surface_normal(
    shape: &dyn Shape,
    support_map: &dyn SupportMap,
    pose: &Pose,
    q: Vector,
    size: f32,
) -> Option<Vector> {
    let outside = q * (1.0 - NORMAL_PROBE_REL);
    let mut normal = (outside - projection(shape, support_map, pose, outside)?).normalize_or_zero();
    if normal == Vector::ZERO {
        return None;
    }
    let lever = NORMAL_LEVER_REL * size;
    for _ in 0..2 {
        let o = q + normal * lever;
        let Some(proj) = projection(shape, support_map, pose, o) else {
            break;
        };
        let refined = (o - proj).normalize_or_zero();
        if refined == Vector::ZERO {
            break;
        }
        normal = refined;
    }
    Some(normal)
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

/// Case C in closed form for a ball (centre `c`, radius `rho`, sensor frame). The plane
/// through the axis and the centre is a symmetry plane of the problem and the minimiser is
/// unique, so it lies on the generator at the centre's azimuth, where the first hit is
/// `c·d - sqrt(rho² - |c|² + (c·d)²)`. That generator is also the lateral one nearest to the
/// centre: if it misses the ball, the ball does not reach the cone's surface at all.
fn ball_lateral(geom: &Geom, c: Vector, rho: f32, limit: f32) -> Option<ProximityHit> {
    let d = geom.generator(c.y.atan2(c.x));
    let cd = c.dot(d);
    let disc = rho * rho - c.length_squared() + cd * cd;
    if disc < 0.0 {
        return None;
    }
    let t = cd - disc.sqrt();
    // t < 0 would put the ball behind the sensor (the origin inside it is case A).
    if t < 0.0 || t > limit {
        return None;
    }
    let point = d * t;
    Some(ProximityHit {
        distance: t,
        point,
        normal: facing_sensor(point - c, point),
    })
}

/// Normal at the lateral minimiser `point` of a convex shape: exact face or radial normals
/// where the shape type gives them, else [`surface_normal`]. `separating` is the last
/// separating direction of the Newton iteration (from the sector towards the shape), whose
/// opposite is a valid normal and the fallback.
fn lateral_normal(
    shape: &dyn Shape,
    support_map: &dyn SupportMap,
    pose: &Pose,
    point: Vector,
    separating: Vector,
    size: f32,
) -> Vector {
    let normal = match shape.as_typed_shape() {
        TypedShape::Triangle(tri) => tri.normal().map(|n| pose.rotation * n),
        TypedShape::ConvexPolyhedron(poly) => {
            // The feature whose normal cone contains the outward direction -separating.
            let local = pose.rotation.inverse() * -separating;
            poly.feature_normal(poly.support_feature_id_toward(local))
                .map(|n| pose.rotation * n)
        }
        _ => surface_normal(shape, support_map, pose, point, size),
    };
    normal.unwrap_or(-separating)
}

/// Normalises `normal` and orients it towards the sensor (`normal · point <= 0`), falling back
/// to `-point / |point|` when it is degenerate.
fn facing_sensor(normal: Vector, point: Vector) -> Vector {
    let n = normal.normalize_or_zero();
    if n == Vector::ZERO || !n.is_finite() {
        -point.normalize_or(Vector::Z)
    } else if n.dot(point) > 0.0 {
        -n
    } else {
        n
    }
}

/// Support function of the unit sector `Q_1 = K ∩ B(1)` in direction `n`: `max(n · p)` over
/// `Q_1`, which is `|n|` if `n` points into the cone, else the value at the rim point of `n`'s
/// azimuth, or 0 at the apex.
fn unit_sector_support_value(geom: &Geom, n: D3) -> f64 {
    let (cos, sin) = (f64::from(geom.cos), f64::from(geom.sin));
    let len = n.length();
    if n.z >= len * cos {
        len
    } else {
        let rxy = (n.x * n.x + n.y * n.y).sqrt();
        (n.z * cos + rxy * sin).max(0.0)
    }
}

/// Minimal f64 3-vector for the GJK (parry's glam is built without f64 types).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct D3 {
    x: f64,
    y: f64,
    z: f64,
}

impl D3 {
    const ZERO: Self = Self::new(0.0, 0.0, 0.0);

    const fn new(x: f64, y: f64, z: f64) -> Self {
        Self { x, y, z }
    }
    fn dot(self, o: Self) -> f64 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    fn length_squared(self) -> f64 {
        self.dot(self)
    }
    fn length(self) -> f64 {
        self.length_squared().sqrt()
    }
    fn cross(self, o: Self) -> Self {
        Self::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }
    fn to_f32(self) -> Vector {
        Vector::new(self.x as f32, self.y as f32, self.z as f32)
    }
}

impl From<Vector> for D3 {
    fn from(v: Vector) -> Self {
        Self::new(f64::from(v.x), f64::from(v.y), f64::from(v.z))
    }
}

impl core::ops::Add for D3 {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl core::ops::Sub for D3 {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Self::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl core::ops::Neg for D3 {
    type Output = Self;
    fn neg(self) -> Self {
        Self::new(-self.x, -self.y, -self.z)
    }
}

impl core::ops::Mul<f64> for D3 {
    type Output = Self;
    fn mul(self, k: f64) -> Self {
        Self::new(self.x * k, self.y * k, self.z * k)
    }
}

impl core::ops::Div<f64> for D3 {
    type Output = Self;
    fn div(self, k: f64) -> Self {
        Self::new(self.x / k, self.y / k, self.z / k)
    }
}

/// Support point of the shape (sensor frame) in direction `dir`, in f64. Only the local
/// support point comes from parry in f32; the pose is applied in f64, because parry's f32
/// transform adds rounding of order 1e-8 m at 0.1 m, which is what limits how close to the
/// contact the lateral search can resolve the separating direction.
fn shape_support(support_map: &dyn SupportMap, pose: &Pose, dir: D3) -> D3 {
    let q = pose.rotation;
    let (axis, w) = (D3::from(Vector::new(q.x, q.y, q.z)), f64::from(q.w));
    let local_dir = rotate(-axis, w, dir);
    let local = D3::from(support_map.local_support_point(local_dir.to_f32()));
    rotate(axis, w, local) + D3::from(pose.translation)
}

/// Rotates `v` by the quaternion `(axis, w)` (glam's formula, in f64).
fn rotate(axis: D3, w: f64, v: D3) -> D3 {
    let b2 = axis.length_squared();
    v * (w * w - b2) + axis * (2.0 * v.dot(axis)) + axis.cross(v) * (2.0 * w)
}

/// The simple convex set GJK measures the shape against.
#[derive(Clone, Copy)]
enum Probe<'a> {
    /// A single point (sensor frame, m).
    Point(D3),
    /// The sector `Q_t = K ∩ B(t)` with `t = radius` (m).
    Sector { geom: &'a Geom, radius: f64 },
}

impl Probe<'_> {
    fn support(&self, dir: D3) -> D3 {
        match *self {
            Self::Point(p) => p,
            Self::Sector { geom, radius } => {
                let (cos, sin) = (f64::from(geom.cos), f64::from(geom.sin));
                let len = dir.length();
                if len <= 0.0 || !len.is_finite() {
                    return D3::ZERO;
                }
                if dir.z >= len * cos {
                    // The direction points into the cone: a point of the spherical cap.
                    return dir * (radius / len);
                }
                let rxy = (dir.x * dir.x + dir.y * dir.y).sqrt();
                if rxy <= 0.0 {
                    // Straight backwards: the apex.
                    return D3::ZERO;
                }
                // The rim point at the direction's azimuth, unless the apex is further.
                let k = radius * sin / rxy;
                let rim = D3::new(dir.x * k, dir.y * k, radius * cos);
                if dir.dot(rim) > 0.0 { rim } else { D3::ZERO }
            }
        }
    }
}

/// A vertex of the GJK simplex: the point `w = x - y` of the Minkowski difference
/// `S - probe`, with its witnesses `x ∈ S` and `y ∈ probe`.
#[derive(Clone, Copy, Debug, Default)]
struct CsoVertex {
    w: D3,
    x: D3,
    y: D3,
}

/// A GJK simplex (up to 4 vertices), kept between calls to warm-start the next one.
#[derive(Clone, Copy, Debug, Default)]
struct Simplex {
    vertices: [CsoVertex; 4],
    len: usize,
}

impl Simplex {
    /// Re-targets the simplex at the sector scaled by `ratio`: support points of `k·Q` are
    /// `k` times those of `Q` in the same direction, so every vertex stays a valid point of the
    /// new Minkowski difference and GJK resumes close to the answer.
    fn rescale_probe(&mut self, ratio: f64) {
        for vertex in &mut self.vertices[..self.len] {
            vertex.y = vertex.y * ratio;
            vertex.w = vertex.x - vertex.y;
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
fn gjk_closest_points(
    probe: Probe<'_>,
    support_map: &dyn SupportMap,
    pose: &Pose,
    towards: D3,
    tolerance: f64,
    simplex: &mut Simplex,
) -> Option<(D3, D3)> {
    let support = |d: D3| {
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
        let vv = v.length_squared();
        if vv <= GJK_TOUCH * GJK_TOUCH {
            return None;
        }
        let s = support(-v);
        // Duality gap |v|·(|v| - lower bound): stop once the distance is known precisely
        // enough.
        let gap = vv - v.dot(s.w);
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
        if found.0.length_squared() >= vv {
            // No progress (rounding): keep the previous answer.
            simplex.len -= 1;
            break;
        }
        bary = keep_face(simplex, &found);
        v = found.0;
    }
    let mut x = D3::ZERO;
    let mut y = D3::ZERO;
    for (p, &l) in simplex.vertices[..simplex.len].iter().zip(&bary) {
        x = x + p.x * l;
        y = y + p.y * l;
    }
    Some((x, y))
}

/// The closest point to the origin of a simplex's hull: the point, the indices of the
/// vertices of the face holding it and their barycentric weights (unused slots weigh 0).
type SimplexPoint = (D3, [usize; 3], [f64; 3]);

/// Closest point to the origin of the hull of `simplex`, or `None` when the origin is inside
/// a (non-flat) tetrahedron, i.e. the shapes overlap. Does not modify the simplex; see
/// [`keep_face`].
fn closest_on_simplex(simplex: &Simplex) -> Option<SimplexPoint> {
    let w: [D3; 4] = core::array::from_fn(|i| simplex.vertices[i].w);
    match simplex.len {
        1 => Some((w[0], [0, 0, 0], [1.0, 0.0, 0.0])),
        2 => Some(closest_on_segment(w, 0, 1)),
        3 => Some(closest_on_triangle(w, [0, 1, 2])),
        _ => {
            // The four faces with the index of the vertex opposite to each.
            const FACES: [([usize; 3], usize); 4] = [([0, 1, 2], 3), ([0, 2, 3], 1), ([0, 3, 1], 2), ([1, 3, 2], 0)];
            // The origin is outside iff some face plane separates it from the opposite vertex
            // (or the tetrahedron is flat). The closest point is then on the faces; all four
            // are searched, because with nearly flat tetrahedra the sign tests can pick the
            // wrong face, which stalls GJK on grazing contacts.
            let outside = FACES.iter().any(|&(face, opposite)| {
                let [a, b, c] = face.map(|i| w[i]);
                let n = (b - a).cross(c - a);
                let to_opposite = w[opposite] - a;
                let side_opposite = to_opposite.dot(n);
                let flat = side_opposite * side_opposite <= 1.0e-24 * n.length_squared() * to_opposite.length_squared();
                flat || -a.dot(n) * side_opposite < 0.0
            });
            if !outside {
                return None;
            }
            let mut best: Option<SimplexPoint> = None;
            for (face, _) in FACES {
                let candidate = closest_on_triangle(w, face);
                if best.is_none_or(|b| candidate.0.length_squared() < b.0.length_squared()) {
                    best = Some(candidate);
                }
            }
            best
        }
    }
}

/// Reduces the simplex to the face of `found` (see [`closest_on_simplex`]), dropping the
/// vertices of zero weight; returns the barycentric coordinates in the new vertex order.
fn keep_face(simplex: &mut Simplex, found: &SimplexPoint) -> [f64; 4] {
    let (_, used, lambda) = *found;
    let old = simplex.vertices;
    let count = simplex.len.min(3);
    let mut bary = [0.0; 4];
    let mut n = 0;
    for k in 0..count {
        if lambda[k] > 0.0 {
            simplex.vertices[n] = old[used[k]];
            bary[n] = lambda[k];
            n += 1;
        }
    }
    if n == 0 {
        simplex.vertices[0] = old[used[0]];
        bary[0] = 1.0;
        n = 1;
    }
    simplex.len = n;
    bary
}

/// Closest point to the origin on the segment `[w[i], w[j]]`: the point, the two vertex
/// indices and their weights (padded to three).
fn closest_on_segment(w: [D3; 4], i: usize, j: usize) -> (D3, [usize; 3], [f64; 3]) {
    let (a, b) = (w[i], w[j]);
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 { -a.dot(ab) / len2 } else { 0.0 };
    if t <= 0.0 {
        (a, [i, j, j], [1.0, 0.0, 0.0])
    } else if t >= 1.0 {
        (b, [i, j, j], [0.0, 1.0, 0.0])
    } else {
        (a + ab * t, [i, j, j], [1.0 - t, t, 0.0])
    }
}

/// Closest point to the origin on the triangle `w[face]` (Ericson's region tests): the point,
/// the vertex indices and their weights.
fn closest_on_triangle(w: [D3; 4], face: [usize; 3]) -> (D3, [usize; 3], [f64; 3]) {
    let [ia, ib, ic] = face;
    let (a, b, c) = (w[ia], w[ib], w[ic]);
    let ab = b - a;
    let ac = c - a;
    let d1 = -ab.dot(a);
    let d2 = -ac.dot(a);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, face, [1.0, 0.0, 0.0]);
    }
    let d3 = -ab.dot(b);
    let d4 = -ac.dot(b);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, face, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let t = d1 / (d1 - d3);
        return (a + ab * t, face, [1.0 - t, t, 0.0]);
    }
    let d5 = -ab.dot(c);
    let d6 = -ac.dot(c);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, face, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let t = d2 / (d2 - d6);
        return (a + ac * t, face, [1.0 - t, 0.0, t]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * t, face, [0.0, 1.0 - t, t]);
    }
    let sum = va + vb + vc;
    if sum <= 0.0 || !sum.is_finite() {
        // Degenerate (flat) triangle: the closest point is on one of its edges.
        let edges = [
            closest_on_segment(w, ia, ib),
            closest_on_segment(w, ib, ic),
            closest_on_segment(w, ia, ic),
        ];
        let mut best = edges[0];
        for e in &edges[1..] {
            if e.0.length_squared() < best.0.length_squared() {
                best = *e;
            }
        }
        return best;
    }
    let v = vb / sum;
    let t = vc / sum;
    (a + ab * v + ac * t, face, [1.0 - v - t, v, t])
}

/// Near cap: `q ∈ S ∩ K` with `|q| < a` is the minimiser. Finds a point of `S ∩ K` at exactly
/// `|p| = a`, if any (see the module documentation).
fn near_cap(
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
    let vv = v.length_squared();
    let qv = q.dot(v);
    let c0 = q.length_squared() - a * a;
    let p = if vv > 0.0 {
        let disc = (qv * qv - vv * c0).max(0.0).sqrt();
        // The positive root of vv·λ² + 2·qv·λ + c0, in a cancellation-free form.
        let lambda = if qv >= 0.0 { -c0 / (qv + disc) } else { (disc - qv) / vv };
        q + v * lambda.clamp(0.0, 1.0)
    } else {
        r
    };
    let len = p.length();
    if len > 0.0 { p * (a / len) } else { Vector::Z * a }
}

/// Ball (centre `c`, radius `rho`, sensor frame): exact witness of `|p| >= a` in `S ∩ K`.
/// The farthest point of the ball is the only local maximum of `|p|` on it; if it is outside
/// `K`, the maximum over `S ∩ K` lies on `∂K`, on the generator facing the centre (the exit
/// distance `c·d + sqrt(rho² - |c|² + (c·d)²)` grows with `c·d`).
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
    let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero();
    if n == Vector::ZERO {
        return None;
    }
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
    // on these shapes can be inexact (see the module documentation), so each candidate is
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

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d::math::Rotation;
    use parry3d::shape::{
        Ball, Capsule, Compound, Cone, ConvexPolyhedron, Cuboid, Cylinder, HalfSpace, HeightField, RoundShape,
        SharedShape, TriMesh,
    };
    use parry3d::utils::Array2;

    /// Tolerance (m) required between the detector and the brute-force oracle.
    const TOL: f32 = 1.0e-5;

    /// The scene used in most tests: offset 0.005 m, range 0.15 m, full angle 30°.
    fn small_cone() -> ProximityVolume {
        ProximityVolume::Cone {
            offset: 0.005,
            range: 0.15,
            half_angle: 15f32.to_radians(),
        }
    }

    fn cone_params(vol: &ProximityVolume) -> (f32, f32, f32) {
        match *vol {
            ProximityVolume::Cone {
                offset,
                range,
                half_angle,
            } => (offset, offset + range, half_angle),
            ProximityVolume::Ray { .. } => panic!("the oracle handles cones only"),
        }
    }

    /// Tiny deterministic xorshift generator (no external dependency).
    struct Rng(u64);
    impl Rng {
        fn next_f32(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
        fn range(&mut self, lo: f32, hi: f32) -> f32 {
            lo + (hi - lo) * self.next_f32()
        }
        fn rotation(&mut self) -> Rotation {
            let axis = Vector::new(self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0))
                .normalize_or(Vector::X);
            Rotation::from_axis_angle(axis, self.range(0.0, TAU))
        }
    }

    fn direction(theta: f32, phi: f32) -> Vector {
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        Vector::new(st * cp, st * sp, ct)
    }

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
    fn oracle(vol: &ProximityVolume, shape: &dyn Shape, pose: &Pose) -> Option<f32> {
        const FAR: f32 = 50.0;
        const EPS: f32 = 1.0e-7;
        const STEP: f32 = 1.0e-6;
        let (a, b, alpha) = cone_params(vol);
        // parry's projections on round shapes go through its f32 GJK, which can be off by tens
        // of micrometres: use the exact inner-cuboid distance minus the border instead.
        let round = shape.as_round_cuboid();
        let dist = |p: Vector| match round {
            Some(r) => (r.inner_shape.distance_to_point(pose, p, true) - r.border_radius).max(0.0),
            None => shape.distance_to_point(pose, p, true),
        };
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
            if round.is_some() {
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
        let eval = |theta: f32, phi: f32| -> f32 {
            eval_dir(direction(theta.clamp(0.0, alpha), phi)).unwrap_or(f32::INFINITY)
        };
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

    /// Distance from `p` to the shape (0 inside), exact where parry's projection is not
    /// (convex polyhedra and round shapes go through parry's f32 GJK): face planes and the
    /// triangulated surface for polyhedra, inner-cuboid distance minus the border for round
    /// cuboids.
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
        if let Some(r) = shape.as_round_cuboid() {
            return (r.inner_shape.distance_to_point(pose, p, true) - r.border_radius).max(0.0);
        }
        shape.distance_to_point(pose, p, true)
    }

    /// Checks the invariants of a hit: distance = |point|, point in the volume, point on or in
    /// the shape, unit normal facing the sensor.
    fn check_hit(vol: &ProximityVolume, shape: &dyn Shape, pose: &Pose, hit: &ProximityHit) {
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
    fn assert_matches_oracle(vol: &ProximityVolume, shape: &dyn Shape, pose: &Pose) -> Option<ProximityHit> {
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

    fn box_trimesh(h: Vector) -> TriMesh {
        let v: Vec<Vector> = (0..8)
            .map(|i| {
                Vector::new(
                    if i & 1 == 0 { -h.x } else { h.x },
                    if i & 2 == 0 { -h.y } else { h.y },
                    if i & 4 == 0 { -h.z } else { h.z },
                )
            })
            .collect();
        let idx = vec![
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        TriMesh::new(v, idx).expect("a closed box is a valid trimesh")
    }

    #[test]
    fn ball_straight_ahead() {
        let vol = small_cone();
        let ball = Ball::new(0.02);
        let pose = Pose::translation(0.0, 0.0, 0.1);
        let hit = vol.detect(&ball, &pose).expect("ball ahead is detected");
        assert!((hit.distance - 0.08).abs() <= 1.0e-6);
        assert!((hit.normal - Vector::new(0.0, 0.0, -1.0)).length() <= 1.0e-6);
        check_hit(&vol, &ball, &pose, &hit);
        assert_matches_oracle(&vol, &ball, &pose);
    }

    #[test]
    fn ball_off_axis_partly_inside() {
        let vol = small_cone();
        let ball = Ball::new(0.02);
        // Centre at 25° off axis, 0.1 m away: only part of the ball is inside the 15° cone.
        for (k, phi) in [0.0f32, 1.0, 2.5, 4.0].into_iter().enumerate() {
            let c = direction(25f32.to_radians(), phi) * 0.1;
            let pose = Pose::from_translation(c);
            let hit = assert_matches_oracle(&vol, &ball, &pose).expect("partly inside");
            // Not the fast path: the nearest point of the ball is outside the cone.
            assert!(hit.distance > 0.08 + 1.0e-4, "case {k}: {hit:?}");
            // The normal of a ball is radial.
            let radial = (hit.point - c).normalize();
            assert!((hit.normal - radial).length() <= 1.0e-3, "{hit:?}");
        }
    }

    #[test]
    fn cuboid_face_on_and_rotated() {
        let vol = small_cone();
        let cuboid = Cuboid::new(Vector::new(0.05, 0.05, 0.02));
        let pose = Pose::translation(0.003, -0.002, 0.1);
        let hit = vol.detect(&cuboid, &pose).expect("face-on cuboid");
        assert!((hit.distance - 0.08).abs() <= 1.0e-6);
        assert!((hit.normal - Vector::new(0.0, 0.0, -1.0)).length() <= 1.0e-6);
        check_hit(&vol, &cuboid, &pose, &hit);

        let mut rng = Rng(0x1234_5678);
        for _ in 0..6 {
            let pose = Pose::from_parts(
                Vector::new(rng.range(-0.04, 0.04), rng.range(-0.04, 0.04), 0.1),
                rng.rotation(),
            );
            assert_matches_oracle(&vol, &cuboid, &pose);
        }
        // A cuboid beside the cone whose corner pokes into it: lateral path.
        let pose = Pose::from_parts(Vector::new(0.055, 0.0, 0.1), Rotation::from_axis_angle(Vector::Y, 0.3));
        assert_matches_oracle(&vol, &cuboid, &pose).expect("corner inside the cone");
    }

    #[test]
    fn cylinder_seen_from_the_side() {
        // A 0.1 m-diameter vertical obstacle (sensor +Y is up, parry cylinders are Y-aligned)
        // whose surface is 0.1 m ahead of the sensor.
        let vol = small_cone();
        let cyl = Cylinder::new(0.2, 0.05);
        let pose = Pose::translation(0.0, 0.0, 0.15);
        let hit = vol.detect(&cyl, &pose).expect("cylinder ahead");
        assert!((hit.distance - 0.1).abs() <= 1.0e-6, "{hit:?}");
        assert!((hit.normal - Vector::new(0.0, 0.0, -1.0)).length() <= 1.0e-6);
        check_hit(&vol, &cyl, &pose, &hit);
        // Slid sideways until only its flank is inside the cone.
        for x in [0.03f32, 0.06, 0.075, -0.07] {
            let pose = Pose::translation(x, 0.0, 0.15);
            assert_matches_oracle(&vol, &cyl, &pose).expect("flank inside");
        }
        // Tilted.
        let pose = Pose::from_parts(
            Vector::new(0.06, 0.01, 0.14),
            Rotation::from_axis_angle(Vector::new(1.0, 0.0, 1.0).normalize(), 0.7),
        );
        assert_matches_oracle(&vol, &cyl, &pose);
    }

    #[test]
    fn outside_the_angle_is_none() {
        let vol = small_cone();
        let ball = Ball::new(0.02);
        let pose = Pose::from_translation(direction(40f32.to_radians(), 1.0) * 0.1);
        assert_eq!(vol.detect(&ball, &pose), None);
        assert_eq!(oracle(&vol, &ball, &pose), None);
        // A cuboid in the AABB corner but outside the cone.
        let cuboid = Cuboid::new(Vector::splat(0.005));
        let pose = Pose::translation(0.035, 0.035, 0.14);
        assert_eq!(vol.detect(&cuboid, &pose), None);
        // Behind the sensor.
        let pose = Pose::translation(0.0, 0.0, -0.1);
        assert_eq!(vol.detect(&ball, &pose), None);
    }

    #[test]
    fn beyond_range_is_none() {
        let vol = small_cone();
        let ball = Ball::new(0.02);
        // Nearest point at 0.156 m > 0.155 m.
        assert_eq!(vol.detect(&ball, &Pose::translation(0.0, 0.0, 0.176)), None);
        // Nearest point at 0.154 m: detected.
        let hit = vol.detect(&ball, &Pose::translation(0.0, 0.0, 0.174));
        assert!((hit.expect("inside range").distance - 0.154).abs() <= 1.0e-6);
        // Off-axis near the far cap corner: compare.
        let pose = Pose::from_translation(direction(20f32.to_radians(), 0.5) * 0.17);
        assert_matches_oracle(&vol, &ball, &pose);
    }

    #[test]
    fn closer_than_offset() {
        let vol = small_cone();
        // A thick wall starting 2 mm ahead: the volume starts inside it, at the near cap.
        let wall = Cuboid::new(Vector::new(0.1, 0.1, 0.02));
        let pose = Pose::translation(0.0, 0.0, 0.022);
        let hit = assert_matches_oracle(&vol, &wall, &pose).expect("wall fills the near cap");
        assert!((hit.distance - 0.005).abs() <= 1.0e-6);
        assert!((hit.normal + hit.point / hit.distance).length() <= 1.0e-5);
        // A thin plate entirely inside the dead zone: 1 mm thick at 2–3 mm. Its points in
        // the cone are at most 3 mm / cos 15° = 3.1 mm < 5 mm away.
        let plate = Cuboid::new(Vector::new(0.1, 0.1, 0.0005));
        let pose = Pose::translation(0.0, 0.0, 0.0025);
        assert_eq!(vol.detect(&plate, &pose), None);
        assert_eq!(oracle(&vol, &plate, &pose), None);
        // The same plate tilted by 80°: it now extends beyond the near cap inside the cone.
        let pose = Pose::from_parts(
            Vector::new(0.0, 0.0, 0.0025),
            Rotation::from_axis_angle(Vector::X, 80f32.to_radians()),
        );
        assert_matches_oracle(&vol, &plate, &pose).expect("tilted plate crosses the near cap");
        // A ball containing the sensor.
        let ball = Ball::new(0.05);
        let pose = Pose::translation(0.01, 0.0, 0.0);
        let hit = assert_matches_oracle(&vol, &ball, &pose).expect("sensor inside a ball");
        assert!((hit.distance - 0.005).abs() <= 1.0e-6);
        // A small ball partly inside the dead zone, off axis (lateral minimum below offset).
        let ball = Ball::new(0.003);
        for c in [
            Vector::new(0.003, 0.0, 0.004),
            Vector::new(0.0, 0.0, 0.004),
            Vector::new(0.0025, 0.001, 0.0035),
        ] {
            assert_matches_oracle(&vol, &ball, &Pose::from_translation(c));
        }
        // Offset zero and the sensor inside a solid: distance zero.
        let vol0 = ProximityVolume::Cone {
            offset: 0.0,
            range: 0.15,
            half_angle: 0.2,
        };
        let hit = vol0.detect(&Ball::new(0.05), &Pose::IDENTITY).expect("inside");
        assert_eq!(hit.distance, 0.0);
    }

    #[test]
    fn trimesh_box_equals_cuboid() {
        let vol = small_cone();
        let h = Vector::new(0.03, 0.02, 0.025);
        let cuboid = Cuboid::new(h);
        let mesh = box_trimesh(h);
        let mut rng = Rng(0xdead_beef);
        let mut lateral = 0;
        for i in 0..24 {
            let pose = Pose::from_parts(
                Vector::new(rng.range(-0.06, 0.06), rng.range(-0.06, 0.06), rng.range(0.05, 0.15)),
                rng.rotation(),
            );
            let a = vol.detect(&cuboid, &pose);
            let b = vol.detect(&mesh, &pose);
            match (a, b) {
                (None, None) => {}
                (Some(a), Some(b)) => {
                    assert!(
                        (a.distance - b.distance).abs() <= TOL,
                        "case {i}: cuboid {a:?} mesh {b:?}"
                    );
                    check_hit(&vol, &mesh, &pose, &b);
                    if !cuboid_fast_path(&vol, &cuboid, &pose) {
                        lateral += 1;
                    }
                }
                (a, b) => panic!("case {i}: cuboid {a:?} mesh {b:?}"),
            }
        }
        assert!(lateral > 0, "the random poses should exercise the lateral path");
    }

    fn cuboid_fast_path(vol: &ProximityVolume, cuboid: &Cuboid, pose: &Pose) -> bool {
        let (_, _, alpha) = cone_params(vol);
        let p = cuboid.project_point(pose, Vector::ZERO, true).point;
        (p.z / p.length()).acos() <= alpha
    }

    #[test]
    fn compound_is_the_nearest_part() {
        let vol = small_cone();
        let parts = vec![
            (Pose::translation(0.0, 0.0, 0.05), SharedShape::ball(0.01)),
            (
                Pose::from_parts(Vector::new(0.03, 0.0, 0.0), Rotation::from_axis_angle(Vector::Z, 0.4)),
                SharedShape::cuboid(0.01, 0.02, 0.01),
            ),
        ];
        let compound = Compound::new(parts.clone());
        let mut rng = Rng(42);
        for _ in 0..10 {
            let pose = Pose::from_parts(
                Vector::new(rng.range(-0.04, 0.04), rng.range(-0.04, 0.04), rng.range(0.02, 0.1)),
                rng.rotation(),
            );
            let whole = vol.detect(&compound, &pose);
            let mut best: Option<ProximityHit> = None;
            for (rel, part) in &parts {
                let h = vol.detect(part.as_ref(), &(pose * *rel));
                if let Some(h) = h {
                    check_hit(&vol, part.as_ref(), &(pose * *rel), &h);
                }
                keep_nearest(&mut best, h);
            }
            assert_eq!(whole.map(|h| h.distance), best.map(|h| h.distance));
        }
    }

    #[test]
    fn convex_shapes_against_oracle() {
        let vol = ProximityVolume::Cone {
            offset: 0.01,
            range: 0.3,
            half_angle: 20f32.to_radians(),
        };
        let hull = ConvexPolyhedron::from_convex_hull(&[
            Vector::new(0.0, 0.0, 0.03),
            Vector::new(0.03, 0.0, -0.01),
            Vector::new(-0.02, 0.025, -0.01),
            Vector::new(-0.02, -0.025, -0.01),
            Vector::new(0.01, 0.01, 0.02),
        ])
        .expect("non-degenerate hull");
        let shapes: [(&str, Box<dyn Shape>); 5] = [
            ("capsule", Box::new(Capsule::new_y(0.03, 0.01))),
            ("cone", Box::new(Cone::new(0.03, 0.02))),
            ("cylinder", Box::new(Cylinder::new(0.02, 0.015))),
            ("hull", Box::new(hull)),
            (
                "triangle",
                Box::new(Triangle::new(
                    Vector::new(0.0, 0.0, 0.0),
                    Vector::new(0.05, 0.0, 0.01),
                    Vector::new(0.0, 0.04, -0.01),
                )),
            ),
        ];
        let mut rng = Rng(7);
        for (name, shape) in &shapes {
            let mut found = 0;
            for _ in 0..8 {
                let pose = Pose::from_parts(
                    Vector::new(rng.range(-0.08, 0.08), rng.range(-0.08, 0.08), rng.range(0.0, 0.3)),
                    rng.rotation(),
                );
                if assert_matches_oracle(&vol, shape.as_ref(), &pose).is_some() {
                    found += 1;
                }
            }
            assert!(found > 0, "{name}: no random pose was detected");
        }
    }

    #[test]
    fn thin_rod_crossing_the_cone() {
        // The rod's nearest point is outside the cone; it enters on one side and leaves on
        // the other, so the first-hit distance along the generators is bimodal with narrow
        // arcs. The exact minimum is at the near crossing.
        let vol = small_cone();
        let rod = Capsule::new_x(0.2, 0.0005);
        let pose = Pose::from_parts(Vector::new(0.04, 0.0, 0.1), Rotation::from_axis_angle(Vector::Y, 0.5));
        let hit = assert_matches_oracle(&vol, &rod, &pose).expect("rod crosses the cone");
        assert!(hit.point.x > 0.0, "near crossing is on the +X side: {hit:?}");
    }

    #[test]
    fn half_space_floor() {
        // The floor is the world half-space y <= 0; `sensor_in_world` places the sensor.
        let vol = small_cone();
        let floor = HalfSpace::new(Vector::Y);
        let floor_pose = |height: f32, pitch_down_deg: f32| {
            let rot = Rotation::from_axis_angle(Vector::X, pitch_down_deg.to_radians());
            Pose::from_parts(Vector::new(0.0, height, 0.0), rot).inverse()
        };
        // 0.05 m above the floor, looking 20° down: the lowest rays dip 35°.
        let pose = floor_pose(0.05, 20.0);
        let hit = vol.detect(&floor, &pose).expect("floor in view");
        let expected = 0.05 / 35f32.to_radians().sin();
        assert!((hit.distance - expected).abs() <= 1.0e-6, "{hit:?} vs {expected}");
        check_hit(&vol, &floor, &pose, &hit);
        assert!((hit.normal - pose.rotation * Vector::Y).length() <= 1.0e-6);
        assert_matches_oracle(&vol, &floor, &pose);
        // Looking straight down from 0.1 m: fast path.
        let hit = vol.detect(&floor, &floor_pose(0.1, 90.0)).expect("floor below");
        assert!((hit.distance - 0.1).abs() <= 1.0e-6);
        // Looking up, or horizontally from too high: nothing.
        assert_eq!(vol.detect(&floor, &floor_pose(0.1, -90.0)), None);
        assert_eq!(vol.detect(&floor, &floor_pose(0.05, 0.0)), None);
        assert_eq!(oracle(&vol, &floor, &floor_pose(0.05, 0.0)), None);
        // Sensor below the floor surface (inside the solid): near cap.
        for pitch in [20.0, -20.0, 90.0, -90.0] {
            let pose = floor_pose(-0.01, pitch);
            let hit = vol.detect(&floor, &pose).expect("sensor inside the floor");
            assert!((hit.distance - 0.005).abs() <= 1.0e-6);
            check_hit(&vol, &floor, &pose, &hit);
        }
        // Sensor 2 mm under the surface looking up: the cap at 5 mm is above the floor.
        assert_eq!(vol.detect(&floor, &floor_pose(-0.002, -90.0)), None);
        // Floor 2 mm below the sensor: reached inside the dead zone, detected at the offset.
        let pose = floor_pose(0.002, 20.0);
        let hit = assert_matches_oracle(&vol, &floor, &pose).expect("floor crosses the cap");
        assert!((hit.distance - 0.005).abs() <= 1.0e-6);
    }

    #[test]
    fn ray_volume() {
        let vol = ProximityVolume::Ray {
            offset: 0.01,
            range: 0.2,
        };
        let ball = Ball::new(0.02);
        let hit = vol
            .detect(&ball, &Pose::translation(0.0, 0.0, 0.1))
            .expect("ball on the ray");
        assert!((hit.distance - 0.08).abs() <= 1.0e-6);
        assert!((hit.normal + Vector::Z).length() <= 1.0e-6);
        check_hit(&vol, &ball, &Pose::translation(0.0, 0.0, 0.1), &hit);
        // Off the ray: miss.
        assert_eq!(vol.detect(&ball, &Pose::translation(0.021, 0.0, 0.1)), None);
        // Beyond the range: miss.
        assert_eq!(vol.detect(&ball, &Pose::translation(0.0, 0.0, 0.231)), None);
        // Closer than the offset: not detected; straddling the offset: detected at the offset
        // with the normal pointing back.
        assert_eq!(vol.detect(&Ball::new(0.002), &Pose::translation(0.0, 0.0, 0.005)), None);
        let hit = vol
            .detect(&ball, &Pose::translation(0.0, 0.0, 0.0))
            .expect("ray starts inside");
        assert!((hit.distance - 0.01).abs() <= 1.0e-6);
        assert_eq!(hit.normal, -Vector::Z);
        // Tilted cuboid: the normal is the face normal, facing the sensor.
        let cuboid = Cuboid::new(Vector::splat(0.02));
        let pose = Pose::from_parts(Vector::new(0.0, 0.0, 0.1), Rotation::from_axis_angle(Vector::Y, 0.3));
        let hit = vol.detect(&cuboid, &pose).expect("cuboid on the ray");
        let face = pose.rotation * -Vector::Z;
        assert!((hit.normal - face).length() <= 1.0e-5, "{hit:?}");
        // A trimesh seen from inside: the back face is detected, normal facing the sensor.
        let mesh = box_trimesh(Vector::splat(0.05));
        let hit = vol.detect(&mesh, &Pose::IDENTITY).expect("inner face");
        assert!((hit.distance - 0.05).abs() <= 1.0e-6);
        assert!(hit.normal.z < 0.0);
        // Ray and a very narrow cone agree.
        let narrow = ProximityVolume::Cone {
            offset: 0.01,
            range: 0.2,
            half_angle: 1.0e-4,
        };
        let pose = Pose::translation(0.0, 0.0, 0.1);
        let a = vol.detect(&cuboid, &pose).expect("on the ray").distance;
        let b = narrow.detect(&cuboid, &pose).expect("in the narrow cone").distance;
        assert!((a - b).abs() <= 1.0e-6);
    }

    #[test]
    fn local_aabb_bounds_the_volume() {
        let vol = ProximityVolume::Cone {
            offset: 0.02,
            range: 0.3,
            half_angle: 0.4,
        };
        let aabb = vol.local_aabb();
        let mut rng = Rng(99);
        for _ in 0..2000 {
            let p = direction(rng.range(0.0, 0.4), rng.range(0.0, TAU)) * rng.range(0.02, 0.32);
            assert!(aabb.contains_local_point(p));
        }
        // Tight: the rim of the far cap and the near cap's rim touch the box.
        assert!((aabb.maxs.x - 0.32 * 0.4f32.sin()).abs() <= 1.0e-6);
        assert!((aabb.mins.z - 0.02 * 0.4f32.cos()).abs() <= 1.0e-6);
        let ray = ProximityVolume::Ray {
            offset: 0.1,
            range: 0.5,
        }
        .local_aabb();
        assert_eq!(ray.mins, Vector::new(0.0, 0.0, 0.1));
        assert_eq!(ray.maxs, Vector::new(0.0, 0.0, 0.6));
    }

    #[test]
    fn invalid_volumes_detect_nothing() {
        let ball = Ball::new(1.0);
        for vol in [
            ProximityVolume::Ray {
                offset: -1.0,
                range: 1.0,
            },
            ProximityVolume::Cone {
                offset: 0.0,
                range: 1.0,
                half_angle: FRAC_PI_2,
            },
            ProximityVolume::Cone {
                offset: 0.0,
                range: f32::NAN,
                half_angle: 0.1,
            },
        ] {
            assert!(!vol.is_valid());
            assert_eq!(vol.detect(&ball, &Pose::IDENTITY), None);
        }
    }

    #[test]
    fn ray_on_a_cylinder_is_exact() {
        // A configuration where parry 0.31's GJK-based ray cast on a cylinder reports a hit
        // about 1 mm early (found by the random test). Cylinder frame: the ray starts at `o`
        // and goes along `d`; it enters through the top cap y = half_height.
        let (half_height, radius) = (0.012_346_055_f32, 0.073_888_32_f32);
        let cyl = Cylinder::new(half_height, radius);
        let o = Vector::new(0.009_073_697, 0.119_934_79, -0.055_430_543);
        let d = Vector::new(0.455_847_05, -0.859_040_7, 0.232_922_32).normalize();
        let expected = (o.y - half_height) / -d.y;
        let entry = o + d * expected;
        assert!(Vector::new(entry.x, 0.0, entry.z).length() < radius);
        // The sensor sits at `o` looking along `d`.
        let sensor = Pose::from_parts(o, Rotation::from_rotation_arc(Vector::Z, d));
        let pose = sensor.inverse();
        let vol = ProximityVolume::Ray {
            offset: 0.0,
            range: 0.5,
        };
        let hit = vol.detect(&cyl, &pose).expect("the cap is hit");
        assert!((hit.distance - expected).abs() <= 2.0e-6, "{hit:?} vs {expected}");
        let cap_normal = pose.rotation * Vector::Y;
        assert!((hit.normal - cap_normal).length() <= 1.0e-3, "{hit:?}");
        // The cone sees the same cap point.
        let narrow = ProximityVolume::Cone {
            offset: 0.0,
            range: 0.5,
            half_angle: 1.0e-3,
        };
        let cone_hit = narrow.detect(&cyl, &pose).expect("cap in the narrow cone");
        assert!(cone_hit.distance <= expected + 1.0e-6);
        assert_matches_oracle(&narrow, &cyl, &pose);
    }

    #[test]
    fn height_field_matches_half_space() {
        // A flat 2 m × 2 m height field (surface y = 0) and the floor half-space y <= 0, seen
        // from 0.05 m above, looking 20° down: a height field is a surface, but seen from above
        // it is detected like the solid floor.
        let vol = small_cone();
        let heights = Array2::repeat(5, 5, 0.0);
        let hf = HeightField::new(heights, Vector::new(2.0, 1.0, 2.0));
        let floor = HalfSpace::new(Vector::Y);
        for (height, pitch) in [(0.05f32, 20.0f32), (0.05, 90.0), (0.03, 45.0), (0.05, 0.0)] {
            let rot = Rotation::from_axis_angle(Vector::X, pitch.to_radians());
            let pose = Pose::from_parts(Vector::new(0.1, height, -0.2), rot).inverse();
            let a = vol.detect(&hf, &pose);
            let b = vol.detect(&floor, &pose);
            assert_eq!(a.is_some(), b.is_some(), "{a:?} vs {b:?}");
            if let (Some(a), Some(b)) = (a, b) {
                assert!((a.distance - b.distance).abs() <= 1.0e-6, "{a:?} vs {b:?}");
                assert!((a.normal - b.normal).length() <= 1.0e-5, "{a:?} vs {b:?}");
                check_hit(&vol, &hf, &pose, &a);
            }
        }
    }

    #[test]
    fn lateral_contact_on_a_face() {
        // A large wall whose perpendicular foot is outside the cone: the nearest volume point
        // is on the cone's surface, inside the wall's face. It must match the closed form of
        // the same plane as a half-space, including the exact face normal.
        let vol = small_cone();
        let wall = Cuboid::new(Vector::new(0.5, 0.5, 0.01));
        let floor = HalfSpace::new(-Vector::Z);
        for (tilt, azimuth) in [(40f32, 0.3f32), (55.0, 2.0), (70.0, -1.0)] {
            // Wall normal (towards the sensor) tilted `tilt` degrees away from -Z.
            let rot =
                Rotation::from_axis_angle(Vector::Z, azimuth) * Rotation::from_axis_angle(Vector::Y, tilt.to_radians());
            let front = rot * -Vector::Z;
            let centre = -front * 0.06 + rot * Vector::new(0.0, 0.0, 0.01);
            let pose = Pose::from_parts(centre, rot);
            // The half-space bounded by the wall's front face.
            let plane_pose = Pose::from_parts(-front * 0.06, rot);
            let hit = vol.detect(&wall, &pose);
            let expected = vol.detect(&floor, &plane_pose);
            let (Some(hit), Some(expected)) = (hit, expected) else {
                panic!("tilt {tilt}: {hit:?} vs {expected:?}");
            };
            assert!(
                (hit.distance - expected.distance).abs() <= 2.0e-6,
                "{hit:?} vs {expected:?}"
            );
            assert!(
                (hit.point - expected.point).length() <= 1.0e-5,
                "{hit:?} vs {expected:?}"
            );
            assert!((hit.normal - front).length() <= 1.0e-5, "{hit:?} vs {front:?}");
            check_hit(&vol, &wall, &pose, &hit);
        }
    }

    #[test]
    fn round_cuboid_against_oracle() {
        let vol = small_cone();
        let shape = RoundShape {
            inner_shape: Cuboid::new(Vector::new(0.02, 0.01, 0.015)),
            border_radius: 0.005,
        };
        let mut rng = Rng(31);
        let mut found = 0;
        for _ in 0..3 {
            let pose = Pose::from_parts(
                Vector::new(rng.range(-0.04, 0.04), rng.range(-0.04, 0.04), rng.range(0.05, 0.12)),
                rng.rotation(),
            );
            if assert_matches_oracle(&vol, &shape, &pose).is_some() {
                found += 1;
            }
        }
        assert!(found > 0);
    }

    /// Long randomized comparison with the oracle over every convex shape type, cone shapes
    /// and offsets (including large offsets, to exercise the near cap). Run with
    /// `cargo test --release -- --ignored stress`.
    #[test]
    #[ignore = "slow: thousands of oracle evaluations"]
    fn stress_against_oracle() {
        let mut rng = Rng(0x5eed);
        let hull = ConvexPolyhedron::from_convex_hull(
            &(0..12)
                .map(|i| {
                    let a = i as f32 * 2.4;
                    let z = 1.0 - 2.0 * (i as f32 + 0.5) / 12.0;
                    Vector::new((1.0 - z * z).sqrt() * a.cos(), (1.0 - z * z).sqrt() * a.sin(), z) * 0.03
                })
                .collect::<Vec<_>>(),
        )
        .expect("hull");
        let (mut cases, mut detected, mut cap_misses, mut oracle_misses) = (0, 0, 0, 0);
        let mut worst: f32 = 0.0;
        let mut cap_hits = 0;
        for i in 0..1500 {
            let half_angle = rng.range(3.0, 60.0).to_radians();
            let offset = if i % 3 == 0 {
                rng.range(0.02, 0.08)
            } else {
                rng.range(0.0, 0.01)
            };
            let vol = ProximityVolume::Cone {
                offset,
                range: rng.range(0.05, 0.4),
                half_angle,
            };
            let shape: Box<dyn Shape> = match i % 8 {
                0 => Box::new(Ball::new(rng.range(0.003, 0.06))),
                1 => Box::new(Cuboid::new(Vector::new(
                    rng.range(0.002, 0.06),
                    rng.range(0.002, 0.06),
                    rng.range(0.002, 0.06),
                ))),
                2 => Box::new(Cylinder::new(rng.range(0.003, 0.06), rng.range(0.003, 0.06))),
                3 => Box::new(Capsule::new_x(rng.range(0.003, 0.06), rng.range(0.001, 0.03))),
                4 => Box::new(Cone::new(rng.range(0.003, 0.06), rng.range(0.003, 0.06))),
                5 => Box::new(hull.clone()),
                6 => Box::new(Triangle::new(
                    Vector::new(rng.range(-0.05, 0.05), rng.range(-0.05, 0.05), rng.range(-0.05, 0.05)),
                    Vector::new(rng.range(-0.05, 0.05), rng.range(-0.05, 0.05), rng.range(-0.05, 0.05)),
                    Vector::new(rng.range(-0.05, 0.05), rng.range(-0.05, 0.05), rng.range(-0.05, 0.05)),
                )),
                _ => Box::new(RoundShape {
                    inner_shape: Cuboid::new(Vector::new(
                        rng.range(0.002, 0.04),
                        rng.range(0.002, 0.04),
                        rng.range(0.002, 0.04),
                    )),
                    border_radius: rng.range(0.001, 0.01),
                }),
            };
            // One case in three (those with a large offset) is placed around the near cap.
            let (reach, z_min, z_max) = if i % 3 == 0 {
                (0.05, -0.02, offset + 0.05)
            } else {
                (0.15, -0.05, 0.3)
            };
            let pose = Pose::from_parts(
                Vector::new(
                    rng.range(-reach, reach),
                    rng.range(-reach, reach),
                    rng.range(z_min, z_max),
                ),
                rng.rotation(),
            );
            cases += 1;
            let hit = vol.detect(shape.as_ref(), &pose);
            let expected = oracle(&vol, shape.as_ref(), &pose);
            match (hit, expected) {
                (None, None) => {}
                (Some(h), Some(e)) => {
                    detected += 1;
                    // The detection is a genuine point of the shape in the volume (so it is
                    // >= the exact minimum) and no oracle sample, all feasible, beats it.
                    check_hit(&vol, shape.as_ref(), &pose, &h);
                    // The oracle accepts points within 1e-7 m of the surface, i.e. up to
                    // 1e-7 / cos(incidence) m early along its rays at grazing incidence.
                    let incidence = h.normal.dot(-h.point.normalize_or(Vector::Z)).max(0.01);
                    assert!(
                        h.distance <= e + 2.0e-6 + 1.0e-7 / incidence,
                        "case {i} {:?}: detector {h:?} vs oracle {e} for {vol:?} {pose:?}",
                        shape.shape_type()
                    );
                    if h.distance < e - TOL {
                        // The oracle's search stalled on a vertex or an edge.
                        oracle_misses += 1;
                    } else {
                        worst = worst.max((h.distance - e).abs());
                    }
                    if (h.distance - offset).abs() <= 1.0e-6 {
                        cap_hits += 1;
                    }
                }
                (None, Some(e)) if (e - offset).abs() <= TOL && matches!(i % 8, 2 | 3 | 4 | 7) => {
                    // The documented limitation: smooth solids barely reaching past the near cap.
                    cap_misses += 1;
                    eprintln!("near-cap miss: case {i} {:?} {vol:?} {pose:?}", shape.shape_type());
                }
                (Some(h), None) => {
                    // The oracle's grid can miss a sliver of contact; the detection must still
                    // be a genuine point of the shape in the volume.
                    check_hit(&vol, shape.as_ref(), &pose, &h);
                    oracle_misses += 1;
                }
                (h, e) => panic!(
                    "case {i} {:?}: detector {h:?} vs oracle {e:?} for {vol:?} {pose:?}",
                    shape.shape_type()
                ),
            }
        }
        eprintln!(
            "stress: {cases} cases, {detected} detections ({cap_hits} on the near cap), \
             {cap_misses} near-cap misses, \
             {oracle_misses} where the oracle's search fell short, worst distance difference \
             {worst:e} m otherwise"
        );
    }

    #[test]
    fn random_convex_poses_against_oracle() {
        // Wide cone, random primitives and poses, many of them straddling the boundary.
        let vol = ProximityVolume::Cone {
            offset: 0.02,
            range: 0.5,
            half_angle: 35f32.to_radians(),
        };
        let mut rng = Rng(2024);
        let mut detected = 0;
        for i in 0..40 {
            let shape: Box<dyn Shape> = match i % 4 {
                0 => Box::new(Ball::new(rng.range(0.005, 0.1))),
                1 => Box::new(Cuboid::new(Vector::new(
                    rng.range(0.005, 0.1),
                    rng.range(0.005, 0.1),
                    rng.range(0.005, 0.1),
                ))),
                2 => Box::new(Cylinder::new(rng.range(0.005, 0.1), rng.range(0.005, 0.1))),
                _ => Box::new(Capsule::new_z(rng.range(0.005, 0.1), rng.range(0.005, 0.05))),
            };
            let pose = Pose::from_parts(
                Vector::new(rng.range(-0.3, 0.3), rng.range(-0.3, 0.3), rng.range(-0.05, 0.5)),
                rng.rotation(),
            );
            if assert_matches_oracle(&vol, shape.as_ref(), &pose).is_some() {
                detected += 1;
            }
        }
        assert!(detected >= 10, "only {detected} detections");
    }
}
