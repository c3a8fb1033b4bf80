//! A detection ([`ProximityHit`]) and the small rules every shape's detection shares:
//! keep the nearest, search no farther than the best so far, clamp to the near cap.

use parry3d::math::Vector;

use super::geom::Geom;

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

/// Replaces `best` by `candidate` when the latter is strictly nearer.
pub(super) fn keep_nearest(best: &mut Option<ProximityHit>, candidate: Option<ProximityHit>) {
    if let Some(c) = candidate
        && best.is_none_or(|b| c.distance < b.distance)
    {
        *best = Some(c);
    }
}

/// Largest distance (m) still worth finding: the far cap, or the best detection so far.
pub(super) fn limit(geom: &Geom, best: &Option<ProximityHit>) -> f32 {
    best.map_or(geom.far, |b| b.distance.min(geom.far))
}

/// Detection at the sensor origin (offset 0 and the origin inside a solid).
pub(super) fn origin_hit() -> ProximityHit {
    ProximityHit {
        distance: 0.0,
        point: Vector::ZERO,
        normal: -Vector::Z,
    }
}

/// Detection clamped to the near cap at `point` (inside the solid): normal pointing back.
pub(super) fn cap_hit(point: Vector) -> ProximityHit {
    let distance = point.length();
    ProximityHit {
        distance,
        point,
        normal: if distance > 0.0 { -point / distance } else { -Vector::Z },
    }
}
