//! The volume's precomputed geometry in the sensor frame: the infinite cone `K` (the +Z
//! half-line for the ray), its generators, the sector `Q_1 = K ∩ B(1)` and the volume's AABB.

use parry3d::bounding_volume::Aabb;
use parry3d::math::Vector;

use crate::math::Vec3;

/// Relative slack when testing whether a witness point lies in the cone.
const CONE_SLACK: f32 = 1.0e-6;

/// Precomputed volume: near/far cap radii (m) and the half-angle's trigonometry. A half-angle
/// of 0 is the ray: the cone degenerates to the +Z half-line and every formula below still
/// holds (the sector `Q_t` becomes the segment `[0, t]·Z`).
#[derive(Clone, Copy, Debug)]
pub(super) struct Geom {
    /// Near cap radius `a` (m).
    pub(super) near: f32,
    /// Far cap radius `b` (m).
    pub(super) far: f32,
    /// Half-angle (rad) of the cone, 0 for the ray.
    pub(super) half_angle: f32,
    /// `cos(half_angle)`.
    pub(super) cos: f32,
    /// `sin(half_angle)`.
    pub(super) sin: f32,
}

impl Geom {
    pub(super) fn new(near: f32, far: f32, half_angle: f32) -> Self {
        let (sin, cos) = half_angle.sin_cos();
        Self {
            near,
            far,
            half_angle,
            cos,
            sin,
        }
    }

    pub(super) fn is_ray(&self) -> bool {
        self.half_angle == 0.0
    }

    /// Whether `p` lies in the infinite cone `K` (apex included).
    pub(super) fn in_cone(&self, p: Vector) -> bool {
        p.z >= p.length() * self.cos
    }

    /// [`Self::in_cone`] with a small relative slack, for witnesses computed on `∂K`.
    pub(super) fn in_cone_slack(&self, p: Vector) -> bool {
        p.z >= p.length() * (self.cos - CONE_SLACK)
    }

    /// Unit direction of the lateral generator at azimuth `phi` (rad).
    pub(super) fn generator(&self, phi: f32) -> Vector {
        let (s, c) = phi.sin_cos();
        Vector::new(self.sin * c, self.sin * s, self.cos)
    }

    /// Cheap rejection with a bounding sphere (centre `c`, radius `r`, sensor frame): false
    /// when the sphere is entirely farther than `limit` (m) or entirely outside the cone.
    pub(super) fn sphere_may_touch(&self, c: Vector, r: f32, limit: f32) -> bool {
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

    /// The volume AABB (see [`ProximityVolume::local_aabb`](super::ProximityVolume::local_aabb)).
    pub(super) fn aabb(&self) -> Aabb {
        let r = self.far * self.sin;
        Aabb::new(Vector::new(-r, -r, self.near * self.cos), Vector::new(r, r, self.far))
    }
}

/// Support function of the unit sector `Q_1 = K ∩ B(1)` in direction `n`: `max(n · p)` over
/// `Q_1`, which is `|n|` if `n` points into the cone, else the value at the rim point of `n`'s
/// azimuth, or 0 at the apex.
pub(super) fn unit_sector_support_value(geom: &Geom, n: Vec3) -> f64 {
    let (cos, sin) = (f64::from(geom.cos), f64::from(geom.sin));
    let len = n.norm();
    if n.z >= len * cos {
        len
    } else {
        let rxy = (n.x * n.x + n.y * n.y).sqrt();
        (n.z * cos + rxy * sin).max(0.0)
    }
}
