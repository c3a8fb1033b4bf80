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
//! * [`ProximityVolume::Pyramid`], [`ProximityVolume::Cylinder`] and [`ProximityVolume::Disc`]:
//!   CoppeliaSim's flat-faced volumes, detected on triangles as CoppeliaSim detects them
//!   (`polytope.rs` says how; the rest of this page is about the ray and the cone).
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
//! # Method
//!
//! Each file holds one part of the method and documents why it is exact:
//!
//! * `convex.rs`: one convex shape; the nearest distance is `max(t*, offset)`, where `t*` is
//!   the minimum of `|p|` over the shape inside the infinite cone (cases A and B: the origin
//!   inside the shape, or its projection inside the cone).
//! * `lateral.rs`: case C, the minimiser on the cone's lateral surface, by a certified Newton
//!   iteration on the distance between the shape and the growing sector, with `gjk.rs` (an
//!   f64 GJK against the sector) and `simplex.rs` (its simplex).
//! * `near_cap.rs`: when `t* < offset`, whether the shape reaches past the near cap.
//! * `normal.rs`: the normal at a lateral detection.
//! * `shape_query.rs`: point projections and ray casts on one shape.
//! * `composite.rs` (compounds, meshes, height fields) and `half_space.rs`.
//! * `geom.rs`: the volume's precomputed geometry (cone membership, generators, AABB).
//!
//! # What parry does, and what it cannot
//!
//! parry answers every query it answers exactly: support points, point projections where they
//! are analytic (ball, cuboid, capsule, cylinder, cone, triangle, segment), ray casts where
//! they are analytic (ball, cuboid, capsule, triangle, half-space), the ray–ball crossing of
//! the near cap, face normals of triangles and polyhedra, bounding volumes, and the BVH walk
//! of composites. The rest is ours, for two reasons. parry has no cone or cone-shell (sector)
//! shape, so the lateral search and the near-cap witnesses are cone geometry of our own. And
//! parry 0.31 is built for f32 (its `Real`) with a GJK that stops at a relative gap of ~1e-3:
//! its projections on convex polyhedra and round shapes and its GJK-based ray casts (cylinder,
//! cone, convex polyhedron, round shapes; see dimforge/parry PR #414) miss by 0.1 to 1 mm, on
//! thin shapes (triangles) its GJK can report an intersection across a 1e-4-relative gap, and
//! it cannot resolve the lateral search's separating directions. Those are a small f64 GJK on nalgebra vectors
//! (`gjk.rs`) and searches on its projections; `shape_query.rs` and `gjk.rs` name the tests
//! that fail with parry's own queries in their place.
//!
//! # Numerics, accuracy and cost
//!
//! Distances are exact to about 1e-6 of the distance (a micrometre at 1 m; 2e-5 of it at
//! worst when the search stalls on a curved–curved contact), points lie within a few
//! micrometres of the surface, normals within ~1e-5 rad on flat faces and ~1e-3 rad on curved
//! surfaces. The tests compare against an independent brute-force oracle; an ignored stress
//! test (`cargo test --release -- --ignored stress`) does so on thousands of random cases.
//! Cost (release build, one core): the fast path is one point projection, ~80 ns for
//! primitives; the lateral path ~0.1 µs for balls and 2–7 µs for other shapes; a mesh costs
//! that per triangle reaching the volume. Nothing allocates
//! (`cargo bench -p gantry-world --bench proximity` times each path).

mod composite;
mod convex;
mod geom;
mod gjk;
mod half_space;
mod hit;
mod lateral;
mod near_cap;
mod normal;
mod polytope;
mod shape_query;
mod simplex;
#[cfg(test)]
mod tests;

use core::f32::consts::FRAC_PI_2;

use parry3d::bounding_volume::Aabb;
use parry3d::math::Pose;
use parry3d::shape::Shape;

use composite::detect_shape;
use geom::Geom;
pub use hit::ProximityHit;
use polytope::Polytope;
// The composite tests merge detections as the detectors do.
#[cfg(test)]
use hit::keep_nearest;

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
    /// Frustum of a rectangular pyramid between `z = offset` and `z = offset + range`, its
    /// faces `near_size` and `far_size` wide (full widths along X and Y, m). See `polytope.rs`.
    Pyramid {
        /// Distance (m) of the near face from the origin, `>= 0`.
        offset: f32,
        /// Depth (m), `> 0`.
        range: f32,
        /// Full widths (m) along X and Y at `z = offset`.
        near_size: [f32; 2],
        /// Full widths (m) along X and Y at `z = offset + range`.
        far_size: [f32; 2],
    },
    /// Frustum of a cone around +Z, faceted, between `z = offset` and `z = offset + range`.
    Cylinder {
        /// Distance (m) of the near face from the origin, `>= 0`.
        offset: f32,
        /// Depth (m), `> 0`.
        range: f32,
        /// Radius (m) at `z = offset`.
        radius: f32,
        /// Radius (m) at `z = offset + range`.
        radius_far: f32,
    },
    /// A fan in the XZ plane around +Z, faceted: radii `offset..offset + range` (in that
    /// plane), within `half_angle` of +Z (up to π, a ring), `thickness` thick along Y.
    Disc {
        /// Inner radius (m), `>= 0`.
        offset: f32,
        /// Radial depth (m), `> 0`.
        range: f32,
        /// Half of the opening angle (rad), in `(0, π]`.
        half_angle: f32,
        /// Full thickness (m) along Y, `> 0`.
        thickness: f32,
    },
}

impl ProximityVolume {
    /// Whether the parameters are usable: finite, `offset >= 0`, `range > 0` and, for the
    /// cone, `0 < half_angle < π/2` (radians). [`detect`](Self::detect) returns `None` for an
    /// invalid volume.
    pub fn is_valid(&self) -> bool {
        if let Some(p) = self.polytope() {
            return p.is_valid();
        }
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
        if let Some(p) = self.polytope() {
            return p.local_aabb();
        }
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
        if let Some(p) = self.polytope() {
            return p.detect(shape, shape_pose);
        }
        if !self.is_valid() {
            return None;
        }
        let (offset, range, half_angle) = self.params();
        let geom = Geom::new(offset, offset + range, half_angle);
        let mut best = None;
        detect_shape(&geom, shape, shape_pose, &mut best);
        best
    }

    /// `(offset, range, half_angle)` of the ray and the cone, the ray being the cone of
    /// half-angle 0 (the polytope volumes never get here).
    fn params(&self) -> (f32, f32, f32) {
        match *self {
            Self::Ray { offset, range } => (offset, range, 0.0),
            Self::Cone {
                offset,
                range,
                half_angle,
            } => (offset, range, half_angle),
            Self::Pyramid { .. } | Self::Cylinder { .. } | Self::Disc { .. } => (0.0, 0.0, 0.0),
        }
    }

    /// The pyramid, cylinder and disc as convex pieces, in f64; `None` for the ray and cone.
    fn polytope(&self) -> Option<Polytope> {
        let f = f64::from;
        match *self {
            Self::Ray { .. } | Self::Cone { .. } => None,
            Self::Pyramid {
                offset,
                range,
                near_size,
                far_size,
            } => Some(Polytope::Pyramid {
                near: f(offset),
                far: f(offset) + f(range),
                near_half: near_size.map(|w| f(w) / 2.0),
                far_half: far_size.map(|w| f(w) / 2.0),
            }),
            Self::Cylinder {
                offset,
                range,
                radius,
                radius_far,
            } => Some(Polytope::Cylinder {
                near: f(offset),
                far: f(offset) + f(range),
                radius: f(radius),
                radius_far: f(radius_far),
            }),
            Self::Disc {
                offset,
                range,
                half_angle,
                thickness,
            } => Some(Polytope::Disc {
                inner: f(offset),
                outer: f(offset) + f(range),
                half_angle: f(half_angle),
                half_thickness: f(thickness) / 2.0,
            }),
        }
    }
}
