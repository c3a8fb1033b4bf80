//! Path objects and the path math under them.
//!
//! A path object (`sim.createPath`) is, as in CoppeliaSim 4.3+, a dummy in the object
//! tree; what makes it a path is kept here, by handle: its control points, whether it is
//! closed, how its curve is generated from them, the generated points with their lengths,
//! and the state V-REP's path API gives a path (its current position along itself and a
//! target nominal velocity). Every point is `x, y, z, qx, qy, qz, qw` in the path's own
//! frame; the API places them in the world with the dummy's pose.
//!
//! The curve: without smoothing it is the polyline through the control points; with a
//! smoothness in (0, 1] it is `subdiv` points resampled, at equal lengths, along the
//! polyline whose corners are rounded by quadratic Bezier curves of that strength
//! (`config.rs`, the method `sim.getPathInterpolatedConfig` calls `quadraticBezier`). A
//! closed path returns to its first control point. An orientation mode other than 0
//! replaces the points' orientations by a frame with one axis along the path and one as
//! close to the up vector as the tangent allows.
//!
//! Not here: a path's position does not advance by itself with its target velocity
//! (V-REP's path handling by the main script), and copies of a path object
//! (`sim.copyPasteObjects`) are plain dummies.

mod config;

use std::collections::BTreeMap;

pub use config::{DofType, Method, PathRef, count, lengths};

use crate::error::SimError;
use crate::handle::Handle;
use crate::math::{Quat, Vec3, quat_from_array, quat_to_array};
use crate::scene::PathModel;

/// One path point: `x, y, z, qx, qy, qz, qw` in the path's frame.
pub type PathPoint = [f64; 7];

/// The value types of a path point: a position and a quaternion.
pub const POSE_TYPES: [DofType; 7] = [
    DofType::Cartesian,
    DofType::Cartesian,
    DofType::Cartesian,
    DofType::Quaternion,
    DofType::Quaternion,
    DofType::Quaternion,
    DofType::Quaternion,
];

/// How a path's curve is generated from its control points (`sim.createPath`'s
/// `subdiv`, `smoothness`, `orientationMode` and `upVector`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shaping {
    /// Number of points of a smoothed curve (at least 2).
    pub subdiv: usize,
    /// 0 for the polyline through the control points, up to 1 for the roundest corners.
    pub smoothness: f64,
    /// 0: the control points' orientations, interpolated. 1 to 6: one axis along the
    /// path and one up: x along with y up, x along with z up, y along with x up, y along
    /// with z up, z along with x up, z along with y up.
    pub orientation: u8,
    /// The up direction of orientation modes 1 to 6, in the path's frame.
    pub up: [f64; 3],
}

impl Default for Shaping {
    /// `sim.createPath`'s defaults: 100 points, smoothness 1, orientation as given, z up.
    fn default() -> Self {
        Self {
            subdiv: 100,
            smoothness: 1.0,
            orientation: 0,
            up: [0.0, 0.0, 1.0],
        }
    }
}

impl Shaping {
    /// A polyline through the control points with their own orientations: V-REP 3's
    /// paths as gantry builds them from `sim.insertPathCtrlPoints`.
    pub const POLYLINE: Shaping = Shaping {
        subdiv: 2,
        smoothness: 0.0,
        orientation: 0,
        up: [0.0, 0.0, 1.0],
    };
}

/// A path object's data.
#[derive(Debug, Clone)]
pub struct PathObject {
    ctrl: Vec<PathPoint>,
    closed: bool,
    shaping: Shaping,
    points: Vec<PathPoint>,
    lengths: Vec<f64>,
    /// V-REP's path position (`sim.getPathPosition`), m along the path.
    position: f64,
    /// V-REP's target nominal velocity (`sim.setPathTargetNominalVelocity`), m/s; kept,
    /// not acted on.
    pub target_velocity: f64,
}

impl PathObject {
    /// A path through `ctrl` (quaternions normalised; a zero one is the identity).
    ///
    /// # Errors
    /// A value that is not finite, or a shaping out of range.
    pub fn new(ctrl: Vec<PathPoint>, closed: bool, shaping: Shaping) -> Result<Self, SimError> {
        if !(0.0..=1.0).contains(&shaping.smoothness) {
            return Err(SimError::bad_argument(format!(
                "smoothness: expected a value from 0 to 1, got {}",
                shaping.smoothness
            )));
        }
        if shaping.orientation > 6 {
            return Err(SimError::bad_argument(format!(
                "orientationMode: expected 0 to 6, got {}",
                shaping.orientation
            )));
        }
        let mut path = Self {
            ctrl: Vec::new(),
            closed,
            shaping: Shaping {
                subdiv: shaping.subdiv.max(2),
                ..shaping
            },
            points: Vec::new(),
            lengths: Vec::new(),
            position: 0.0,
            target_velocity: 0.0,
        };
        path.insert_ctrl_points(0, ctrl)?;
        Ok(path)
    }

    /// The curve of a scene's old path object. A model built in code may hold what a
    /// loader refuses: a smoothness out of 0..1 is clamped and points that are not
    /// finite are left out, so this cannot fail.
    pub fn from_model(m: &PathModel) -> Self {
        let ctrl: Vec<PathPoint> = m
            .ctrl_points
            .iter()
            .filter(|p| p.iter().all(|v| v.is_finite()))
            .copied()
            .collect();
        let smoothness = if m.smoothness.is_finite() {
            m.smoothness.clamp(0.0, 1.0)
        } else {
            0.0
        };
        let shaping = Shaping {
            subdiv: m.subdiv.clamp(2, 1_000_000),
            smoothness,
            orientation: 0,
            up: [0.0, 0.0, 1.0],
        };
        let mut path = Self {
            ctrl: Vec::new(),
            closed: m.closed,
            shaping,
            points: Vec::new(),
            lengths: Vec::new(),
            position: 0.0,
            target_velocity: 0.0,
        };
        // Finite points in, so this cannot fail.
        let _ = path.insert_ctrl_points(0, ctrl);
        path
    }

    /// The control points.
    pub fn ctrl_points(&self) -> &[PathPoint] {
        &self.ctrl
    }

    /// The generated points.
    pub fn points(&self) -> &[PathPoint] {
        &self.points
    }

    /// Each generated point's length along the path, m.
    pub fn lengths(&self) -> &[f64] {
        &self.lengths
    }

    /// The path's length, m (0 without points).
    pub fn length(&self) -> f64 {
        self.lengths.last().copied().unwrap_or(0.0)
    }

    /// Whether the path is closed.
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// Sets whether the path is closed, and regenerates it.
    pub fn set_closed(&mut self, closed: bool) {
        self.closed = closed;
        self.generate();
    }

    /// The path position, m along the path.
    pub fn position(&self) -> f64 {
        self.position
    }

    /// Sets the path position, m: kept within the path, wrapped round a closed one.
    pub fn set_position(&mut self, position: f64) {
        let l = self.length();
        self.position = if !position.is_finite() || l <= 0.0 {
            0.0
        } else if self.closed {
            position.rem_euclid(l)
        } else {
            position.clamp(0.0, l)
        };
    }

    /// Inserts control points before control point `index` (at the end when past it),
    /// and regenerates the curve.
    ///
    /// # Errors
    /// A value that is not finite; nothing is inserted then.
    pub fn insert_ctrl_points(&mut self, index: usize, pts: Vec<PathPoint>) -> Result<(), SimError> {
        if pts.iter().flatten().any(|v| !v.is_finite()) {
            return Err(SimError::bad_argument("control points must be finite numbers"));
        }
        let pts = pts.into_iter().map(|mut p| {
            let q = quat_from_array([p[3], p[4], p[5], p[6]]).unwrap_or_else(Quat::identity);
            p[3..].copy_from_slice(&quat_to_array(&q));
            p
        });
        let at = index.min(self.ctrl.len());
        self.ctrl.splice(at..at, pts);
        self.generate();
        Ok(())
    }

    /// Removes `count` control points from `index` on, and regenerates the curve.
    pub fn cut_ctrl_points(&mut self, index: usize, count: usize) {
        let from = index.min(self.ctrl.len());
        let to = from.saturating_add(count).min(self.ctrl.len());
        self.ctrl.drain(from..to);
        self.generate();
    }

    /// The position and orientation at `distance` m along the path (clamped to it), in
    /// the path's frame; `None` without points.
    pub fn pose_at(&self, distance: f64) -> Option<([f64; 3], Quat)> {
        let flat: Vec<f64> = self.points.iter().flatten().copied().collect();
        let p = PathRef::new(&flat, 7, &self.lengths, &POSE_TYPES).ok()?;
        let c = p.interpolate(distance, Method::LINEAR);
        let q = quat_from_array([c[3], c[4], c[5], c[6]]).unwrap_or_else(Quat::identity);
        Some(([c[0], c[1], c[2]], q))
    }

    /// Builds the points and lengths from the control points.
    fn generate(&mut self) {
        let mut base = self.ctrl.clone();
        if self.closed && base.len() >= 2 && base.first() != base.last() {
            base.push(base[0]);
        }
        self.points = match smoothed(&base, self.closed, &self.shaping) {
            Some(points) => points,
            None => base,
        };
        if self.shaping.orientation != 0 {
            orient(&mut self.points, self.closed, &self.shaping);
        }
        let flat: Vec<f64> = self.points.iter().flatten().copied().collect();
        self.lengths = lengths(&flat, 7).map(|(l, _)| l).unwrap_or_default();
        self.set_position(self.position);
    }
}

/// The curve through `base` with rounded corners, when the shaping smooths and there is
/// a corner to round.
fn smoothed(base: &[PathPoint], closed: bool, shaping: &Shaping) -> Option<Vec<PathPoint>> {
    if shaping.smoothness <= 0.0 || base.len() < 3 {
        return None;
    }
    let flat: Vec<f64> = base.iter().flatten().copied().collect();
    let (l, _) = lengths(&flat, 7).ok()?;
    let p = PathRef::new(&flat, 7, &l, &POSE_TYPES).ok()?;
    let method = Method {
        bezier: Some(shaping.smoothness),
        force_open: !closed,
    };
    let out = p.resample(shaping.subdiv, method);
    Some(
        out.chunks_exact(7)
            .map(|c| [c[0], c[1], c[2], c[3], c[4], c[5], c[6]])
            .collect(),
    )
}

/// Replaces each point's orientation by a frame with axis `along` on the tangent and
/// axis `up` as close to the up vector as it can be (orientation modes 1 to 6); a point
/// whose tangent is undefined or parallel to the up vector keeps its orientation.
fn orient(points: &mut [PathPoint], closed: bool, shaping: &Shaping) {
    let (along, up_axis) = match shaping.orientation {
        1 => (0, 1),
        2 => (0, 2),
        3 => (1, 0),
        4 => (1, 2),
        5 => (2, 0),
        _ => (2, 1),
    };
    let up = Vec3::from(shaping.up);
    let n = points.len();
    let pos = |i: usize| Vec3::new(points[i][0], points[i][1], points[i][2]);
    let mut frames = Vec::with_capacity(n);
    for i in 0..n {
        // A closed path's ends are one point: its neighbours are the second and the
        // second-to-last.
        let prev = if i > 0 {
            i - 1
        } else if closed && n > 2 {
            n - 2
        } else {
            0
        };
        let next = if i + 1 < n {
            i + 1
        } else if closed && n > 2 {
            1
        } else {
            n - 1
        };
        let t = pos(next) - pos(prev);
        let frame = t.try_normalize(1e-12).and_then(|t| {
            let u = (up - t * up.dot(&t)).try_normalize(1e-9)?;
            let mut cols = [Vec3::zeros(); 3];
            cols[along] = t;
            cols[up_axis] = u;
            let third = 3 - along - up_axis;
            cols[third] = cols[(third + 1) % 3].cross(&cols[(third + 2) % 3]);
            let m = nalgebra::Matrix3::from_columns(&cols);
            Some(Quat::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(
                m,
            )))
        });
        frames.push(frame);
    }
    for (p, f) in points.iter_mut().zip(frames) {
        if let Some(q) = f {
            p[3..].copy_from_slice(&quat_to_array(&q));
        }
    }
}

/// Every path object's data, by the handle of its dummy.
#[derive(Debug, Clone, Default)]
pub struct Paths {
    by_handle: BTreeMap<Handle, PathObject>,
}

impl Paths {
    /// Makes object `h` a path.
    pub fn insert(&mut self, h: Handle, path: PathObject) {
        self.by_handle.insert(h, path);
    }

    /// The path data of object `h`, if it is a path.
    pub fn get(&self, h: Handle) -> Option<&PathObject> {
        self.by_handle.get(&h)
    }

    /// The path data of object `h`, to change, if it is a path.
    pub fn get_mut(&mut self, h: Handle) -> Option<&mut PathObject> {
        self.by_handle.get_mut(&h)
    }

    /// Keeps only the paths whose object `keep` accepts (the others were removed).
    pub fn retain(&mut self, mut keep: impl FnMut(Handle) -> bool) {
        self.by_handle.retain(|h, _| keep(*h));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const I: [f64; 4] = [0.0, 0.0, 0.0, 1.0];

    fn pt(x: f64, y: f64, z: f64) -> PathPoint {
        [x, y, z, I[0], I[1], I[2], I[3]]
    }

    #[test]
    fn a_scene_path_is_built_from_its_model() {
        let m = PathModel {
            ctrl_points: vec![pt(0.0, 0.0, 0.0), pt(1.0, 0.0, 0.0), [f64::NAN; 7], pt(1.0, 1.0, 0.0)],
            closed: false,
            smoothness: 0.0,
            subdiv: 10,
        };
        let p = PathObject::from_model(&m);
        assert_eq!(p.ctrl_points().len(), 3, "the NaN point is left out");
        assert!((p.length() - 2.0).abs() < 1e-12);
        // Out-of-range shaping from code is held in range, not a panic.
        let p = PathObject::from_model(&PathModel {
            smoothness: 7.0,
            subdiv: 0,
            closed: true,
            ..m
        });
        assert!(p.is_closed() && p.points().len() >= 2 && p.length().is_finite());
    }

    #[test]
    fn a_polyline_path_and_its_position() {
        let mut p = PathObject::new(vec![pt(0.0, 0.0, 0.0), pt(2.0, 0.0, 0.0)], false, Shaping::POLYLINE).unwrap();
        assert_eq!(p.length(), 2.0);
        let (at, _) = p.pose_at(0.5).unwrap();
        assert_eq!(at, [0.5, 0.0, 0.0]);
        p.insert_ctrl_points(9, vec![pt(2.0, 1.0, 0.0)]).unwrap();
        assert_eq!(p.length(), 3.0, "appended at the end");
        p.set_position(5.0);
        assert_eq!(p.position(), 3.0, "an open path's position stays on it");
        p.set_closed(true);
        assert_eq!(p.points().len(), 4, "back to the first point");
        assert!((p.length() - (3.0 + 5f64.sqrt())).abs() < 1e-12);
        p.set_position(-1.0);
        assert!((p.position() - (p.length() - 1.0)).abs() < 1e-12, "wrapped");
        p.cut_ctrl_points(1, 1);
        assert_eq!(p.ctrl_points().len(), 2);
        assert!(p.insert_ctrl_points(0, vec![[f64::NAN; 7]]).is_err());
        assert!(
            PathObject::new(Vec::new(), false, Shaping::default())
                .unwrap()
                .pose_at(0.0)
                .is_none()
        );
    }

    #[test]
    fn smoothing_and_orientation_modes() {
        let shaping = Shaping {
            subdiv: 11,
            smoothness: 1.0,
            orientation: 2,
            up: [0.0, 0.0, 1.0],
        };
        let p = PathObject::new(
            vec![pt(0.0, 0.0, 0.0), pt(1.0, 0.0, 0.0), pt(1.0, 1.0, 0.0)],
            false,
            shaping,
        )
        .unwrap();
        assert_eq!(p.points().len(), 11);
        assert_eq!(p.points()[0][..3], [0.0, 0.0, 0.0]);
        assert_eq!(p.points()[10][..3], [1.0, 1.0, 0.0]);
        // The corner is cut: no point is at (1, 0).
        assert!(p.points().iter().all(|q| (q[0] - 1.0).abs() + q[1].abs() > 1e-3));
        // Mode 2, x along the path with z up: at the start x is +x, at the end +y.
        let x_axis = |q: &PathPoint| quat_from_array([q[3], q[4], q[5], q[6]]).unwrap() * Vec3::x();
        assert!((x_axis(&p.points()[0]) - Vec3::x()).norm() < 1e-9);
        assert!((x_axis(&p.points()[10]) - Vec3::y()).norm() < 1e-9);
        assert!(
            PathObject::new(
                Vec::new(),
                false,
                Shaping {
                    smoothness: 2.0,
                    ..shaping
                }
            )
            .is_err()
        );
    }
}
