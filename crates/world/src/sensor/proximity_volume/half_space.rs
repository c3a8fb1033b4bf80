//! Half-spaces (solids bounded by one plane, e.g. a floor): the nearest direction of the volume
//! in closed form, then parry's (analytic) ray cast along it.

use parry3d::math::{Pose, Vector};
use parry3d::query::{Ray, RayCast};
use parry3d::shape::HalfSpace;

use super::geom::Geom;
use super::hit::{ProximityHit, cap_hit, origin_hit};

/// Closed form for a half-space `{ p : n·p <= c }` (sensor frame, `n` the outward normal).
pub(super) fn detect_half_space(geom: &Geom, hs: &HalfSpace, pose: &Pose) -> Option<ProximityHit> {
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
    let dir = if w.z >= geom.cos {
        w
    } else {
        geom.generator(w.y.atan2(w.x))
    };
    // A direction parallel to the plane or leaving it never hits: parry's cast says None.
    let hit = hs.cast_ray_and_get_normal(pose, &Ray::new(Vector::ZERO, dir), geom.far, true)?;
    let t = hit.time_of_impact;
    if t < geom.near {
        // The same direction stays inside the solid beyond t, so it reaches the near cap.
        return Some(cap_hit(dir * geom.near));
    }
    Some(ProximityHit {
        distance: t,
        point: dir * t,
        normal: hit.normal,
    })
}
