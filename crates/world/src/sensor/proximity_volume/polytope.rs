//! Pyramid, cylinder and disc volumes: unions of convex polytopes, detected on triangles.
//!
//! CoppeliaSim builds these three volumes from flat faces (its "face count" settings), and
//! detects triangles only. We do the same: a volume is a union of convex pieces, each the
//! intersection of half-spaces `n·p <= d` in the sensor frame; a shape is seen through its
//! triangles; each triangle is clipped to each piece (Sutherland–Hodgman) and the detection
//! is the point of the clipped polygons nearest to the sensor origin. On a triangle the
//! answer is exact to rounding (f64 throughout).
//!
//! * **Pyramid**: one piece, exact. The near face (`near_size`, full widths along X and Y) lies
//!   at `z = offset`, the far face (`far_size`) at `z = offset + range`.
//! * **Cylinder**: a frustum of [`FACETS`] flat sides inscribed in the circles of radius
//!   `radius` (at `z = offset`) and `radius_far` (at `z = offset + range`).
//! * **Disc**: a fan in the sensor's XZ plane, symmetric about +Z, `thickness` thick along Y,
//!   between the radii `offset` and `offset + range` (measured in the XZ plane) and within
//!   `half_angle` of +Z (up to π, a whole ring). It is cut into slices of at most 2π/[`FACETS`],
//!   each bounded by the chords of its two arcs, so it is a polygon inscribed in the fan.
//!
//! The faceting moves the rim inwards by at most `r·(1 − cos(π/FACETS))`, 0.5 % of the radius.
//!
//! Shapes are surfaces here, as in CoppeliaSim: triangle meshes, height fields and compounds
//! through their triangles; convex primitives through a tessellation of their surface
//! (exact for cuboids and convex polyhedra; balls, capsules, cylinders and cones within
//! 0.5 % of their radius); a half-space (a floor) through its plane. A solid that swallows the
//! whole volume is therefore not seen, as in CoppeliaSim (the ray and cone volumes, which are
//! exact on solids, report it at the near cap instead).

use core::f64::consts::{PI, TAU};

use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::{Pose, Vector};
use parry3d::partitioning::TraversalAction;
use parry3d::shape::{CompositeShape, HalfSpace, Shape, TypedShape};

use super::hit::{ProximityHit, keep_nearest};
use crate::math::{self, Vec3};

/// Flat sides of a cylinder volume, slices of a full disc volume, and segments around a
/// tessellated round primitive.
pub(super) const FACETS: usize = 32;

/// Most planes of one piece: the cylinder's sides and its two caps.
const MAX_PLANES: usize = FACETS + 2;

/// Most vertices of a triangle clipped by one piece: each plane adds at most one.
const MAX_POLY: usize = 3 + MAX_PLANES;

/// How far past π a disc's half-angle may be and still mean a whole ring (π in f32 is
/// 8.7e-8 rad more than π in f64).
const ANGLE_SLACK: f64 = 1.0e-6;

/// A convex volume of the polytope family, in the sensor frame (metres, radians). The
/// fields are those of [`super::ProximityVolume`]'s variants, in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Polytope {
    /// Frustum of a rectangular pyramid: near face at `z = near`, far face at `z = far`,
    /// half-widths along X and Y.
    Pyramid {
        near: f64,
        far: f64,
        near_half: [f64; 2],
        far_half: [f64; 2],
    },
    /// Faceted frustum of a cone: radii `radius` at `z = near`, `radius_far` at `z = far`.
    Cylinder {
        near: f64,
        far: f64,
        radius: f64,
        radius_far: f64,
    },
    /// Faceted fan in the XZ plane: radii `inner..outer`, `|angle from +Z| <= half_angle`,
    /// `|y| <= half_thickness`.
    Disc {
        inner: f64,
        outer: f64,
        half_angle: f64,
        half_thickness: f64,
    },
}

/// A bounding plane `n·p <= d` (sensor frame, `n` a unit vector pointing out of the piece).
#[derive(Clone, Copy, Debug)]
struct Plane {
    n: Vec3,
    d: f64,
}

impl Plane {
    fn new(n: Vec3, d: f64) -> Self {
        let len = n.norm();
        Self { n: n / len, d: d / len }
    }

    fn signed(&self, p: &Vec3) -> f64 {
        self.n.dot(p) - self.d
    }
}

/// One convex piece: its planes and a bounding box of its corners (sensor frame).
#[derive(Clone, Debug)]
struct Piece {
    planes: Vec<Plane>,
    mins: Vec3,
    maxs: Vec3,
}

impl Piece {
    fn new(planes: Vec<Plane>, corners: &[Vec3]) -> Self {
        let mut mins = Vec3::repeat(f64::INFINITY);
        let mut maxs = Vec3::repeat(f64::NEG_INFINITY);
        for c in corners {
            mins = mins.inf(c);
            maxs = maxs.sup(c);
        }
        Self { planes, mins, maxs }
    }
}

impl Polytope {
    /// Whether the parameters describe a non-empty volume: finite, `0 <= near < far`,
    /// positive sizes, and for the disc `0 < half_angle <= π`.
    pub(super) fn is_valid(&self) -> bool {
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        match *self {
            Self::Pyramid {
                near,
                far,
                near_half,
                far_half,
            } => {
                finite(&[near, far, near_half[0], near_half[1], far_half[0], far_half[1]])
                    && near >= 0.0
                    && far > near
                    && near_half.iter().chain(&far_half).all(|&h| h >= 0.0)
                    && near_half.iter().zip(&far_half).all(|(a, b)| a + b > 0.0)
            }
            Self::Cylinder {
                near,
                far,
                radius,
                radius_far,
            } => {
                finite(&[near, far, radius, radius_far])
                    && near >= 0.0
                    && far > near
                    && radius >= 0.0
                    && radius_far >= 0.0
                    && radius + radius_far > 0.0
            }
            Self::Disc {
                inner,
                outer,
                half_angle,
                half_thickness,
            } => {
                finite(&[inner, outer, half_angle, half_thickness])
                    && inner >= 0.0
                    && outer > inner
                    && half_angle > 0.0
                    && half_angle <= PI + ANGLE_SLACK
                    && half_thickness > 0.0
            }
        }
    }

    /// The convex pieces whose union is the volume.
    fn pieces(&self) -> Vec<Piece> {
        match *self {
            Self::Pyramid {
                near,
                far,
                near_half,
                far_half,
            } => vec![pyramid(near, far, near_half, far_half)],
            Self::Cylinder {
                near,
                far,
                radius,
                radius_far,
            } => vec![cylinder(near, far, radius, radius_far)],
            Self::Disc {
                inner,
                outer,
                half_angle,
                half_thickness,
            } => disc(inner, outer, half_angle.min(PI), half_thickness),
        }
    }

    /// Bounding box (m) of the volume in the sensor frame.
    pub(super) fn local_aabb(&self) -> Aabb {
        let mut mins = Vec3::repeat(f64::INFINITY);
        let mut maxs = Vec3::repeat(f64::NEG_INFINITY);
        for p in self.pieces() {
            mins = mins.inf(&p.mins);
            maxs = maxs.sup(&p.maxs);
        }
        Aabb::new(math::vec_to_physics(&mins), math::vec_to_physics(&maxs))
    }

    /// Nearest point of `shape` (posed in the sensor frame) inside the volume.
    pub(super) fn detect(&self, shape: &dyn Shape, pose: &Pose) -> Option<ProximityHit> {
        if !self.is_valid() {
            return None;
        }
        let pieces = self.pieces();
        let aabb = self.local_aabb();
        let mut best = None;
        detect_shape(&pieces, &aabb, shape, pose, &mut best);
        best
    }
}

/// The pyramid frustum: two caps and four sides through the near and far rectangles.
fn pyramid(near: f64, far: f64, [hx0, hy0]: [f64; 2], [hx1, hy1]: [f64; 2]) -> Piece {
    let depth = far - near;
    let (sx, sy) = ((hx1 - hx0) / depth, (hy1 - hy0) / depth);
    // x <= hx0 + sx (z - near), i.e. x - sx z <= hx0 - sx near; the same mirrored and for y.
    let planes = vec![
        Plane::new(-Vec3::z(), -near),
        Plane::new(Vec3::z(), far),
        Plane::new(Vec3::new(1.0, 0.0, -sx), hx0 - sx * near),
        Plane::new(Vec3::new(-1.0, 0.0, -sx), hx0 - sx * near),
        Plane::new(Vec3::new(0.0, 1.0, -sy), hy0 - sy * near),
        Plane::new(Vec3::new(0.0, -1.0, -sy), hy0 - sy * near),
    ];
    let mut corners = Vec::with_capacity(8);
    for (z, hx, hy) in [(near, hx0, hy0), (far, hx1, hy1)] {
        for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            corners.push(Vec3::new(a * hx, b * hy, z));
        }
    }
    Piece::new(planes, &corners)
}

/// The cylinder frustum: two caps and [`FACETS`] sides, their edges on the two circles.
fn cylinder(near: f64, far: f64, r0: f64, r1: f64) -> Piece {
    let depth = far - near;
    let slope = (r1 - r0) / depth;
    let half = PI / FACETS as f64;
    let mut planes = vec![Plane::new(-Vec3::z(), -near), Plane::new(Vec3::z(), far)];
    let mut corners = Vec::with_capacity(2 * FACETS);
    for k in 0..FACETS {
        // The side between the edges at azimuths 2k·half and 2(k+1)·half, at distance
        // r(z)·cos(half) from the axis along its middle azimuth u.
        let (s, c) = ((2 * k + 1) as f64 * half).sin_cos();
        let ch = half.cos();
        planes.push(Plane::new(Vec3::new(c, s, -ch * slope), ch * (r0 - slope * near)));
        let (s, c) = ((2 * k) as f64 * half).sin_cos();
        corners.push(Vec3::new(r0 * c, r0 * s, near));
        corners.push(Vec3::new(r1 * c, r1 * s, far));
    }
    Piece::new(planes, &corners)
}

/// The disc's slices: each between two half-planes through the Y axis, its inner and outer
/// chords and the two faces `|y| = half_thickness`.
fn disc(inner: f64, outer: f64, half_angle: f64, half_thickness: f64) -> Vec<Piece> {
    let span = 2.0 * half_angle;
    let slices = ((span / (TAU / FACETS as f64)).ceil() as usize).clamp(1, FACETS);
    let width = span / slices as f64;
    // The direction at angle θ from +Z towards +X.
    let dir = |theta: f64| Vec3::new(theta.sin(), 0.0, theta.cos());
    (0..slices)
        .map(|i| {
            let a = -half_angle + i as f64 * width;
            let b = a + width;
            let mid = dir(a + width / 2.0);
            let chord = (width / 2.0).cos();
            let planes = vec![
                Plane::new(Vec3::y(), half_thickness),
                Plane::new(-Vec3::y(), half_thickness),
                // sin(a − θ) <= 0 and sin(θ − b) <= 0 for p at angle θ: a <= θ <= b.
                Plane::new(Vec3::new(-a.cos(), 0.0, a.sin()), 0.0),
                Plane::new(Vec3::new(b.cos(), 0.0, -b.sin()), 0.0),
                Plane::new(mid, outer * chord),
                Plane::new(-mid, -inner * chord),
            ];
            let mut corners = Vec::with_capacity(8);
            for r in [inner, outer] {
                for t in [a, b] {
                    for y in [-half_thickness, half_thickness] {
                        corners.push(dir(t) * r + Vec3::new(0.0, y, 0.0));
                    }
                }
            }
            Piece::new(planes, &corners)
        })
        .collect()
}

/// Dispatches on the shape type; composites recurse into their parts.
fn detect_shape(pieces: &[Piece], aabb: &Aabb, shape: &dyn Shape, pose: &Pose, best: &mut Option<ProximityHit>) {
    match shape.as_typed_shape() {
        TypedShape::Triangle(t) => detect_triangle(
            pieces,
            [
                pose.transform_point(t.a),
                pose.transform_point(t.b),
                pose.transform_point(t.c),
            ],
            best,
        ),
        TypedShape::HalfSpace(hs) => detect_half_space(pieces, aabb, hs, pose, best),
        TypedShape::HeightField(hf) => {
            let local = aabb.transform_by(&pose.inverse());
            hf.map_elements_in_local_aabb(&local, &mut |_, t| {
                detect_triangle(
                    pieces,
                    [
                        pose.transform_point(t.a),
                        pose.transform_point(t.b),
                        pose.transform_point(t.c),
                    ],
                    best,
                );
            });
        }
        TypedShape::Ball(b) => detect_mesh(pieces, aabb, b.to_trimesh(FACETS as u32 / 2, FACETS as u32), pose, best),
        TypedShape::Cuboid(c) => detect_mesh(pieces, aabb, c.to_trimesh(), pose, best),
        TypedShape::Capsule(c) => {
            detect_mesh(pieces, aabb, c.to_trimesh(FACETS as u32, FACETS as u32 / 2), pose, best);
        }
        TypedShape::Cylinder(c) => detect_mesh(pieces, aabb, c.to_trimesh(FACETS as u32), pose, best),
        TypedShape::Cone(c) => detect_mesh(pieces, aabb, c.to_trimesh(FACETS as u32), pose, best),
        TypedShape::ConvexPolyhedron(c) => detect_mesh(pieces, aabb, c.to_trimesh(), pose, best),
        // Rounded shapes: their inner shape (the rounding is a few millimetres at most in
        // imported scenes, and CoppeliaSim has no rounded shapes).
        TypedShape::RoundCuboid(r) => detect_shape(pieces, aabb, &r.inner_shape, pose, best),
        TypedShape::RoundCylinder(r) => detect_shape(pieces, aabb, &r.inner_shape, pose, best),
        TypedShape::RoundCone(r) => detect_shape(pieces, aabb, &r.inner_shape, pose, best),
        TypedShape::RoundConvexPolyhedron(r) => detect_shape(pieces, aabb, &r.inner_shape, pose, best),
        TypedShape::RoundTriangle(r) => detect_shape(pieces, aabb, &r.inner_shape, pose, best),
        _ => {
            if let Some(composite) = shape.as_composite_shape() {
                detect_composite(pieces, aabb, composite, pose, best);
            }
            // Anything else (polylines, voxels, custom shapes) has no triangles to see.
        }
    }
}

/// Walks the composite's BVH, pruning nodes that miss the volume's box.
fn detect_composite(
    pieces: &[Piece],
    aabb: &Aabb,
    composite: &dyn CompositeShape,
    pose: &Pose,
    best: &mut Option<ProximityHit>,
) {
    let local = aabb.transform_by(&pose.inverse());
    composite.bvh().traverse(|node| {
        if !node.aabb().intersects(&local) {
            return TraversalAction::Prune;
        }
        if let Some(part) = node.leaf_data() {
            composite.map_part_at(part, &mut |part_pose, part_shape, _| {
                let part_pose = part_pose.map_or(*pose, |pp| *pose * *pp);
                detect_shape(pieces, aabb, part_shape, &part_pose, best);
            });
        }
        TraversalAction::Continue
    });
}

/// A tessellated primitive, its triangles culled against the volume's box.
fn detect_mesh(
    pieces: &[Piece],
    aabb: &Aabb,
    (vertices, triangles): (Vec<Vector>, Vec<[u32; 3]>),
    pose: &Pose,
    best: &mut Option<ProximityHit>,
) {
    let posed: Vec<Vector> = vertices.iter().map(|v| pose.transform_point(*v)).collect();
    // A convex primitive wholly outside one face plane of every piece is not seen: one
    // pass over its vertices instead of one clip per triangle.
    let outside = |piece: &Piece| {
        piece
            .planes
            .iter()
            .any(|plane| posed.iter().all(|v| plane.signed(&math::vec_from_physics(*v)) > 0.0))
    };
    if pieces.iter().all(outside) {
        return;
    }
    for [a, b, c] in triangles {
        let tri = [posed[a as usize], posed[b as usize], posed[c as usize]];
        if Aabb::from_points(tri).intersects(aabb) {
            detect_triangle(pieces, tri, best);
        }
    }
}

/// A half-space is seen through its boundary plane: a square of that plane wide enough to
/// cover the volume's box, as two triangles.
fn detect_half_space(pieces: &[Piece], aabb: &Aabb, hs: &HalfSpace, pose: &Pose, best: &mut Option<ProximityHit>) {
    let n = pose.rotation * hs.normal;
    let on_plane = pose.translation;
    let centre = aabb.center();
    let foot = centre - n * n.dot(centre - on_plane);
    let half = aabb.half_extents().length() * 2.0;
    let u = n.any_orthonormal_vector() * half;
    let v = n.cross(u);
    let corners = [foot - u - v, foot + u - v, foot + u + v, foot - u + v];
    detect_triangle(pieces, [corners[0], corners[1], corners[2]], best);
    detect_triangle(pieces, [corners[0], corners[2], corners[3]], best);
}

/// Clips one triangle (sensor frame) to each piece and keeps the nearest point.
fn detect_triangle(pieces: &[Piece], tri: [Vector; 3], best: &mut Option<ProximityHit>) {
    let [a, b, c] = tri.map(math::vec_from_physics);
    let normal = (b - a).cross(&(c - a));
    let area2 = normal.norm();
    if area2.is_nan() || area2 <= 0.0 {
        return; // degenerate (or non-finite): no surface to see
    }
    let normal = normal / area2;
    let (tmin, tmax) = (a.inf(&b).inf(&c), a.sup(&b).sup(&c));
    for piece in pieces {
        let outside_box = (0..3).any(|i| tmax[i] < piece.mins[i] || tmin[i] > piece.maxs[i]);
        // Wholly outside one plane: not in this piece (most triangles near a volume).
        if outside_box
            || piece
                .planes
                .iter()
                .any(|plane| [a, b, c].iter().all(|v| plane.signed(v) > 0.0))
        {
            continue;
        }
        let mut poly = Polygon::triangle([a, b, c]);
        for plane in &piece.planes {
            poly.clip(plane);
            if poly.len == 0 {
                break;
            }
        }
        if poly.len == 0 {
            continue;
        }
        let p = poly.nearest_to_origin(&normal);
        let distance = p.norm();
        if best.is_some_and(|b| f64::from(b.distance) <= distance) {
            continue;
        }
        // The face normal, turned towards the sensor side.
        let n = if normal.dot(&p) > 0.0 { -normal } else { normal };
        keep_nearest(
            best,
            Some(ProximityHit {
                distance: distance as f32,
                point: math::vec_to_physics(&p),
                normal: math::vec_to_physics(&n),
            }),
        );
    }
}

/// A convex planar polygon, its vertices in order, on the stack.
struct Polygon {
    pts: [Vec3; MAX_POLY],
    len: usize,
}

impl Polygon {
    fn triangle([a, b, c]: [Vec3; 3]) -> Self {
        let mut pts = [Vec3::zeros(); MAX_POLY];
        pts[..3].copy_from_slice(&[a, b, c]);
        Self { pts, len: 3 }
    }

    /// Keeps the part with `plane.signed(p) <= 0` (Sutherland–Hodgman).
    fn clip(&mut self, plane: &Plane) {
        // Most planes leave a triangle whole or remove it whole: decided from the signs
        // alone, without building a new polygon (the copies were most of a sensor's cost
        // on a gripper's finger meshes). Same result as the general case below.
        let mut signed = [0.0; MAX_POLY];
        let (mut any_in, mut any_out) = (false, false);
        for (s, p) in signed.iter_mut().zip(&self.pts[..self.len]) {
            *s = plane.signed(p);
            any_in |= *s <= 0.0;
            any_out |= *s > 0.0;
        }
        if !any_out {
            return;
        }
        if !any_in {
            self.len = 0;
            return;
        }
        let mut out = [Vec3::zeros(); MAX_POLY];
        let mut len = 0;
        for i in 0..self.len {
            let j = (i + 1) % self.len;
            let (p, q) = (self.pts[i], self.pts[j]);
            let (sp, sq) = (signed[i], signed[j]);
            if sp <= 0.0 {
                out[len] = p;
                len += 1;
            }
            if (sp < 0.0 && sq > 0.0) || (sp > 0.0 && sq < 0.0) {
                out[len] = p + (q - p) * (sp / (sp - sq));
                len += 1;
            }
            if len == MAX_POLY {
                break; // cannot happen for a convex input; guards the array all the same
            }
        }
        self.pts = out;
        self.len = len;
    }

    /// The polygon's point nearest to the origin; `normal` is the unit normal of its plane,
    /// with the vertices counter-clockwise about it.
    fn nearest_to_origin(&self, normal: &Vec3) -> Vec3 {
        let pts = &self.pts[..self.len];
        let foot = normal * normal.dot(&pts[0]);
        let inside = pts.len() >= 3
            && (0..pts.len()).all(|i| {
                let (p, q) = (pts[i], pts[(i + 1) % pts.len()]);
                (q - p).cross(&(foot - p)).dot(normal) >= 0.0
            });
        if inside {
            return foot;
        }
        let mut nearest = pts[0];
        for i in 0..pts.len() {
            let (p, q) = (pts[i], pts[(i + 1) % pts.len()]);
            let e = q - p;
            let len2 = e.norm_squared();
            let t = if len2 > 0.0 {
                (-p.dot(&e) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let c = p + e * t;
            if c.norm_squared() < nearest.norm_squared() {
                nearest = c;
            }
        }
        nearest
    }
}
