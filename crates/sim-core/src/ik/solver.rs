//! The iterative solver over a [`KinematicModel`]: pure, deterministic, never touches the
//! scene.
//!
//! Each iteration stacks every element's error rows `e` (weighted as CoppeliaSim does: the
//! linear/angular weights scale the error, not the Jacobian) and Jacobian `J`, and steps
//! `Δq = J^T (J J^T + λ² I)^-1 e` (damped least squares; the other methods are variants).
//! A revolute step is wrapped into (-pi, pi] as CoppeliaSim does; the new values are then
//! clamped to the limits (cyclic joints wrapped), so every iterate is a configuration the
//! scene accepts. Iteration stops once every element is within [`STOP_TOLERANCE`] (much
//! tighter than the default success precision, so repeated solves do not drift) or after
//! the group's maximum. The result is the best iterate seen, measured in units of each
//! element's precision: damped steps can overshoot near singularities, and a later worse
//! iterate should not replace an earlier better one.

use nalgebra::{DMatrix, DVector};

use super::chain::{Distance, KinematicModel};
use super::environment::IkMethod;

/// Iteration stops early once every element is within this linear (m) and angular (rad)
/// distance of its target.
pub const STOP_TOLERANCE: [f64; 2] = [1e-6, 1e-5];

/// `simIK.calc_notperformed`: the group had nothing to solve.
pub const CALC_NOT_PERFORMED: i64 = 1;
/// `simIK.calc_cannotinvert`: the linear system could not be solved (or produced NaN).
pub const CALC_CANNOT_INVERT: i64 = 2;
/// `simIK.calc_notwithintolerance`: some element ended outside its precision.
pub const CALC_NOT_WITHIN_TOLERANCE: i64 = 4;
/// `simIK.calc_limithit`: a joint was clamped at a limit during the solve.
pub const CALC_LIMIT_HIT: i64 = 16;

/// The overall outcome, `simIK.result_*`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IkResult {
    /// `simIK.result_not_performed` (0).
    NotPerformed,
    /// `simIK.result_success` (1).
    Success,
    /// `simIK.result_fail` (2).
    Fail,
}

impl IkResult {
    /// CoppeliaSim's number.
    pub fn code(self) -> i64 {
        match self {
            Self::NotPerformed => 0,
            Self::Success => 1,
            Self::Fail => 2,
        }
    }
}

/// How to solve: the group's calculation settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveParams {
    /// The method.
    pub method: IkMethod,
    /// Damping λ (only damped least squares uses it).
    pub damping: f64,
    /// Maximum number of steps.
    pub max_iterations: u32,
}

/// What a solve produced.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// Joint values per slot of the model (within limits).
    pub q: Vec<f64>,
    /// Success or failure.
    pub result: IkResult,
    /// `simIK.calc_*` bits.
    pub flags: i64,
    /// Largest remaining linear (m) and angular (rad) distance over the elements.
    pub precision: [f64; 2],
    /// Number of steps taken.
    pub iterations: u32,
}

/// Solves `model` from its start configuration.
pub fn solve(model: &KinematicModel, params: &SolveParams) -> Solution {
    let n = model.slots.len();
    if model.elements.is_empty() || n == 0 {
        return Solution {
            q: model.start.clone(),
            result: IkResult::NotPerformed,
            flags: CALC_NOT_PERFORMED | CALC_NOT_WITHIN_TOLERANCE,
            precision: [0.0; 2],
            iterations: 0,
        };
    }
    let mut q = model.start.clone();
    let mut flags = 0;
    let mut best = (f64::INFINITY, q.clone(), Vec::new());
    let mut iterations = 0;
    loop {
        let (jacobian, error, distances) = stack(model, &q);
        let score = score(model, &distances);
        if score < best.0 {
            best = (score, q.clone(), distances.clone());
        }
        let converged = distances
            .iter()
            .zip(&model.elements)
            .all(|(d, e)| d.linear <= stop(e.precision[0], 0) && d.angular <= stop(e.precision[1], 1));
        if converged || iterations >= params.max_iterations {
            break;
        }
        let Some(dq) = step(params, &jacobian, &error) else {
            flags |= CALC_CANNOT_INVERT;
            break;
        };
        iterations += 1;
        for (i, slot) in model.slots.iter().enumerate() {
            let mut d = dq[i];
            if slot.joint_type == crate::scene::JointType::Revolute {
                d = d.sin().atan2(d.cos());
            }
            let raw = q[i] + d;
            let v = slot.constrain(raw);
            if !slot.cyclic && v != raw {
                flags |= CALC_LIMIT_HIT;
            }
            q[i] = v;
        }
    }
    let (_, q, distances) = best;
    let within = distances
        .iter()
        .zip(&model.elements)
        .all(|(d, e)| d.linear <= e.precision[0] && d.angular <= e.precision[1]);
    if !within {
        flags |= CALC_NOT_WITHIN_TOLERANCE;
    }
    let precision = distances
        .iter()
        .fold([0.0f64; 2], |acc, d| [acc[0].max(d.linear), acc[1].max(d.angular)]);
    Solution {
        q,
        result: if flags & (CALC_CANNOT_INVERT | CALC_NOT_WITHIN_TOLERANCE) == 0 {
            IkResult::Success
        } else {
            IkResult::Fail
        },
        flags,
        precision,
        iterations,
    }
}

/// The early-stop threshold for component `i` (0 linear, 1 angular): the fixed tolerance,
/// or the element's precision if a script asked for an even tighter one.
fn stop(precision: f64, i: usize) -> f64 {
    STOP_TOLERANCE[i].min(precision)
}

/// Sum over elements of the distance in units of the element's precision (the larger of
/// the linear and angular ratios), so that metres and radians compare sensibly.
fn score(model: &KinematicModel, distances: &[Distance]) -> f64 {
    distances
        .iter()
        .zip(&model.elements)
        .map(|(d, e)| {
            let l = d.linear / e.precision[0].max(f64::MIN_POSITIVE);
            let a = d.angular / e.precision[1].max(f64::MIN_POSITIVE);
            l.max(a)
        })
        .sum()
}

/// Every element's rows stacked: Jacobian, weighted error, and distances.
fn stack(model: &KinematicModel, q: &[f64]) -> (DMatrix<f64>, DVector<f64>, Vec<Distance>) {
    let parts: Vec<_> = model.elements.iter().map(|e| e.linearize(q, &model.slots)).collect();
    let rows: usize = parts.iter().map(|p| p.error.len()).sum();
    let mut jacobian = DMatrix::zeros(rows, model.slots.len());
    let mut error = DVector::zeros(rows);
    let mut r0 = 0;
    for (p, e) in parts.iter().zip(&model.elements) {
        let m = p.error.len();
        jacobian.rows_mut(r0, m).copy_from(&p.jacobian);
        for k in 0..m {
            let w = if p.linear_rows[k] { e.weights[0] } else { e.weights[1] };
            error[r0 + k] = p.error[k] * w * e.weights[2];
        }
        r0 += m;
    }
    (jacobian, error, parts.iter().map(|p| p.distance).collect())
}

/// One step `Δq` for the method, or `None` when the system cannot be solved.
fn step(params: &SolveParams, j: &DMatrix<f64>, e: &DVector<f64>) -> Option<DVector<f64>> {
    let damping = match params.method {
        IkMethod::JacobianTranspose => {
            let dq = j.transpose() * e;
            return dq.iter().all(|v| v.is_finite()).then_some(dq);
        }
        IkMethod::DampedLeastSquares => params.damping,
        // CoppeliaSim's "pseudo inverse" is DLS with a tiny damping, which keeps it
        // defined at singularities.
        IkMethod::PseudoInverse => 1e-6,
        IkMethod::UndampedPseudoInverse => 0.0,
    };
    let jt = j.transpose();
    let mut a = j * &jt;
    for i in 0..a.nrows() {
        a[(i, i)] += damping * damping;
    }
    // J J^T + λ² I is symmetric positive definite for λ > 0: Cholesky. Without damping
    // (or when rounding breaks definiteness) fall back to the SVD pseudo-inverse.
    let dq = match a.clone().cholesky() {
        Some(ch) => &jt * ch.solve(e),
        None => a.pseudo_inverse(1e-12).ok().map(|p| &jt * (p * e))?,
    };
    dq.iter().all(|v| v.is_finite()).then_some(dq)
}
