//! Matrix, pose and Euler-angle helpers: `sim.buildMatrix`, `sim.buildPose`,
//! `sim.multiplyMatrices`, `sim.interpolatePoses`, `sim.getRotationAxis`, ...
//!
//! Pure functions of their arguments; the world is not touched. The conventions are
//! CoppeliaSim's (see [`crate::math`]): a matrix is 12 numbers, row-major 3x4
//! `[Xx Yx Zx Px; Xy Yy Zy Py; Xz Yz Zz Pz]`; a pose is `[x, y, z, qx, qy, qz, qw]`;
//! Euler angles are `alpha, beta, gamma` with `R = Rx(alpha) Ry(beta) Rz(gamma)`; metres
//! and radians.
//!
//! Where CoppeliaSim works on the 12 numbers as given (products, transforming vectors,
//! rotating about an axis), so does gantry, so a scaled matrix stays scaled. Functions
//! that need a rotation (Euler angles, quaternions, interpolation, rotation axes) take
//! the quaternion of the 3x3 block with the closed-form (trace) method, as CoppeliaSim
//! does, rather than an iterative orthonormalisation that a degenerate matrix could keep
//! busy. Malformed arguments (wrong length, non-numbers, NaN or infinities, a zero
//! quaternion or axis) are errors that name the argument.

use crate::error::SimError;
use nalgebra::{Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::math::{self, Pose, Quat, Vec3};
use crate::world::World;

/// The functions this file implements, sorted by name.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "alphaBetaGammaToYawPitchRoll",
        call: ApiFn::World(alpha_beta_gamma_to_yaw_pitch_roll),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "buildIdentityMatrix",
        call: ApiFn::World(build_identity_matrix),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "buildMatrix",
        call: ApiFn::World(build_matrix),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "buildMatrixQ",
        call: ApiFn::World(build_matrix_q),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "buildPose",
        call: ApiFn::World(build_pose),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getEulerAnglesFromMatrix",
        call: ApiFn::World(get_euler_angles_from_matrix),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getMatrixInverse",
        call: ApiFn::World(get_matrix_inverse),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getPoseInverse",
        call: ApiFn::World(get_pose_inverse),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getQuaternionFromMatrix",
        call: ApiFn::World(get_quaternion_from_matrix),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getRotationAxis",
        call: ApiFn::World(get_rotation_axis),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "interpolateMatrices",
        call: ApiFn::World(interpolate_matrices),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "interpolatePoses",
        call: ApiFn::World(interpolate_poses),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "matrixToPose",
        call: ApiFn::World(matrix_to_pose),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "multiplyMatrices",
        call: ApiFn::World(multiply_matrices),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "multiplyPoses",
        call: ApiFn::World(multiply_poses),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "multiplyVector",
        call: ApiFn::World(multiply_vector),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "poseToMatrix",
        call: ApiFn::World(pose_to_matrix),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "rotateAroundAxis",
        call: ApiFn::World(rotate_around_axis),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "yawPitchRollToAlphaBetaGamma",
        call: ApiFn::World(yaw_pitch_roll_to_alpha_beta_gamma),
        cost: Cost::Quick,
    },
];

/// CoppeliaSim's gimbal-lock threshold for yaw-pitch-roll: `|sin(pitch)|` at or above
/// this puts the whole rotation about the aligned axes into roll.
const YPR_GIMBAL_LOCK: f64 = 0.999_999;

/// A 3x4 matrix as the API's 12 numbers.
type Matrix12 = [f64; 12];

// ---------------------------------------------------------------------------------------
// Argument parsing

/// Argument `i` as a table of finite numbers of any length; `what` names it in errors.
fn numbers(a: &Args<'_>, i: usize, what: &str) -> Result<Vec<f64>, SimError> {
    let Value::Array(items) = a.get(i) else {
        return Err(SimError::bad_argument(format!(
            "argument {} ({what}): expected a table of numbers, got {}",
            i + 1,
            describe(a.get(i))
        )));
    };
    items
        .iter()
        .enumerate()
        .map(|(k, v)| match v.as_f64() {
            Some(f) if f.is_finite() => Ok(f),
            Some(f) => Err(SimError::bad_argument(format!(
                "argument {} ({what}): element {} must be a finite number, got {f}",
                i + 1,
                k + 1
            ))),
            None => Err(SimError::bad_argument(format!(
                "argument {} ({what}): element {} must be a number, got {}",
                i + 1,
                k + 1,
                v.type_name()
            ))),
        })
        .collect()
}

/// Argument `i` as exactly `N` finite numbers.
fn exact<const N: usize>(a: &Args<'_>, i: usize, what: &str) -> Result<[f64; N], SimError> {
    let v = numbers(a, i, what)?;
    v.try_into().map_err(|v: Vec<f64>| {
        SimError::bad_argument(format!(
            "argument {} ({what}): expected {N} numbers, got {}",
            i + 1,
            v.len()
        ))
    })
}

/// A value's type for an error message ("nil" reads as "no value" for a missing argument).
fn describe(v: &Value) -> &'static str {
    match v {
        Value::Nil => "nil",
        other => other.type_name(),
    }
}

/// A required finite scalar, named in errors.
fn scalar(a: &Args<'_>, i: usize, what: &str) -> Result<f64, SimError> {
    match a.get(i).as_f64() {
        Some(f) if f.is_finite() => Ok(f),
        Some(f) => Err(SimError::bad_argument(format!(
            "argument {} ({what}): expected a finite number, got {f}",
            i + 1
        ))),
        None => Err(SimError::bad_argument(format!(
            "argument {} ({what}): expected a number, got {}",
            i + 1,
            describe(a.get(i))
        ))),
    }
}

/// A non-zero 3-vector, normalised.
fn unit_axis(a: &Args<'_>, i: usize, what: &str) -> Result<Vec3, SimError> {
    let v = Vec3::from(exact::<3>(a, i, what)?);
    let n = v.norm();
    if n < 1e-12 {
        return Err(SimError::bad_argument(format!(
            "argument {} ({what}): the axis must not be zero",
            i + 1
        )));
    }
    Ok(v / n)
}

/// A pose from its 7 numbers; the quaternion is normalised (as CoppeliaSim does), and a
/// zero one is refused.
fn pose_from_array(v: &[f64; 7], arg: usize, what: &str) -> Result<Pose, SimError> {
    let q = math::quat_from_array([v[3], v[4], v[5], v[6]]).ok_or_else(|| {
        SimError::bad_argument(format!(
            "argument {} ({what}): the quaternion (elements 4 to 7) must not be zero",
            arg + 1
        ))
    })?;
    Ok(Pose::from_parts(Translation3::new(v[0], v[1], v[2]), q))
}

/// A pose argument.
fn pose_arg(a: &Args<'_>, i: usize, what: &str) -> Result<Pose, SimError> {
    pose_from_array(&exact::<7>(a, i, what)?, i, what)
}

/// The rotation of a matrix's 3x3 block, by the closed-form trace method: bounded work
/// whatever the numbers (an iterative orthonormalisation need not end on a reflection).
/// A rotation block gives its quaternion; any other block some rotation, as in
/// CoppeliaSim; only a block whose quaternion cannot be normalised is an error.
fn matrix_rotation(m: &Matrix12, arg: usize, what: &str) -> Result<Quat, SimError> {
    let block = Matrix3::new(m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]);
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(block)).into_inner();
    math::quat_from_array([q.i, q.j, q.k, q.w]).ok_or_else(|| {
        SimError::bad_argument(format!(
            "argument {} ({what}): the 3x3 block is not a rotation",
            arg + 1
        ))
    })
}

/// A matrix as a pose (its rotation taken as in [`matrix_rotation`]).
fn matrix_pose(m: &Matrix12, arg: usize, what: &str) -> Result<Pose, SimError> {
    Ok(Pose::from_parts(
        Translation3::new(m[3], m[7], m[11]),
        matrix_rotation(m, arg, what)?,
    ))
}

/// A transform argument given either way: 12 numbers are a matrix, 7 a pose.
enum Transform {
    /// The 12 numbers as given.
    Matrix(Matrix12),
    /// A pose with a unit quaternion.
    Pose(Pose),
}

impl Transform {
    /// Reads argument `i`, deciding by its length.
    fn arg(a: &Args<'_>, i: usize, what: &str) -> Result<Self, SimError> {
        let v = numbers(a, i, what)?;
        match v.len() {
            12 => {
                let mut m = [0.0; 12];
                m.copy_from_slice(&v);
                Ok(Transform::Matrix(m))
            }
            7 => {
                let mut p = [0.0; 7];
                p.copy_from_slice(&v);
                Ok(Transform::Pose(pose_from_array(&p, i, what)?))
            }
            n => Err(SimError::bad_argument(format!(
                "argument {} ({what}): expected a matrix (12 numbers) or a pose (7 numbers), got {n} numbers",
                i + 1
            ))),
        }
    }

    /// The transform as a pose (a matrix's rotation re-derived from its 3x3 block).
    fn pose(&self, arg: usize, what: &str) -> Result<Pose, SimError> {
        match self {
            Transform::Matrix(m) => matrix_pose(m, arg, what),
            Transform::Pose(p) => Ok(*p),
        }
    }
}

/// A pose as the API's 7 numbers.
fn pose_to_array(p: &Pose) -> [f64; 7] {
    let t = p.translation.vector;
    let q = math::quat_to_array(&p.rotation);
    [t.x, t.y, t.z, q[0], q[1], q[2], q[3]]
}

// ---------------------------------------------------------------------------------------
// 3x4 matrix arithmetic on the numbers as given (the implicit last row is 0 0 0 1).

/// `a * b`.
fn mat_mul(a: &Matrix12, b: &Matrix12) -> Matrix12 {
    let mut r = [0.0; 12];
    for i in 0..3 {
        for j in 0..4 {
            let mut s = (0..3).map(|k| a[4 * i + k] * b[4 * k + j]).sum::<f64>();
            if j == 3 {
                s += a[4 * i + 3];
            }
            r[4 * i + j] = s;
        }
    }
    r
}

/// `m * [p; 1]`.
fn mat_apply(m: &Matrix12, p: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| m[4 * i] * p[0] + m[4 * i + 1] * p[1] + m[4 * i + 2] * p[2] + m[4 * i + 3])
}

/// The rigid inverse `[R^T, -R^T p]`, as CoppeliaSim computes it: exact for a rotation
/// block, and never singular.
fn mat_rigid_inverse(m: &Matrix12) -> Matrix12 {
    let mut r = [0.0; 12];
    for i in 0..3 {
        for j in 0..3 {
            r[4 * i + j] = m[4 * j + i];
        }
        r[4 * i + 3] = -(0..3).map(|k| m[4 * k + i] * m[4 * k + 3]).sum::<f64>();
    }
    r
}

/// The rotation about the (unit) `axis` through `pivot` by `angle`, as a matrix.
fn axis_rotation_matrix(axis: &Vec3, pivot: &Vec3, angle: f64) -> Matrix12 {
    let pose = Pose::from_parts(
        Translation3::from(*pivot),
        UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_unchecked(*axis), angle),
    ) * Translation3::from(-*pivot);
    math::pose_to_matrix12(&pose)
}

/// CoppeliaSim's interpolation between two rotations: along the shortest arc, with
/// `t` outside [0, 1] extrapolating along the same axis.
fn interpolate_rotation(a: &Quat, b: &Quat, t: f64) -> Quat {
    // `axis_angle` picks the shortest arc (angle in [0, pi]) and is None for no rotation.
    match (a.inverse() * b).axis_angle() {
        Some((axis, angle)) => a * UnitQuaternion::from_axis_angle(&axis, angle * t),
        None => *a,
    }
}

fn interpolate(a: &Pose, b: &Pose, t: f64) -> Pose {
    let p = a.translation.vector + (b.translation.vector - a.translation.vector) * t;
    Pose::from_parts(Translation3::from(p), interpolate_rotation(&a.rotation, &b.rotation, t))
}

// ---------------------------------------------------------------------------------------
// The functions

/// `sim.buildIdentityMatrix()` → the 12-number identity matrix.
fn build_identity_matrix(_: &mut World, _: &CallContext<'_>, _: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::floats(&math::pose_to_matrix12(&Pose::identity()))])
}

/// `sim.buildMatrix(position[3], eulerAngles[3])` → matrix[12].
fn build_matrix(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p = exact::<3>(a, 0, "position")?;
    let e = exact::<3>(a, 1, "eulerAngles")?;
    Ok(vec![Value::floats(&math::pose_to_matrix12(&math::pose_from_euler(
        p, e,
    )))])
}

/// `sim.buildMatrixQ(position[3], quaternion[4])` → matrix[12]; the quaternion
/// `[qx, qy, qz, qw]` is normalised.
fn build_matrix_q(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p = exact::<3>(a, 0, "position")?;
    let q = math::quat_from_array(exact::<4>(a, 1, "quaternion")?)
        .ok_or_else(|| SimError::bad_argument("argument 2 (quaternion): the quaternion must not be zero"))?;
    let pose = Pose::from_parts(Translation3::new(p[0], p[1], p[2]), q);
    Ok(vec![Value::floats(&math::pose_to_matrix12(&pose))])
}

/// `sim.buildPose(position[3], eulerAnglesOrAxis[3], mode=0, axis2[3]=nil)` → pose[7].
///
/// Mode 0: Euler angles. Modes 1-3: the frame's x, y or z axis is the given vector (the
/// frame is the smallest rotation that takes the reference axis onto it). Modes 4-9: two
/// axes, the first exact and the second made orthogonal to it: (x, y), (y, z), (z, x),
/// (x, z), (y, x), (z, y).
fn build_pose(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p = exact::<3>(a, 0, "position")?;
    let mode = a.opt_int(2, 0)?;
    let q = match mode {
        0 => math::quat_from_euler(exact::<3>(a, 1, "eulerAngles")?),
        1..=3 => {
            let k = (mode - 1) as usize;
            let v = unit_axis(a, 1, "axis")?;
            let reference = Vec3::ith(k, 1.0);
            UnitQuaternion::rotation_between(&reference, &v).unwrap_or_else(|| {
                // Antiparallel: a half turn about an axis perpendicular to the reference.
                let about = if k == 2 { Vector3::x_axis() } else { Vector3::z_axis() };
                UnitQuaternion::from_axis_angle(&about, std::f64::consts::PI)
            })
        }
        4..=9 => {
            // Which frame axes the two vectors are, in CoppeliaSim's mode order.
            let (i, j) = [(0, 1), (1, 2), (2, 0), (0, 2), (1, 0), (2, 1)][(mode - 4) as usize];
            let e1 = unit_axis(a, 1, "axis")?;
            let v2 = Vec3::from(exact::<3>(a, 3, "axis2")?);
            let e2 = v2 - e1 * e1.dot(&v2);
            let n2 = e2.norm();
            if n2 < 1e-9 * v2.norm().max(1.0) {
                return Err(SimError::bad_argument(
                    "argument 4 (axis2): must not be zero or parallel to the first axis",
                ));
            }
            let mut cols = [Vec3::zeros(); 3];
            cols[i] = e1;
            cols[j] = e2 / n2;
            let k = 3 - i - j;
            // Right-handed: X = Y x Z, Y = Z x X, Z = X x Y.
            cols[k] = cols[(k + 1) % 3].cross(&cols[(k + 2) % 3]);
            let r = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&cols));
            UnitQuaternion::from_rotation_matrix(&r)
        }
        other => {
            return Err(SimError::bad_argument(format!(
                "argument 3 (mode): expected 0 to 9, got {other}"
            )));
        }
    };
    let pose = Pose::from_parts(Translation3::new(p[0], p[1], p[2]), q);
    Ok(vec![Value::floats(&pose_to_array(&pose))])
}

/// `sim.getEulerAnglesFromMatrix(matrix[12])` → `[alpha, beta, gamma]`, rad.
fn get_euler_angles_from_matrix(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let m = exact::<12>(a, 0, "matrix")?;
    let q = matrix_rotation(&m, 0, "matrix")?;
    Ok(vec![Value::floats(&math::euler_from_quat(&q))])
}

/// `sim.getQuaternionFromMatrix(matrix[12])` → `[qx, qy, qz, qw]`.
fn get_quaternion_from_matrix(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let m = exact::<12>(a, 0, "matrix")?;
    let q = matrix_rotation(&m, 0, "matrix")?;
    Ok(vec![Value::floats(&math::quat_to_array(&q))])
}

/// `sim.getMatrixInverse(matrix[12])` → matrix[12]: the rigid inverse (transposed
/// rotation block), as CoppeliaSim.
fn get_matrix_inverse(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let m = exact::<12>(a, 0, "matrix")?;
    Ok(vec![Value::floats(&mat_rigid_inverse(&m))])
}

/// `sim.getPoseInverse(pose[7])` → pose[7].
fn get_pose_inverse(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p = pose_arg(a, 0, "pose")?;
    Ok(vec![Value::floats(&pose_to_array(&p.inverse()))])
}

/// `sim.matrixToPose(matrix[12])` → pose[7].
fn matrix_to_pose(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let m = exact::<12>(a, 0, "matrix")?;
    Ok(vec![Value::floats(&pose_to_array(&matrix_pose(&m, 0, "matrix")?))])
}

/// `sim.poseToMatrix(pose[7])` → matrix[12].
fn pose_to_matrix(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p = pose_arg(a, 0, "pose")?;
    Ok(vec![Value::floats(&math::pose_to_matrix12(&p))])
}

/// `sim.multiplyMatrices(matrixIn1[12], matrixIn2[12])` → `matrixIn1 * matrixIn2`.
fn multiply_matrices(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let m1 = exact::<12>(a, 0, "matrixIn1")?;
    let m2 = exact::<12>(a, 1, "matrixIn2")?;
    Ok(vec![Value::floats(&mat_mul(&m1, &m2))])
}

/// `sim.multiplyPoses(poseIn1[7], poseIn2[7])` → `poseIn1 * poseIn2`.
fn multiply_poses(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p1 = pose_arg(a, 0, "poseIn1")?;
    let p2 = pose_arg(a, 1, "poseIn2")?;
    Ok(vec![Value::floats(&pose_to_array(&(p1 * p2)))])
}

/// `sim.multiplyVector(matrix[12] | pose[7], inVectors[3*n])` → the n points transformed.
fn multiply_vector(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let t = Transform::arg(a, 0, "matrix or pose")?;
    let v = numbers(a, 1, "inVectors")?;
    if v.len() % 3 != 0 {
        return Err(SimError::bad_argument(format!(
            "argument 2 (inVectors): expected 3 numbers per vector, got {} numbers",
            v.len()
        )));
    }
    let mut out = Vec::with_capacity(v.len());
    for p in v.chunks_exact(3) {
        let p = [p[0], p[1], p[2]];
        match &t {
            Transform::Matrix(m) => out.extend(mat_apply(m, p)),
            Transform::Pose(pose) => out.extend(pose.transform_point(&p.into()).coords.iter().copied()),
        }
    }
    Ok(vec![Value::floats(&out)])
}

/// `sim.interpolateMatrices(matrixIn1[12], matrixIn2[12], interpolFactor)` → matrix[12]:
/// position linear, rotation along the shortest arc; factors outside [0, 1] extrapolate.
fn interpolate_matrices(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let m1 = matrix_pose(&exact::<12>(a, 0, "matrixIn1")?, 0, "matrixIn1")?;
    let m2 = matrix_pose(&exact::<12>(a, 1, "matrixIn2")?, 1, "matrixIn2")?;
    let t = scalar(a, 2, "interpolFactor")?;
    Ok(vec![Value::floats(&math::pose_to_matrix12(&interpolate(&m1, &m2, t)))])
}

/// `sim.interpolatePoses(poseIn1[7], poseIn2[7], interpolFactor)` → pose[7].
fn interpolate_poses(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p1 = pose_arg(a, 0, "poseIn1")?;
    let p2 = pose_arg(a, 1, "poseIn2")?;
    let t = scalar(a, 2, "interpolFactor")?;
    Ok(vec![Value::floats(&pose_to_array(&interpolate(&p1, &p2, t)))])
}

/// `sim.getRotationAxis(matrixStart | poseStart, matrixGoal | poseGoal)` → `axis[3], angle`:
/// the unit axis, in the absolute frame, and the angle in [0, pi] of the shortest
/// rotation that takes the start orientation onto the goal's (positions are ignored).
/// With no rotation the axis is `[0, 0, 1]` and the angle 0.
fn get_rotation_axis(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let start = Transform::arg(a, 0, "start")?.pose(0, "start")?.rotation;
    let goal = Transform::arg(a, 1, "goal")?.pose(1, "goal")?.rotation;
    // The relative rotation in the start frame, its axis then expressed in the absolute frame.
    let (axis, angle) = match (start.inverse() * goal).axis_angle() {
        Some((axis, angle)) => (start * axis.into_inner(), angle),
        None => (Vector3::z(), 0.0),
    };
    Ok(vec![Value::floats(axis.as_slice()), Value::Float(angle)])
}

/// `sim.rotateAroundAxis(matrixIn[12] | poseIn[7], axis[3], axisPos[3], angle)` → the
/// transform, in the same form, rotated by `angle` (rad, right-handed) about the
/// absolute-frame axis through `axisPos`.
fn rotate_around_axis(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let t = Transform::arg(a, 0, "matrix or pose")?;
    let axis = unit_axis(a, 1, "axis")?;
    let pivot = Vec3::from(exact::<3>(a, 2, "axisPos")?);
    let angle = scalar(a, 3, "angle")?;
    let r = axis_rotation_matrix(&axis, &pivot, angle);
    Ok(vec![match t {
        Transform::Matrix(m) => Value::floats(&mat_mul(&r, &m)),
        Transform::Pose(p) => {
            let rot = UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_unchecked(axis), angle);
            let pos = rot * (p.translation.vector - pivot) + pivot;
            Value::floats(&pose_to_array(&Pose::from_parts(
                Translation3::from(pos),
                rot * p.rotation,
            )))
        }
    }])
}

/// `sim.yawPitchRollToAlphaBetaGamma(yaw, pitch, roll)` → `alpha, beta, gamma`, with
/// CoppeliaSim's yaw-pitch-roll convention `R = Rz(yaw) Ry(pitch) Rx(roll)`.
fn yaw_pitch_roll_to_alpha_beta_gamma(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let yaw = scalar(a, 0, "yawAngle")?;
    let pitch = scalar(a, 1, "pitchAngle")?;
    let roll = scalar(a, 2, "rollAngle")?;
    let q = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw)
        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), pitch)
        * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), roll);
    Ok(math::euler_from_quat(&q).into_iter().map(Value::Float).collect())
}

/// `sim.alphaBetaGammaToYawPitchRoll(alpha, beta, gamma)` → `yaw, pitch, roll` (see
/// [`yaw_pitch_roll_to_alpha_beta_gamma`]), with pitch in [-pi/2, pi/2] and, in gimbal
/// lock, yaw 0.
fn alpha_beta_gamma_to_yaw_pitch_roll(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let e = [
        scalar(a, 0, "alphaAngle")?,
        scalar(a, 1, "betaAngle")?,
        scalar(a, 2, "gammaAngle")?,
    ];
    let r = math::quat_from_euler(e).to_rotation_matrix();
    let m = r.matrix();
    let s = m[(2, 0)].clamp(-1.0, 1.0);
    let pitch = (-s).asin();
    let (yaw, roll) = if s.abs() < YPR_GIMBAL_LOCK {
        (m[(1, 0)].atan2(m[(0, 0)]), m[(2, 1)].atan2(m[(2, 2)]))
    } else {
        (0.0, (-m[(1, 2)]).atan2(m[(1, 1)]))
    };
    Ok(vec![Value::Float(yaw), Value::Float(pitch), Value::Float(roll)])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rigid_inverse_undoes_the_transform() {
        let m = math::pose_to_matrix12(&math::pose_from_euler([1.0, -2.0, 0.5], [0.3, -0.2, 1.1]));
        let id = mat_mul(&mat_rigid_inverse(&m), &m);
        let expected = math::pose_to_matrix12(&Pose::identity());
        for (x, y) in id.iter().zip(expected) {
            assert!((x - y).abs() < 1e-12, "{id:?}");
        }
    }

    #[test]
    fn rotation_of_a_degenerate_block_is_bounded() {
        // Zero and NaN-producing blocks must give an answer or an error, not hang.
        for m in [[0.0; 12], [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0]] {
            let _ = matrix_rotation(&m, 0, "matrix");
        }
    }
}
