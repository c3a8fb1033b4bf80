//! A snapshot of kinematic chains (in the scene or an environment's own tree) as pure
//! data: forward kinematics, the analytic Jacobian and the tip-to-target error, with no
//! reference to the trees they were read from (the world reads them:
//! `gantry_world::ik::build_model`).
//!
//! Building the snapshot folds every rigid part of a base→tip path (links, dummies, fixed
//! joints) into one constant transform per movable joint, so a solver iteration costs a
//! handful of isometry products instead of a walk over the object tree, and the trees are
//! untouched until a solution is accepted.
//!
//! Frames: joint axes and origins come out in the world frame. Position errors and
//! Jacobian rows are expressed in the element's *base* frame (so `constraint_x` means the
//! base's X, as in CoppeliaSim); orientation errors and rows in the *tip* frame, which makes
//! `constraint_alpha_beta` (tip Z direction) and `constraint_gamma` (rotation about tip Z)
//! separate rows. With full constraints the choice of frame does not change the solution:
//! damped least squares is invariant under a rotation of its rows.

use nalgebra::{DMatrix, DVector};

use gantry_scene::Handle;
use gantry_scene::math::{Pose, Vec3};
use gantry_scene::scene::JointType;

use crate::environment::Constraints;

/// One movable joint of the problem (shared by every element whose path crosses it).
#[derive(Debug, Clone, PartialEq)]
pub struct JointSlot {
    /// The joint (a scene handle, or one of the environment's own objects).
    pub handle: Handle,
    /// Revolute (rad) or prismatic (m); fixed joints never become slots.
    pub joint_type: JointType,
    /// Whether the position wraps into (-pi, pi].
    pub cyclic: bool,
    /// Limits `(min, max)`, `None` when unlimited.
    pub limits: Option<(f64, f64)>,
}

impl JointSlot {
    /// Clamps to the limits, or wraps a cyclic joint, as the scene will when the
    /// solution is applied ([`gantry_scene::math::constrain_joint`]).
    pub fn constrain(&self, q: f64) -> f64 {
        gantry_scene::math::constrain_joint(q, self.cyclic, self.limits)
    }

    /// The joint's motion at position `q`: rotation about, or translation along, local Z.
    pub fn motion(&self, q: f64) -> Pose {
        match self.joint_type {
            JointType::Revolute => Pose::rotation(Vec3::z() * q),
            JointType::Prismatic => Pose::translation(0.0, 0.0, q),
            JointType::Fixed => Pose::identity(),
        }
    }
}

/// The base→tip path of one element, folded into constant transforms.
#[derive(Debug, Clone, PartialEq)]
pub struct ElementChain {
    /// For each movable joint from base to tip: the constant transform from the previous
    /// joint's moving frame (or, for the first, the world) to this joint's fixed frame,
    /// and the joint's slot index.
    links: Vec<(Pose, usize)>,
    /// From the last joint's moving frame to the tip.
    tip_offset: Pose,
    /// World pose of the frame constraints are expressed in (the base; identity for -1).
    base_frame: Pose,
}

/// The pose of the tip and, per link, the joint's world origin and axis (unit), at one
/// configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainPose {
    /// Tip pose in the world frame.
    pub tip: Pose,
    /// `(slot, origin, axis)` in the world frame, base to tip.
    pub joints: Vec<(usize, Vec3, Vec3)>,
}

impl ElementChain {
    /// A chain from its parts: per movable joint, the constant transform from the previous
    /// joint's moving frame (the first: from the world) to the joint's fixed frame and the
    /// joint's slot; the transform from the last moving frame to the tip; the world pose of
    /// the constraint frame. The world builds these from the trees
    /// (`gantry_world::ik::build_model`).
    pub fn new(links: Vec<(Pose, usize)>, tip_offset: Pose, base_frame: Pose) -> Self {
        Self {
            links,
            tip_offset,
            base_frame,
        }
    }

    /// Forward kinematics at joint values `q` (indexed by slot).
    pub fn forward(&self, q: &[f64], slots: &[JointSlot]) -> ChainPose {
        let mut x = Pose::identity();
        let mut joints = Vec::with_capacity(self.links.len());
        for &(fixed, slot) in &self.links {
            x *= fixed;
            joints.push((slot, x.translation.vector, x.rotation * Vec3::z()));
            x *= slots[slot].motion(q[slot]);
        }
        ChainPose {
            tip: x * self.tip_offset,
            joints,
        }
    }

    /// World pose of the constraint frame.
    pub fn base_frame(&self) -> &Pose {
        &self.base_frame
    }
}

/// An element ready to solve: its chain, target and settings.
#[derive(Debug, Clone, PartialEq)]
pub struct ElementModel {
    /// The chain.
    pub chain: ElementChain,
    /// Target pose, world frame, read when the model was built.
    pub target: Pose,
    /// What is constrained.
    pub constraints: Constraints,
    /// Success thresholds (m, rad).
    pub precision: [f64; 2],
    /// Linear, angular and element weights on the error rows.
    pub weights: [f64; 3],
}

/// Tip-to-target distances of one element, counting constrained components only.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Distance {
    /// Position distance, m.
    pub linear: f64,
    /// Orientation distance, rad.
    pub angular: f64,
}

/// The error rows of an element and their Jacobian, at one configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct Linearization {
    /// `rows × slots`.
    pub jacobian: DMatrix<f64>,
    /// The desired change of each row (m or rad), unweighted.
    pub error: DVector<f64>,
    /// Which rows are linear (true) or angular (false), for weighting.
    pub linear_rows: Vec<bool>,
    /// The distances the precision test uses.
    pub distance: Distance,
}

impl ElementModel {
    /// Distances, error rows and Jacobian at joint values `q` (indexed by slot).
    pub fn linearize(&self, q: &[f64], slots: &[JointSlot]) -> Linearization {
        let pose = self.chain.forward(q, slots);
        let c = self.constraints;
        let base_rot_inv = self.chain.base_frame.rotation.inverse();
        let tip_rot_inv = pose.tip.rotation.inverse();
        let p_tip = pose.tip.translation.vector;

        // Position: base frame, only the constrained axes.
        let dp = base_rot_inv * (self.target.translation.vector - p_tip);
        let axes: Vec<usize> = [Constraints::X, Constraints::Y, Constraints::Z]
            .iter()
            .enumerate()
            .filter(|(_, a)| c.contains(**a))
            .map(|(i, _)| i)
            .collect();
        let linear = axes.iter().map(|&i| dp[i] * dp[i]).sum::<f64>().sqrt();

        // Orientation: the rotation taking the tip onto the target, in the tip frame.
        let rel = tip_rot_inv * self.target.rotation;
        let (omega, ang_rows, angular) = orientation_error(c, &rel);

        let n_rows = axes.len() + ang_rows.len();
        let mut jacobian = DMatrix::zeros(n_rows, slots.len());
        let mut error = DVector::zeros(n_rows);
        let mut linear_rows = Vec::with_capacity(n_rows);
        for (r, &i) in axes.iter().enumerate() {
            error[r] = dp[i];
            linear_rows.push(true);
        }
        for (k, &i) in ang_rows.iter().enumerate() {
            error[axes.len() + k] = omega[i];
            linear_rows.push(false);
        }
        for &(slot, origin, axis) in &pose.joints {
            // Analytic columns: a revolute joint moves the tip point by axis × lever and
            // turns it about its axis; a prismatic one translates it along its axis.
            let (lin, ang) = match slots[slot].joint_type {
                JointType::Revolute => (axis.cross(&(p_tip - origin)), axis),
                _ => (axis, Vec3::zeros()),
            };
            let lin = base_rot_inv * lin;
            let ang = tip_rot_inv * ang;
            // `+=`: a joint met twice (impossible in a tree, but cheap to honour) sums.
            for (r, &i) in axes.iter().enumerate() {
                jacobian[(r, slot)] += lin[i];
            }
            for (k, &i) in ang_rows.iter().enumerate() {
                jacobian[(axes.len() + k, slot)] += ang[i];
            }
        }
        Linearization {
            jacobian,
            error,
            linear_rows,
            distance: Distance { linear, angular },
        }
    }
}

/// The orientation error as a tip-frame rotation vector, the indices of the rows it
/// contributes, and the angular distance, for rotation `rel` = tip⁻¹ · target.
fn orientation_error(c: Constraints, rel: &gantry_scene::math::Quat) -> (Vec3, Vec<usize>, f64) {
    let ab = c.contains(Constraints::ALPHA_BETA);
    let g = c.contains(Constraints::GAMMA);
    match (ab, g) {
        (true, true) => {
            let omega = rel.scaled_axis();
            (omega, vec![0, 1, 2], rel.angle())
        }
        (true, false) => {
            // Only the direction of Z matters: the shortest rotation from the tip's Z to
            // the target's Z, which has no Z component in the tip frame.
            let zt = rel * Vec3::z();
            let angle = zt.z.clamp(-1.0, 1.0).acos();
            let axis = Vec3::z().cross(&zt);
            let n = axis.norm();
            let omega = if n > 1e-12 {
                axis * (angle / n)
            } else if zt.z < 0.0 {
                // Antiparallel: any axis in the XY plane; X is deterministic.
                Vec3::x() * angle
            } else {
                Vec3::zeros()
            };
            (omega, vec![0, 1], angle)
        }
        (false, true) => {
            // Only the twist about Z: the twist part of a swing-twist split of `rel`.
            let twist = gantry_scene::math::wrap_angle(2.0 * rel.k.atan2(rel.w));
            (Vec3::z() * twist, vec![2], twist.abs())
        }
        (false, false) => (Vec3::zeros(), Vec::new(), 0.0),
    }
}

/// Every element of a group plus the joints they share: the whole problem of one solve.
#[derive(Debug, Clone, PartialEq)]
pub struct KinematicModel {
    /// The movable joints, in order of first appearance (base to tip of each element).
    pub slots: Vec<JointSlot>,
    /// Joint values read from the trees when the model was built.
    pub start: Vec<f64>,
    /// The elements.
    pub elements: Vec<ElementModel>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use gantry_scene::math::Quat;

    /// A three-joint toy chain (revolute Z, revolute Y-ish, prismatic) with offsets, built
    /// by hand so the tests do not depend on scene loading.
    fn toy() -> (ElementModel, Vec<JointSlot>) {
        let slot = |joint_type, cyclic| JointSlot {
            handle: 0,
            joint_type,
            cyclic,
            limits: None,
        };
        let slots = vec![
            slot(JointType::Revolute, true),
            slot(JointType::Revolute, false),
            slot(JointType::Prismatic, false),
        ];
        let r = |v: Vec3| Pose::rotation(v);
        let links = vec![
            (Pose::translation(0.1, -0.2, 0.3), 0),
            (Pose::translation(0.05, 0.0, 0.35) * r(Vec3::new(0.4, 0.0, 0.0)), 1),
            (Pose::translation(0.3, 0.1, 0.0) * r(Vec3::new(0.0, 1.1, 0.2)), 2),
        ];
        let chain = ElementChain {
            links,
            tip_offset: Pose::translation(0.02, 0.03, 0.1) * r(Vec3::new(0.3, -0.2, 0.5)),
            base_frame: Pose::translation(0.5, 0.0, 0.0) * r(Vec3::new(0.0, 0.0, 0.7)),
        };
        let model = ElementModel {
            chain,
            target: Pose::identity(),
            constraints: Constraints::POSE,
            precision: [1e-3, 1e-3],
            weights: [1.0; 3],
        };
        (model, slots)
    }

    /// The Jacobian columns equal central finite differences of the tip pose: linear rows
    /// of the tip position in the base frame, angular rows of the tip rotation in the tip
    /// frame (`log(R(q)^T R(q+h))/h`).
    #[test]
    fn jacobian_matches_finite_differences() {
        let (model, slots) = toy();
        for q in [[0.0, 0.0, 0.0], [0.7, -1.2, 0.15], [-2.9, 2.0, -0.3]] {
            let lin = model.linearize(&q, &slots);
            let pose = model.chain.forward(&q, &slots);
            let base_inv = model.chain.base_frame.rotation.inverse();
            let h = 1e-6;
            for j in 0..3 {
                let mut qp = q;
                let mut qm = q;
                qp[j] += h;
                qm[j] -= h;
                let fp = model.chain.forward(&qp, &slots).tip;
                let fm = model.chain.forward(&qm, &slots).tip;
                let dp = base_inv * (fp.translation.vector - fm.translation.vector) / (2.0 * h);
                let rot: Quat = fm.rotation.inverse() * fp.rotation;
                let dw = rot.scaled_axis() / (2.0 * h);
                // Rotation from the midpoint frame; the tip frame at q differs by O(h).
                let dw = pose.tip.rotation.inverse() * (fm.rotation * dw);
                for i in 0..3 {
                    assert!((lin.jacobian[(i, j)] - dp[i]).abs() < 1e-7, "lin q={q:?} j={j} i={i}");
                    assert!(
                        (lin.jacobian[(3 + i, j)] - dw[i]).abs() < 1e-7,
                        "ang q={q:?} j={j} i={i}"
                    );
                }
            }
        }
    }

    /// The error is zero when the target is the tip, and it points the right way: a small
    /// step along `J^+ e` reduces it.
    #[test]
    fn error_vanishes_at_the_tip_and_decreases_along_the_newton_step() {
        let (mut model, slots) = toy();
        let q = [0.3, -0.4, 0.1];
        model.target = model.chain.forward(&q, &slots).tip;
        let at = model.linearize(&q, &slots);
        assert!(at.error.norm() < 1e-12 && at.distance.linear < 1e-12 && at.distance.angular < 1e-7);

        let q0 = [0.35, -0.45, 0.12];
        let l0 = model.linearize(&q0, &slots);
        let dq = l0.jacobian.clone().pseudo_inverse(1e-12).expect("svd") * &l0.error;
        let q1: Vec<f64> = q0.iter().zip(dq.iter()).map(|(a, b)| a + 0.5 * b).collect();
        let l1 = model.linearize(&q1, &slots);
        assert!(l1.error.norm() < 0.6 * l0.error.norm());
    }

    #[test]
    fn partial_orientation_constraints_have_their_own_rows() {
        let (mut model, slots) = toy();
        let q = [0.0; 3];
        let tip = model.chain.forward(&q, &slots).tip;
        // Target = tip twisted about its own Z by 0.3 rad.
        model.target = tip * Pose::rotation(Vec3::z() * 0.3);
        model.constraints = Constraints::ALPHA_BETA;
        let l = model.linearize(&q, &slots);
        assert_eq!(l.error.len(), 2);
        assert!(l.error.norm() < 1e-12, "a twist does not move the Z axis");
        model.constraints = Constraints::GAMMA;
        let l = model.linearize(&q, &slots);
        assert_eq!(l.error.len(), 1);
        assert!((l.error[0] - 0.3).abs() < 1e-12 && (l.distance.angular - 0.3).abs() < 1e-12);
        model.constraints = Constraints(Constraints::X.0 | Constraints::Z.0);
        let l = model.linearize(&q, &slots);
        assert_eq!(l.error.len(), 2);
    }
}
