//! State spaces of a motion-planning task: what part of the scene a planner moves and
//! how (an object's position or pose, a joint's position), with the metric, sampling and
//! interpolation OMPL gives the same spaces.

use gantry_scene::math::{self, Pose, Quat, Vec3};
use gantry_scene::{Handle, SimError};

use crate::rng::Rng;

/// What a state space moves, `simOMPL.StateSpaceType`'s values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpaceKind {
    /// An object's x, y (m); its z and orientation stay.
    Position2d,
    /// An object's x, y (m) and its rotation about z (rad).
    Pose2d,
    /// An object's x, y, z (m).
    Position3d,
    /// An object's x, y, z (m) and orientation (quaternion x, y, z, w).
    Pose3d,
    /// A joint's position (rad or m), within bounds.
    JointPosition,
    /// A revolute joint's position on the circle (rad, wrapped to -pi..pi).
    CyclicJointPosition,
}

impl SpaceKind {
    /// The kind for `simOMPL.StateSpaceType`'s number.
    ///
    /// # Errors
    /// An unknown number, or Dubins (a car's turning-radius metric gantry does not plan
    /// with).
    pub fn from_code(code: i64) -> Result<Self, SimError> {
        Ok(match code {
            0 => Self::Position2d,
            1 => Self::Pose2d,
            2 => Self::Position3d,
            3 => Self::Pose3d,
            4 => Self::JointPosition,
            6 => Self::CyclicJointPosition,
            5 => {
                return Err(SimError::Refused(
                    "Dubins state spaces (a car's turning-radius metric) are not served; plan with pose2d and follow the path with your controller".into(),
                ));
            }
            _ => {
                return Err(SimError::BadArgument(format!(
                    "invalid state space type {code} (simOMPL.StateSpaceType.position2d, pose2d, position3d, pose3d, joint_position or cyclic_joint_position)"
                )));
            }
        })
    }

    /// Values a state of this kind has.
    pub fn dimension(self) -> usize {
        match self {
            Self::Position2d => 2,
            Self::Pose2d | Self::Position3d => 3,
            Self::Pose3d => 7,
            Self::JointPosition | Self::CyclicJointPosition => 1,
        }
    }

    /// Values the bounds have: the positions' (not the rotations') for objects.
    pub fn bound_count(self) -> usize {
        match self {
            Self::Position2d | Self::Pose2d => 2,
            Self::Position3d | Self::Pose3d => 3,
            Self::JointPosition => 1,
            Self::CyclicJointPosition => 0,
        }
    }
}

/// One state space: a kind applied to an object, with bounds and a weight in the
/// task's distance.
#[derive(Debug, Clone)]
pub struct StateSpace {
    /// The name given at creation (for messages).
    pub name: String,
    /// What it moves.
    pub kind: SpaceKind,
    /// The object or joint moved.
    pub object: Handle,
    /// Lower bounds of the positions (m) or the joint (rad or m).
    pub low: Vec<f64>,
    /// Upper bounds.
    pub high: Vec<f64>,
    /// Weight of this space's distance in the task's.
    pub weight: f64,
    /// The frame object positions are in (-1: the world).
    pub reference: Handle,
}

impl StateSpace {
    /// A space, its bounds checked.
    ///
    /// # Errors
    /// Bounds of the wrong length, not finite or not increasing, or a weight that is not
    /// positive.
    pub fn new(
        name: &str,
        kind: SpaceKind,
        object: Handle,
        low: Vec<f64>,
        high: Vec<f64>,
        weight: f64,
        reference: Handle,
    ) -> Result<Self, SimError> {
        let n = kind.bound_count();
        if low.len() < n || high.len() < n {
            return Err(SimError::BadArgument(format!(
                "state space '{name}': {n} lower and {n} upper bounds expected, got {} and {}",
                low.len(),
                high.len()
            )));
        }
        let (low, high) = (low[..n].to_vec(), high[..n].to_vec());
        if low
            .iter()
            .zip(&high)
            .any(|(l, h)| !(l.is_finite() && h.is_finite() && l < h))
        {
            return Err(SimError::BadArgument(format!(
                "state space '{name}': bounds must be finite with low < high, got {low:?} and {high:?}"
            )));
        }
        if !(weight.is_finite() && weight > 0.0) {
            return Err(SimError::BadArgument(format!(
                "state space '{name}': weight must be positive, got {weight}"
            )));
        }
        Ok(Self {
            name: name.to_owned(),
            kind,
            object,
            low,
            high,
            weight,
            reference,
        })
    }

    /// The largest distance between two states of this space, unweighted.
    pub fn extent(&self) -> f64 {
        let diagonal = self
            .low
            .iter()
            .zip(&self.high)
            .map(|(l, h)| (h - l) * (h - l))
            .sum::<f64>()
            .sqrt();
        match self.kind {
            SpaceKind::Position2d | SpaceKind::Position3d | SpaceKind::JointPosition => diagonal,
            // OMPL's SE(2) weighs the rotation by one half.
            SpaceKind::Pose2d => diagonal + 0.5 * std::f64::consts::PI,
            SpaceKind::Pose3d => diagonal + std::f64::consts::FRAC_PI_2,
            SpaceKind::CyclicJointPosition => std::f64::consts::PI,
        }
    }

    /// Whether `s` (this space's values) lies within the bounds.
    pub fn within(&self, s: &[f64]) -> bool {
        self.low
            .iter()
            .zip(&self.high)
            .zip(s)
            .all(|((l, h), v)| (*l..=*h).contains(v))
    }

    /// A uniformly random state.
    pub fn sample(&self, rng: &mut Rng, out: &mut Vec<f64>) {
        for (l, h) in self.low.iter().zip(&self.high) {
            out.push(l + (h - l) * rng.unit());
        }
        let pi = std::f64::consts::PI;
        match self.kind {
            SpaceKind::Pose2d => out.push(-pi + 2.0 * pi * rng.unit()),
            SpaceKind::CyclicJointPosition => out.push(-pi + 2.0 * pi * rng.unit()),
            SpaceKind::Pose3d => {
                // Shoemake's uniform rotation.
                let (u1, u2, u3) = (rng.unit(), 2.0 * pi * rng.unit(), 2.0 * pi * rng.unit());
                let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
                out.extend([a * u2.sin(), a * u2.cos(), b * u3.sin(), b * u3.cos()]);
            }
            _ => {}
        }
    }

    /// The unweighted distance between two states of this space.
    pub fn distance(&self, a: &[f64], b: &[f64]) -> f64 {
        let euclid = |n: usize| {
            a[..n]
                .iter()
                .zip(&b[..n])
                .map(|(x, y)| (x - y) * (x - y))
                .sum::<f64>()
                .sqrt()
        };
        match self.kind {
            SpaceKind::Position2d => euclid(2),
            SpaceKind::Position3d => euclid(3),
            SpaceKind::JointPosition => (a[0] - b[0]).abs(),
            SpaceKind::CyclicJointPosition => math::wrap_angle(a[0] - b[0]).abs(),
            SpaceKind::Pose2d => euclid(2) + 0.5 * math::wrap_angle(a[2] - b[2]).abs(),
            SpaceKind::Pose3d => euclid(3) + quat(&a[3..7]).angle_to(&quat(&b[3..7])),
        }
    }

    /// The state a fraction `t` of the way from `a` to `b`, appended to `out`.
    pub fn interpolate(&self, a: &[f64], b: &[f64], t: f64, out: &mut Vec<f64>) {
        let lerp = |x: f64, y: f64| x + (y - x) * t;
        match self.kind {
            SpaceKind::CyclicJointPosition => out.push(math::wrap_angle(a[0] + math::wrap_angle(b[0] - a[0]) * t)),
            SpaceKind::Pose2d => {
                out.extend([lerp(a[0], b[0]), lerp(a[1], b[1])]);
                out.push(math::wrap_angle(a[2] + math::wrap_angle(b[2] - a[2]) * t));
            }
            SpaceKind::Pose3d => {
                out.extend((0..3).map(|k| lerp(a[k], b[k])));
                let q = quat(&a[3..7]).slerp(&quat(&b[3..7]), t);
                out.extend(math::quat_to_array(&q));
            }
            _ => out.extend(a.iter().zip(b).map(|(x, y)| lerp(*x, *y))),
        }
    }

    /// Whether this space moves a joint (its state is the joint's position) rather than
    /// an object (its state is read from the object's pose, [`StateSpace::pose_state`]).
    pub fn moves_joint(&self) -> bool {
        matches!(self.kind, SpaceKind::JointPosition | SpaceKind::CyclicJointPosition)
    }

    /// This space's part of a state for an object at pose `p` in the space's reference
    /// frame, appended to `out`. A joint's space appends nothing: its state is the
    /// joint's position.
    pub fn pose_state(&self, p: &Pose, out: &mut Vec<f64>) {
        let t = p.translation.vector;
        match self.kind {
            SpaceKind::Position2d => out.extend([t.x, t.y]),
            SpaceKind::Position3d => out.extend([t.x, t.y, t.z]),
            SpaceKind::Pose2d => out.extend([t.x, t.y, p.rotation.euler_angles().2]),
            SpaceKind::Pose3d => {
                out.extend([t.x, t.y, t.z]);
                out.extend(math::quat_to_array(&p.rotation));
            }
            SpaceKind::JointPosition | SpaceKind::CyclicJointPosition => {}
        }
    }

    /// Moves pose `p` (in the space's reference frame) to this space's part of a
    /// state, `s`; what the space does not move (the height and tilt of a 2D pose) is
    /// kept. A joint's space leaves `p` alone.
    pub fn set_pose_state(&self, p: &mut Pose, s: &[f64]) {
        match self.kind {
            SpaceKind::Position2d => {
                p.translation.vector.x = s[0];
                p.translation.vector.y = s[1];
            }
            SpaceKind::Position3d => p.translation.vector = Vec3::new(s[0], s[1], s[2]),
            SpaceKind::Pose2d => {
                p.translation.vector.x = s[0];
                p.translation.vector.y = s[1];
                let (roll, pitch, _) = p.rotation.euler_angles();
                p.rotation = Quat::from_euler_angles(roll, pitch, s[2]);
            }
            SpaceKind::Pose3d => *p = Pose::from_parts(Vec3::new(s[0], s[1], s[2]).into(), quat(&s[3..7])),
            SpaceKind::JointPosition | SpaceKind::CyclicJointPosition => {}
        }
    }
}

/// A unit quaternion from x, y, z, w (normalised; the identity for a zero one).
fn quat(v: &[f64]) -> Quat {
    math::quat_from_array([v[0], v[1], v[2], v[3]]).unwrap_or_else(Quat::identity)
}
