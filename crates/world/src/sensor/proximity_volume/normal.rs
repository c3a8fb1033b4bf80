//! The normal reported with a lateral detection (`lateral.rs`): a unit vector in the sensor
//! frame, out of the shape and towards the sensor.

use parry3d::math::{Pose, Vector};
use parry3d::shape::{Shape, SupportMap, TypedShape};

use super::shape_query::projection;

/// First estimate of a lateral detection's normal: project the point moved this fraction of
/// its distance towards the sensor (see `surface_normal`).
const NORMAL_PROBE_REL: f32 = 1.0e-4;
/// Lever arm of the normal refinement, as a fraction of the shape's bounding radius.
const NORMAL_LEVER_REL: f32 = 0.05;

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

/// Normal at the lateral minimiser `point` of a convex shape: exact face or radial normals
/// where the shape type gives them, else [`surface_normal`]. `separating` is the last
/// separating direction of the Newton iteration (from the sector towards the shape), whose
/// opposite is a valid normal and the fallback.
pub(super) fn lateral_normal(
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
pub(super) fn facing_sensor(normal: Vector, point: Vector) -> Vector {
    let n = normal.normalize_or_zero();
    if n == Vector::ZERO || !n.is_finite() {
        -point.normalize_or(Vector::Z)
    } else if n.dot(point) > 0.0 {
        -n
    } else {
        n
    }
}
