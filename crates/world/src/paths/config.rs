//! CoppeliaSim 4.3+'s path math on flat lists of configurations (`sim.getPathLengths`,
//! `sim.getPathInterpolatedConfig`, `sim.resamplePath`): a path is `n` configurations
//! of `dof` numbers each, row-major, and every configuration has a length, its distance
//! from the first one along the path.
//!
//! Interpolation is by length. Between two configurations it is linear per value type:
//! Cartesian values are blended, 2pi-cyclic values take the shorter way round, and each
//! run of four quaternion values (`qx, qy, qz, qw`) is slerped. The quadratic Bezier
//! method rounds every corner: around configuration `k` the stretch from
//! `strength * half the previous segment` before it to `strength * half the next
//! segment` after it is replaced by the quadratic Bezier curve on the two ends of the
//! stretch with configuration `k` as its middle control point (evaluated by de
//! Casteljau's construction with the same per-type blends, so quaternions stay unit).
//! A path whose first and last configurations coincide is closed, unless the caller
//! forces it open: its first corner, where the end meets the start, is rounded too.
//! As in CoppeliaSim, the length along a rounded corner is the parameter of the curve,
//! not its arc length.

use crate::error::SimError;
use crate::math::{Quat, quat_from_array, quat_to_array, wrap_angle};

/// What one value of a configuration is (`types` of `sim.getPathInterpolatedConfig`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DofType {
    /// 0: a Cartesian value, blended linearly.
    Cartesian,
    /// 1: an angle with period 2pi (a cyclic revolute joint): the shorter way round,
    /// the result in (-pi, pi].
    Cyclic,
    /// 2: one of four consecutive quaternion values `qx, qy, qz, qw`, slerped together.
    Quaternion,
}

impl DofType {
    /// CoppeliaSim's code for a type (0, 1 or 2).
    ///
    /// # Errors
    /// Any other code.
    pub fn from_code(code: i64) -> Result<Self, SimError> {
        match code {
            0 => Ok(Self::Cartesian),
            1 => Ok(Self::Cyclic),
            2 => Ok(Self::Quaternion),
            other => Err(SimError::bad_argument(format!(
                "a value type is 0 (Cartesian), 1 (2pi-cyclic) or 2 (quaternion), got {other}"
            ))),
        }
    }
}

/// How to interpolate (`method` of `sim.getPathInterpolatedConfig`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Method {
    /// `None` for `'linear'`, or the strength of `'quadraticBezier'` in (0, 1]: the part
    /// of each half segment next to a corner that the rounding takes.
    pub bezier: Option<f64>,
    /// `forceOpen`: a path whose ends coincide is still open.
    pub force_open: bool,
}

impl Method {
    /// Linear interpolation, closed paths closed (CoppeliaSim's default).
    pub const LINEAR: Method = Method {
        bezier: None,
        force_open: false,
    };
}

/// A path as CoppeliaSim's path functions take it, checked.
#[derive(Debug, Clone, Copy)]
pub struct PathRef<'a> {
    values: &'a [f64],
    dof: usize,
    lengths: &'a [f64],
    types: &'a [DofType],
}

impl<'a> PathRef<'a> {
    /// A path of `values.len() / dof` configurations with their `lengths`, each value
    /// of the type `types` gives (all Cartesian when `types` is empty).
    ///
    /// # Errors
    /// A dof of 0, values that are not whole configurations or not finite, no
    /// configuration, a length per configuration missing or decreasing, types not one
    /// per value, or quaternion values not in runs of four.
    pub fn new(values: &'a [f64], dof: usize, lengths: &'a [f64], types: &'a [DofType]) -> Result<Self, SimError> {
        let n = count(values, dof)?;
        if lengths.len() != n {
            return Err(SimError::bad_argument(format!(
                "pathLengths: expected one length per configuration ({n}), got {}",
                lengths.len()
            )));
        }
        if lengths.iter().any(|l| !l.is_finite()) || lengths.windows(2).any(|w| w[1] < w[0]) {
            return Err(SimError::bad_argument(
                "pathLengths: expected finite lengths that never decrease",
            ));
        }
        if !types.is_empty() {
            if types.len() != dof {
                return Err(SimError::bad_argument(format!(
                    "types: expected one type per value of a configuration ({dof}), got {}",
                    types.len()
                )));
            }
            let mut i = 0;
            while i < dof {
                if types[i] == DofType::Quaternion {
                    if i + 4 > dof || types[i..i + 4].iter().any(|t| *t != DofType::Quaternion) {
                        return Err(SimError::bad_argument(
                            "types: quaternion values (2) come in runs of four (qx, qy, qz, qw)",
                        ));
                    }
                    i += 4;
                } else {
                    i += 1;
                }
            }
        }
        Ok(Self {
            values,
            dof,
            lengths,
            types,
        })
    }

    /// Number of configurations.
    pub fn len(&self) -> usize {
        self.lengths.len()
    }

    /// Whether the path has no configuration (never: [`PathRef::new`] refuses it).
    pub fn is_empty(&self) -> bool {
        self.lengths.is_empty()
    }

    /// Configuration `i`.
    fn at(&self, i: usize) -> &'a [f64] {
        &self.values[i * self.dof..(i + 1) * self.dof]
    }

    fn dof_type(&self, i: usize) -> DofType {
        self.types.get(i).copied().unwrap_or(DofType::Cartesian)
    }

    /// `a` to `b` at fraction `f`, per value type.
    fn blend(&self, a: &[f64], b: &[f64], f: f64) -> Vec<f64> {
        let mut out = vec![0.0; self.dof];
        let mut i = 0;
        while i < self.dof {
            match self.dof_type(i) {
                DofType::Cartesian => {
                    out[i] = a[i] + (b[i] - a[i]) * f;
                    i += 1;
                }
                DofType::Cyclic => {
                    out[i] = wrap_angle(a[i] + wrap_angle(b[i] - a[i]) * f);
                    i += 1;
                }
                DofType::Quaternion => {
                    let q = slerp(&a[i..i + 4], &b[i..i + 4], f);
                    out[i..i + 4].copy_from_slice(&q);
                    i += 4;
                }
            }
        }
        out
    }

    /// Whether the ends coincide: a closed path.
    fn ends_meet(&self) -> bool {
        let n = self.len();
        n >= 3
            && self
                .at(0)
                .iter()
                .zip(self.at(n - 1))
                .all(|(a, b)| (a - b).abs() <= 1e-9 * (1.0 + a.abs()))
    }

    /// The configuration at length `t` on the straight segments.
    fn linear(&self, t: f64) -> Vec<f64> {
        let n = self.len();
        if n == 1 {
            return self.at(0).to_vec();
        }
        // The last segment starting at or before t (the first when t is before it).
        let i = self.lengths[..n - 1]
            .partition_point(|l| *l <= t)
            .saturating_sub(1)
            .min(n - 2);
        let (l0, l1) = (self.lengths[i], self.lengths[i + 1]);
        let f = if l1 > l0 {
            ((t - l0) / (l1 - l0)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        self.blend(self.at(i), self.at(i + 1), f)
    }

    /// The configuration at length `t` (clamped to the path), by `method`.
    pub fn interpolate(&self, t: f64, method: Method) -> Vec<f64> {
        let n = self.len();
        let total = self.lengths[n - 1];
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, total) };
        let Some(strength) = method.bezier else {
            return self.linear(t);
        };
        let s = strength.clamp(0.0, 1.0);
        if n < 3 || s <= 0.0 {
            return self.linear(t);
        }
        let half = |i: usize| (self.lengths[i + 1] - self.lengths[i]) * 0.5 * s;
        // An interior corner k rounds [L_k - before, L_k + after].
        let k = self.lengths.partition_point(|l| *l <= t).clamp(1, n - 1);
        for corner in [k - 1, k] {
            if corner == 0 || corner >= n - 1 {
                continue;
            }
            let (before, after) = (half(corner - 1), half(corner));
            let lk = self.lengths[corner];
            if t >= lk - before && t <= lk + after && before + after > 0.0 {
                let u = (t - (lk - before)) / (before + after);
                return self.bezier(&self.linear(lk - before), self.at(corner), &self.linear(lk + after), u);
            }
        }
        // The corner where a closed path's end meets its start.
        if !method.force_open && self.ends_meet() {
            let (before, after) = (half(n - 2), half(0));
            let offset = if t <= after {
                Some(before + t)
            } else if t >= total - before {
                Some(t - (total - before))
            } else {
                None
            };
            if let Some(offset) = offset.filter(|_| before + after > 0.0) {
                let u = offset / (before + after);
                return self.bezier(&self.linear(total - before), self.at(0), &self.linear(after), u);
            }
        }
        self.linear(t)
    }

    /// The quadratic Bezier curve on `p0`, `p1`, `p2` at `u`, by de Casteljau.
    fn bezier(&self, p0: &[f64], p1: &[f64], p2: &[f64], u: f64) -> Vec<f64> {
        self.blend(&self.blend(p0, p1, u), &self.blend(p1, p2, u), u)
    }

    /// `count` configurations at equal lengths from the start to the end of the path
    /// (`sim.resamplePath`), flat.
    pub fn resample(&self, count: usize, method: Method) -> Vec<f64> {
        let total = self.lengths[self.len() - 1];
        let mut out = Vec::with_capacity(count * self.dof);
        for j in 0..count {
            let t = if count > 1 {
                total * j as f64 / (count - 1) as f64
            } else {
                0.0
            };
            out.extend(self.interpolate(t, method));
        }
        out
    }
}

/// Number of configurations of `dof` values in `values`.
///
/// # Errors
/// A dof of 0, no configuration, a partial one, or a value that is not finite.
pub fn count(values: &[f64], dof: usize) -> Result<usize, SimError> {
    if dof == 0 {
        return Err(SimError::bad_argument(
            "dof: expected at least 1 value per configuration",
        ));
    }
    if values.is_empty() || !values.len().is_multiple_of(dof) {
        return Err(SimError::bad_argument(format!(
            "path: expected whole configurations of {dof} values, got {} values",
            values.len()
        )));
    }
    if values.iter().any(|v| !v.is_finite()) {
        return Err(SimError::bad_argument("path: values must be finite numbers"));
    }
    Ok(values.len() / dof)
}

/// `sim.getPathLengths`: each configuration's distance from the first along the path,
/// and the total, measured in the first (up to) three values as Cartesian coordinates
/// (the rest of a configuration, a pose's quaternion say, does not count).
///
/// # Errors
/// As [`count`].
pub fn lengths(values: &[f64], dof: usize) -> Result<(Vec<f64>, f64), SimError> {
    let n = count(values, dof)?;
    let d = dof.min(3);
    let mut out = Vec::with_capacity(n);
    let mut total = 0.0;
    out.push(0.0);
    for i in 1..n {
        let (a, b) = (&values[(i - 1) * dof..], &values[i * dof..]);
        total += (0..d).map(|k| (b[k] - a[k]).powi(2)).sum::<f64>().sqrt();
        out.push(total);
    }
    Ok((out, total))
}

/// Slerp between two `[qx, qy, qz, qw]` (normalised first; a zero quaternion counts as
/// the identity), the shorter way.
fn slerp(a: &[f64], b: &[f64], f: f64) -> [f64; 4] {
    let q = |v: &[f64]| quat_from_array([v[0], v[1], v[2], v[3]]).unwrap_or_else(Quat::identity);
    let (qa, qb) = (q(a), q(b));
    // nalgebra's slerp refuses (near-)opposite quaternions; nlerp is exact enough there.
    let r = qa.try_slerp(&qb, f, 1e-9).unwrap_or_else(|| qa.nlerp(&qb, f));
    quat_to_array(&r)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &[f64], b: &[f64]) {
        assert_eq!(a.len(), b.len(), "{a:?} vs {b:?}");
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() < 1e-9, "{a:?} vs {b:?}");
        }
    }

    #[test]
    fn lengths_count_the_first_three_values_only() {
        // Two poses 3-4-0 apart with different quaternions: 5 m.
        let path = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 3.0, 4.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        let (l, total) = lengths(&path, 7).unwrap();
        close(&l, &[0.0, 5.0]);
        assert_eq!(total, 5.0);
        // One-dimensional: |2 - 0| + |-1 - 2|.
        let (l, _) = lengths(&[0.0, 2.0, -1.0], 1).unwrap();
        close(&l, &[0.0, 2.0, 5.0]);
        assert!(lengths(&[1.0, 2.0, 3.0], 2).is_err(), "not whole configurations");
        assert!(lengths(&[], 3).is_err() && lengths(&[1.0], 0).is_err());
    }

    #[test]
    fn linear_interpolation_per_value_type() {
        // An L: (0,0) -> (2,0) -> (2,1), an angle from 3 to -3 rad (the short way
        // through pi), and a quarter turn about z.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let path = [
            0.0, 0.0, 3.0, 0.0, 0.0, 0.0, 1.0, //
            2.0, 0.0, -3.0, 0.0, 0.0, h, h, //
            2.0, 1.0, -3.0, 0.0, 0.0, h, h,
        ];
        // The third value is an angle, not a coordinate: lengths in x, y only.
        let l = [0.0, 2.0, 3.0];
        let types = [
            DofType::Cartesian,
            DofType::Cartesian,
            DofType::Cyclic,
            DofType::Quaternion,
            DofType::Quaternion,
            DofType::Quaternion,
            DofType::Quaternion,
        ];
        let p = PathRef::new(&path, 7, &l, &types).unwrap();
        let mid = p.interpolate(1.0, Method::LINEAR);
        // Half way: x = 1; the angle half way from 3 to 2pi - 3 the short way, pi; an
        // eighth turn about z.
        let (s, c) = (std::f64::consts::FRAC_PI_8.sin(), std::f64::consts::FRAC_PI_8.cos());
        close(&mid, &[1.0, 0.0, std::f64::consts::PI, 0.0, 0.0, s, c]);
        close(&p.interpolate(2.5, Method::LINEAR)[..2], &[2.0, 0.5]);
        close(&p.interpolate(-1.0, Method::LINEAR)[..2], &[0.0, 0.0]);
        close(&p.interpolate(9.0, Method::LINEAR)[..2], &[2.0, 1.0]);
        // Without types every value is Cartesian: the angle goes through 0.
        let plain = PathRef::new(&path, 7, &l, &[]).unwrap();
        assert!((plain.interpolate(1.0, Method::LINEAR)[2] - 0.0).abs() < 1e-12);
        assert!(PathRef::new(&path, 7, &l, &types[..6]).is_err(), "a type per value");
        let bad = [DofType::Quaternion; 3];
        assert!(PathRef::new(&path[..6], 3, &l[..2], &bad).is_err(), "runs of four");
        assert!(PathRef::new(&path, 7, &[0.0, 2.0, 1.0], &[]).is_err(), "decreasing");
    }

    #[test]
    fn quadratic_bezier_rounds_corners_and_closed_ends() {
        // The corner (2,0) of the L, strength 1: the curve starts half way along the first
        // segment, (1,0), and ends half way along the second, (2,0.5).
        let path = [0.0, 0.0, 2.0, 0.0, 2.0, 1.0];
        let (l, _) = lengths(&path, 2).unwrap();
        let p = PathRef::new(&path, 2, &l, &[]).unwrap();
        let bez = Method {
            bezier: Some(1.0),
            force_open: false,
        };
        // At the middle of the rounding (length 1.75 of [1, 2.5]: u = 0.5):
        // 0.25 (1,0) + 0.5 (2,0) + 0.25 (2,0.5).
        close(&p.interpolate(1.75, bez), &[1.75, 0.125]);
        // Outside it, the straight segments.
        close(&p.interpolate(0.5, bez), &[0.5, 0.0]);
        close(&p.interpolate(3.0, bez), &[2.0, 1.0]);
        // Resampled: the ends stay, the middle sample (length 1.5, u = 1/3) is on the
        // rounding: 4/9 (1,0) + 4/9 (2,0) + 1/9 (2,0.5).
        let r = p.resample(3, bez);
        close(&r, &[0.0, 0.0, 14.0 / 9.0, 1.0 / 18.0, 2.0, 1.0]);

        // A closed square of side 1: the start corner is rounded too, unless forced open.
        let sq = [0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0, 0.0, 0.0];
        let (l, total) = lengths(&sq, 2).unwrap();
        assert_eq!(total, 4.0);
        let p = PathRef::new(&sq, 2, &l, &[]).unwrap();
        // Length 0 is the middle of the start corner's rounding: 0.25 (0,0.5) + 0.5 (0,0)
        // + 0.25 (0.5,0).
        close(&p.interpolate(0.0, bez), &[0.125, 0.125]);
        close(&p.interpolate(4.0, bez), &[0.125, 0.125]);
        let open = Method {
            bezier: Some(1.0),
            force_open: true,
        };
        close(&p.interpolate(0.0, open), &[0.0, 0.0]);
    }
}
