//! The math and packing helpers of the `sim` API through the registry, as scripts and
//! remote clients call them: matrices, poses and Euler angles against rotations built
//! independently with nalgebra (axis-angle), round trips, CoppeliaSim's documented
//! conventions, and the packing functions on good and malformed data.

use crate::util;

use std::f64::consts::{FRAC_PI_2, PI};

use gantry_sim_core::{Sim, Value};
use gantry_test_support::{assert_close, floats, num};
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use util::{err, ok};

/// An empty scene: these functions never touch the world.
fn world() -> Sim {
    util::text_scene("../../assets/scenes/empty.toml", "[simulation]\ndt = 0.05\n")
}

fn v(x: &[f64]) -> Value {
    Value::floats(x)
}

fn bytes(v: &Value) -> Vec<u8> {
    match v {
        Value::Bytes(b) => b.clone(),
        other => panic!("not bytes: {other:?}"),
    }
}

/// CoppeliaSim's `R = Rx(a) Ry(b) Rz(g)`, built from axis-angle rotations.
fn rot_abg([a, b, g]: [f64; 3]) -> Matrix3<f64> {
    let r = |axis, angle| Rotation3::from_axis_angle(&axis, angle).into_inner();
    r(Vector3::x_axis(), a) * r(Vector3::y_axis(), b) * r(Vector3::z_axis(), g)
}

/// The 12 numbers of `[r | p]`, row-major.
fn matrix12(r: &Matrix3<f64>, p: [f64; 3]) -> Vec<f64> {
    let mut m = Vec::with_capacity(12);
    for i in 0..3 {
        m.extend([r[(i, 0)], r[(i, 1)], r[(i, 2)], p[i]]);
    }
    m
}

/// The rotation block of 12 numbers.
fn block(m: &[f64]) -> Matrix3<f64> {
    Matrix3::new(m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10])
}

/// Whether two quaternions `[x, y, z, w]` are the same rotation (q and -q are).
fn same_rotation(a: &[f64], b: &[f64]) -> bool {
    let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    (dot.abs() - 1.0).abs() < 1e-12
}

/// Euler angles spread over the whole non-singular range.
fn euler_samples() -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for &a in &[-3.0, -1.2, 0.0, 0.4, 2.9] {
        for &b in &[-1.5, -0.7, 0.0, 0.3, 1.4] {
            for &g in &[-2.5, -0.1, 0.0, 1.0, 3.1] {
                out.push([a, b, g]);
            }
        }
    }
    out
}

#[test]
fn build_matrix_follows_coppeliasim_conventions() {
    let mut w = world();
    // The documented example: a quarter turn about z maps x onto y.
    let m = floats(&ok(&mut w, "buildMatrix", &[v(&[0.0, 0.0, 0.0]), v(&[0.0, 0.0, FRAC_PI_2])])[0]);
    let x = floats(&ok(&mut w, "multiplyVector", &[v(&m), v(&[1.0, 0.0, 0.0])])[0]);
    assert_close(&x, &[0.0, 1.0, 0.0], 1e-15);
    // Translation in elements 4, 8 and 12; rotation block against axis-angle products.
    for e in euler_samples() {
        let p = [0.5, -1.0, 2.0];
        let m = floats(&ok(&mut w, "buildMatrix", &[v(&p), v(&e)])[0]);
        assert_close(&m, &matrix12(&rot_abg(e), p), 1e-14);
    }
    let id = floats(&ok(&mut w, "buildIdentityMatrix", &[])[0]);
    assert_close(&id, &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0], 0.0);
}

#[test]
fn euler_angles_and_quaternions_round_trip() {
    let mut w = world();
    for e in euler_samples() {
        let m = floats(&ok(&mut w, "buildMatrix", &[v(&[1.0, 2.0, 3.0]), v(&e)])[0]);
        let back = floats(&ok(&mut w, "getEulerAnglesFromMatrix", &[v(&m)])[0]);
        assert_close(&back, &e, 1e-12);
        // The quaternion of the matrix is nalgebra's of the same rotation, and builds it back.
        let q = floats(&ok(&mut w, "getQuaternionFromMatrix", &[v(&m)])[0]);
        let r = UnitQuaternion::from_matrix(&rot_abg(e));
        assert!(same_rotation(&q, &[r.i, r.j, r.k, r.w]), "{q:?} vs {r:?}");
        let mq = floats(&ok(&mut w, "buildMatrixQ", &[v(&[1.0, 2.0, 3.0]), v(&q)])[0]);
        assert_close(&mq, &m, 1e-14);
        // Pose forms agree with matrix forms.
        let pose = floats(&ok(&mut w, "buildPose", &[v(&[1.0, 2.0, 3.0]), v(&e)])[0]);
        assert_close(&floats(&ok(&mut w, "poseToMatrix", &[v(&pose)])[0]), &m, 1e-14);
        let pose2 = floats(&ok(&mut w, "matrixToPose", &[v(&m)])[0]);
        assert_close(&pose2[..3], &[1.0, 2.0, 3.0], 0.0);
        assert!(same_rotation(&pose2[3..], &pose[3..]));
    }
    // buildMatrixQ normalises its quaternion, as CoppeliaSim does.
    let m = floats(&ok(&mut w, "buildMatrixQ", &[v(&[0.0; 3]), v(&[0.0, 0.0, 2.0, 2.0])])[0]);
    assert_close(&m, &matrix12(&rot_abg([0.0, 0.0, FRAC_PI_2]), [0.0; 3]), 1e-15);
}

#[test]
fn gimbal_lock_keeps_the_rotation() {
    let mut w = world();
    let e = [0.3, FRAC_PI_2, -0.4];
    let m = floats(&ok(&mut w, "buildMatrix", &[v(&[0.0; 3]), v(&e)])[0]);
    let back = floats(&ok(&mut w, "getEulerAnglesFromMatrix", &[v(&m)])[0]);
    assert_eq!(back[0], 0.0, "CoppeliaSim puts the whole rotation in gamma: {back:?}");
    assert_close(&matrix12(&rot_abg([back[0], back[1], back[2]]), [0.0; 3]), &m, 1e-6);
}

#[test]
fn inverses_and_products_agree() {
    let mut w = world();
    let m1 = floats(&ok(&mut w, "buildMatrix", &[v(&[1.0, -2.0, 0.5]), v(&[0.3, -0.2, 1.1])])[0]);
    let m2 = floats(&ok(&mut w, "buildMatrix", &[v(&[-0.4, 0.7, 3.0]), v(&[-1.0, 0.9, 2.5])])[0]);
    let id = floats(&ok(&mut w, "buildIdentityMatrix", &[])[0]);
    let inv = floats(&ok(&mut w, "getMatrixInverse", &[v(&m1)])[0]);
    assert_close(
        &floats(&ok(&mut w, "multiplyMatrices", &[v(&m1), v(&inv)])[0]),
        &id,
        1e-14,
    );
    assert_close(
        &floats(&ok(&mut w, "multiplyMatrices", &[v(&inv), v(&m1)])[0]),
        &id,
        1e-14,
    );
    // The product is rotation then translation: [R1 R2 | R1 p2 + p1].
    let prod = floats(&ok(&mut w, "multiplyMatrices", &[v(&m1), v(&m2)])[0]);
    let r = block(&m1) * block(&m2);
    let p = block(&m1) * Vector3::new(m2[3], m2[7], m2[11]) + Vector3::new(m1[3], m1[7], m1[11]);
    assert_close(&prod, &matrix12(&r, [p.x, p.y, p.z]), 1e-14);
    // Poses give the same transforms.
    let p1 = floats(&ok(&mut w, "matrixToPose", &[v(&m1)])[0]);
    let p2 = floats(&ok(&mut w, "matrixToPose", &[v(&m2)])[0]);
    let pp = floats(&ok(&mut w, "multiplyPoses", &[v(&p1), v(&p2)])[0]);
    assert_close(&floats(&ok(&mut w, "poseToMatrix", &[v(&pp)])[0]), &prod, 1e-14);
    let pinv = floats(&ok(&mut w, "getPoseInverse", &[v(&p1)])[0]);
    assert_close(&floats(&ok(&mut w, "poseToMatrix", &[v(&pinv)])[0]), &inv, 1e-14);
}

#[test]
fn multiply_vector_takes_several_points_and_either_form() {
    let mut w = world();
    let m = floats(&ok(&mut w, "buildMatrix", &[v(&[1.0, 2.0, 3.0]), v(&[0.0, 0.0, FRAC_PI_2])])[0]);
    let pose = floats(&ok(&mut w, "matrixToPose", &[v(&m)])[0]);
    let pts = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 2.0, 3.0, 4.0];
    let expected = [1.0, 3.0, 3.0, 0.0, 2.0, 3.0, -2.0, 4.0, 7.0];
    assert_close(
        &floats(&ok(&mut w, "multiplyVector", &[v(&m), v(&pts)])[0]),
        &expected,
        1e-14,
    );
    assert_close(
        &floats(&ok(&mut w, "multiplyVector", &[v(&pose), v(&pts)])[0]),
        &expected,
        1e-14,
    );
    assert!(floats(&ok(&mut w, "multiplyVector", &[v(&m), v(&[])])[0]).is_empty());
    let e = err(&mut w, "multiplyVector", &[v(&m), v(&[1.0, 2.0])]);
    assert!(
        e.contains("argument 2 (inVectors)") && e.contains("3 numbers per vector"),
        "{e}"
    );
    let e = err(&mut w, "multiplyVector", &[v(&[0.0; 8]), v(&pts)]);
    assert!(
        e.contains("argument 1") && e.contains("12 numbers") && e.contains("7 numbers"),
        "{e}"
    );
    assert!(e.ends_with("(in function 'sim.multiplyVector')"), "{e}");
}

#[test]
fn interpolation_takes_the_shortest_arc() {
    let mut w = world();
    let p1 = floats(&ok(&mut w, "buildPose", &[v(&[0.0, 0.0, 0.0]), v(&[0.0, 0.0, 0.0])])[0]);
    let p2 = floats(&ok(&mut w, "buildPose", &[v(&[2.0, -4.0, 6.0]), v(&[0.0, 0.0, 3.0])])[0]);
    for t in [0.0, 0.25, 0.5, 1.0, 1.5] {
        let p = floats(&ok(&mut w, "interpolatePoses", &[v(&p1), v(&p2), Value::Float(t)])[0]);
        assert_close(&p[..3], &[2.0 * t, -4.0 * t, 6.0 * t], 1e-14);
        let r = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 3.0 * t);
        assert!(same_rotation(&p[3..], &[r.i, r.j, r.k, r.w]), "t={t}: {p:?}");
    }
    // The goal's quaternion negated is the same rotation: still the shortest arc.
    let neg: Vec<f64> = p2[..3].iter().copied().chain(p2[3..].iter().map(|x| -x)).collect();
    let p = floats(&ok(&mut w, "interpolatePoses", &[v(&p1), v(&neg), Value::Float(0.5)])[0]);
    let r = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 1.5);
    assert!(same_rotation(&p[3..], &[r.i, r.j, r.k, r.w]), "{p:?}");
    // Matrices interpolate the same way.
    let m1 = floats(&ok(&mut w, "poseToMatrix", &[v(&p1)])[0]);
    let m2 = floats(&ok(&mut w, "poseToMatrix", &[v(&p2)])[0]);
    let m = floats(&ok(&mut w, "interpolateMatrices", &[v(&m1), v(&m2), Value::Float(0.25)])[0]);
    assert_close(&m, &matrix12(&rot_abg([0.0, 0.0, 0.75]), [0.5, -1.0, 1.5]), 1e-14);
    let e = err(&mut w, "interpolatePoses", &[v(&p1), v(&p2), Value::Float(f64::NAN)]);
    assert!(e.contains("argument 3 (interpolFactor)"), "{e}");
}

#[test]
fn rotation_axis_is_in_the_absolute_frame() {
    let mut w = world();
    let start = rot_abg([0.4, -0.3, 1.2]);
    let axis = Vector3::new(1.0, -2.0, 0.5).normalize();
    for angle in [0.3, 2.0, PI - 1e-3] {
        let goal = Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle).into_inner() * start;
        let ms = matrix12(&start, [1.0, 2.0, 3.0]);
        let mg = matrix12(&goal, [-5.0, 0.0, 9.0]);
        let r = ok(&mut w, "getRotationAxis", &[v(&ms), v(&mg)]);
        assert_close(&floats(&r[0]), axis.as_slice(), 1e-9);
        assert!((num(&r[1]) - angle).abs() < 1e-9, "{r:?}");
        // Poses give the same; rotating the start about that axis reaches the goal.
        let ps = floats(&ok(&mut w, "matrixToPose", &[v(&ms)])[0]);
        let pg = floats(&ok(&mut w, "matrixToPose", &[v(&mg)])[0]);
        let r2 = ok(&mut w, "getRotationAxis", &[v(&ps), v(&pg)]);
        assert_close(&floats(&r2[0]), axis.as_slice(), 1e-9);
        let rotated = floats(
            &ok(
                &mut w,
                "rotateAroundAxis",
                &[v(&ms), r[0].clone(), v(&[0.0; 3]), r[1].clone()],
            )[0],
        );
        assert!((block(&rotated) - goal).norm() < 1e-9, "angle {angle}");
    }
    // More than half a turn: the shorter way round, about the opposite axis.
    let goal = Rotation3::from_axis_angle(&Vector3::z_axis(), 1.5 * PI).into_inner();
    let r = ok(
        &mut w,
        "getRotationAxis",
        &[
            v(&matrix12(&Matrix3::identity(), [0.0; 3])),
            v(&matrix12(&goal, [0.0; 3])),
        ],
    );
    assert_close(&floats(&r[0]), &[0.0, 0.0, -1.0], 1e-12);
    assert!((num(&r[1]) - FRAC_PI_2).abs() < 1e-12);
    // No rotation.
    let id = floats(&ok(&mut w, "buildIdentityMatrix", &[])[0]);
    let r = ok(&mut w, "getRotationAxis", &[v(&id), v(&id)]);
    assert_eq!(num(&r[1]), 0.0);
}

#[test]
fn rotate_around_an_offset_axis() {
    let mut w = world();
    // A frame at the origin, turned a quarter about z through (1, 0, 0): it ends at
    // (1, -1, 0), turned by the same quarter.
    let pose = floats(&ok(&mut w, "buildPose", &[v(&[0.0; 3]), v(&[0.0; 3])])[0]);
    let args = |t: &[f64]| [v(t), v(&[0.0, 0.0, 2.0]), v(&[1.0, 0.0, 0.0]), Value::Float(FRAC_PI_2)];
    let p = floats(&ok(&mut w, "rotateAroundAxis", &args(&pose))[0]);
    assert_eq!(p.len(), 7);
    assert_close(&p[..3], &[1.0, -1.0, 0.0], 1e-15);
    let r = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), FRAC_PI_2);
    assert!(same_rotation(&p[3..], &[r.i, r.j, r.k, r.w]));
    let m = floats(&ok(&mut w, "poseToMatrix", &[v(&pose)])[0]);
    let rm = floats(&ok(&mut w, "rotateAroundAxis", &args(&m))[0]);
    assert_eq!(rm.len(), 12);
    assert_close(&rm, &floats(&ok(&mut w, "poseToMatrix", &[v(&p)])[0]), 1e-15);
    let e = err(
        &mut w,
        "rotateAroundAxis",
        &[v(&m), v(&[0.0; 3]), v(&[0.0; 3]), Value::Float(1.0)],
    );
    assert!(e.contains("argument 2 (axis)") && e.contains("zero"), "{e}");
}

#[test]
fn yaw_pitch_roll_conversions() {
    let mut w = world();
    let r = |axis, angle| Rotation3::from_axis_angle(&axis, angle).into_inner();
    for (yaw, pitch, roll) in [(0.3, -0.4, 1.1), (-2.5, 1.2, -3.0), (0.0, 0.0, 0.0), (3.0, -1.5, 0.2)] {
        let abg = ok(
            &mut w,
            "yawPitchRollToAlphaBetaGamma",
            &[yaw.into(), pitch.into(), roll.into()],
        );
        assert_eq!(abg.len(), 3);
        let e = [num(&abg[0]), num(&abg[1]), num(&abg[2])];
        // Yaw about z, then pitch about y, then roll about x, in the fixed frame.
        let expected = r(Vector3::z_axis(), yaw) * r(Vector3::y_axis(), pitch) * r(Vector3::x_axis(), roll);
        assert!((rot_abg(e) - expected).norm() < 1e-12, "{e:?}");
        let ypr = ok(&mut w, "alphaBetaGammaToYawPitchRoll", &abg);
        assert_close(&[num(&ypr[0]), num(&ypr[1]), num(&ypr[2])], &[yaw, pitch, roll], 1e-9);
    }
    // Gimbal lock: yaw is 0 and roll carries the rest, the rotation unchanged.
    let abg = ok(
        &mut w,
        "yawPitchRollToAlphaBetaGamma",
        &[0.5.into(), FRAC_PI_2.into(), 0.2.into()],
    );
    let ypr = ok(&mut w, "alphaBetaGammaToYawPitchRoll", &abg);
    assert_eq!(num(&ypr[0]), 0.0);
    let back = ok(&mut w, "yawPitchRollToAlphaBetaGamma", &ypr);
    let e1 = [num(&abg[0]), num(&abg[1]), num(&abg[2])];
    let e2 = [num(&back[0]), num(&back[1]), num(&back[2])];
    assert!((rot_abg(e1) - rot_abg(e2)).norm() < 1e-6);
    let e = err(
        &mut w,
        "alphaBetaGammaToYawPitchRoll",
        &[1.0.into(), "x".into(), 0.0.into()],
    );
    assert!(e.contains("argument 2 (betaAngle)"), "{e}");
}

#[test]
fn build_pose_from_axes() {
    let mut w = world();
    let axes = |pose: &[f64], w: &mut Sim| block(&floats(&ok(w, "poseToMatrix", &[v(pose)])[0]));
    // Modes 1-3: that axis of the frame is the vector given.
    let dir = Vector3::new(1.0, 2.0, -2.0);
    for mode in 1..=3_i64 {
        let pose = floats(
            &ok(
                &mut w,
                "buildPose",
                &[v(&[1.0, 2.0, 3.0]), v(dir.as_slice()), mode.into()],
            )[0],
        );
        assert_close(&pose[..3], &[1.0, 2.0, 3.0], 0.0);
        let r = axes(&pose, &mut w);
        assert!(
            (r.column(mode as usize - 1) - dir.normalize()).norm() < 1e-12,
            "mode {mode}"
        );
        assert!((r.determinant() - 1.0).abs() < 1e-12);
    }
    // Antiparallel to the reference axis.
    let pose = floats(&ok(&mut w, "buildPose", &[v(&[0.0; 3]), v(&[0.0, 0.0, -3.0]), 3.into()])[0]);
    assert!((axes(&pose, &mut w).column(2) - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-12);
    // Modes 4-9: the first axis exact, the second made orthogonal, right-handed.
    let a1 = Vector3::new(0.0, 0.0, 2.0);
    let a2 = Vector3::new(1.0, 1.0, 5.0); // orthogonalised: (1, 1, 0) / sqrt 2
    let pairs = [(0, 1), (1, 2), (2, 0), (0, 2), (1, 0), (2, 1)];
    for (mode, (i, j)) in (4..=9_i64).zip(pairs) {
        let pose = floats(
            &ok(
                &mut w,
                "buildPose",
                &[v(&[0.0; 3]), v(a1.as_slice()), mode.into(), v(a2.as_slice())],
            )[0],
        );
        let r = axes(&pose, &mut w);
        assert!((r.column(i) - Vector3::z()).norm() < 1e-12, "mode {mode}: {r}");
        assert!(
            (r.column(j) - Vector3::new(1.0, 1.0, 0.0).normalize()).norm() < 1e-12,
            "mode {mode}: {r}"
        );
        assert!((r.determinant() - 1.0).abs() < 1e-12, "mode {mode}");
    }
    let e = err(
        &mut w,
        "buildPose",
        &[v(&[0.0; 3]), v(&[0.0, 0.0, 1.0]), 4.into(), v(&[0.0, 0.0, 3.0])],
    );
    assert!(e.contains("argument 4 (axis2)") && e.contains("parallel"), "{e}");
    let e = err(&mut w, "buildPose", &[v(&[0.0; 3]), v(&[0.0, 0.0, 1.0]), 4.into()]);
    assert!(e.contains("argument 4 (axis2)"), "{e}");
    let e = err(&mut w, "buildPose", &[v(&[0.0; 3]), v(&[0.0, 0.0, 1.0]), 10.into()]);
    assert!(e.contains("argument 3 (mode)"), "{e}");
    let e = err(&mut w, "buildPose", &[v(&[0.0; 3]), v(&[0.0; 3]), 1.into()]);
    assert!(e.contains("argument 2 (axis)") && e.contains("zero"), "{e}");
}

#[test]
fn bad_arguments_name_the_argument() {
    let mut w = world();
    let cases: &[(&str, Vec<Value>, &str)] = &[
        (
            "buildMatrix",
            vec![v(&[0.0, 0.0]), v(&[0.0; 3])],
            "argument 1 (position): expected 3 numbers, got 2",
        ),
        (
            "buildMatrix",
            vec![v(&[0.0; 3])],
            "argument 2 (eulerAngles): expected a table of numbers, got nil",
        ),
        (
            "buildMatrix",
            vec![v(&[0.0; 3]), v(&[0.0, f64::NAN, 0.0])],
            "element 2 must be a finite number, got NaN",
        ),
        (
            "buildMatrix",
            vec![v(&[0.0; 3]), Value::Array(vec![0.0.into(), "a".into(), 0.0.into()])],
            "argument 2 (eulerAngles): element 2 must be a number, got string",
        ),
        (
            "buildMatrixQ",
            vec![v(&[0.0; 3]), v(&[0.0; 4])],
            "argument 2 (quaternion): the quaternion must not be zero",
        ),
        (
            "poseToMatrix",
            vec![v(&[0.0; 7])],
            "argument 1 (pose): the quaternion (elements 4 to 7) must not be zero",
        ),
        (
            "getMatrixInverse",
            vec![v(&[0.0; 11])],
            "argument 1 (matrix): expected 12 numbers, got 11",
        ),
        (
            "multiplyPoses",
            vec![v(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]), v(&[0.0; 12])],
            "argument 2 (poseIn2)",
        ),
        (
            "multiplyMatrices",
            vec![v(&[0.0; 12]), v(&[f64::INFINITY; 12])],
            "argument 2 (matrixIn2)",
        ),
        (
            "getEulerAnglesFromMatrix",
            vec!["m".into()],
            "argument 1 (matrix): expected a table of numbers, got string",
        ),
        (
            "yawPitchRollToAlphaBetaGamma",
            vec![0.0.into(), 0.0.into()],
            "argument 3 (rollAngle)",
        ),
    ];
    for (name, args, expected) in cases {
        let e = err(&mut w, name, args);
        assert!(e.contains(expected), "{name}: {e}");
        assert!(e.ends_with(&format!("(in function 'sim.{name}')")), "{e}");
    }
}

// ---------------------------------------------------------------------------------------
// Packing

#[test]
fn numbers_pack_little_endian_and_round_trip() {
    let mut w = world();
    let ints = Value::Array(vec![1.into(), (-2).into(), 300.into()]);
    assert_eq!(
        bytes(&ok(&mut w, "packInt32Table", &[ints])[0]),
        [1, 0, 0, 0, 254, 255, 255, 255, 44, 1, 0, 0]
    );
    assert_eq!(
        bytes(&ok(&mut w, "packUInt16Table", &[Value::Array(vec![1.into(), 65535.into()])])[0]),
        [1, 0, 255, 255]
    );
    assert_eq!(
        bytes(&ok(&mut w, "packFloatTable", &[v(&[1.0])])[0]),
        1.0f32.to_le_bytes()
    );
    assert_eq!(
        bytes(&ok(&mut w, "packDoubleTable", &[v(&[-2.5])])[0]),
        (-2.5f64).to_le_bytes()
    );
    let cases: &[(&str, &str, Vec<Value>)] = &[
        (
            "packInt32Table",
            "unpackInt32Table",
            vec![
                0.into(),
                i64::from(i32::MIN).into(),
                i64::from(i32::MAX).into(),
                (-7).into(),
            ],
        ),
        (
            "packUInt32Table",
            "unpackUInt32Table",
            vec![0.into(), i64::from(u32::MAX).into(), 12345.into()],
        ),
        (
            "packUInt16Table",
            "unpackUInt16Table",
            vec![0.into(), 65535.into(), 7.into()],
        ),
        (
            "packUInt8Table",
            "unpackUInt8Table",
            vec![0.into(), 255.into(), 128.into()],
        ),
        (
            "packDoubleTable",
            "unpackDoubleTable",
            vec![0.1.into(), (-1e300).into(), f64::INFINITY.into(), 3.into()],
        ),
        // Values exact in single precision survive; integers come back as floats.
        (
            "packFloatTable",
            "unpackFloatTable",
            vec![0.5.into(), (-1024.25).into(), 3.0.into()],
        ),
    ];
    for (pack, unpack, values) in cases {
        let data = ok(&mut w, pack, &[Value::Array(values.clone())]).remove(0);
        let back = ok(&mut w, unpack, &[data]).remove(0);
        let Value::Array(back) = back else {
            panic!("{unpack}: not an array")
        };
        assert_eq!(back.len(), values.len(), "{unpack}");
        for (a, b) in back.iter().zip(values) {
            assert_eq!(a.as_f64(), b.as_f64(), "{unpack}");
        }
    }
    // Single precision rounds.
    let data = ok(&mut w, "packFloatTable", &[v(&[0.1])]).remove(0);
    assert_eq!(floats(&ok(&mut w, "unpackFloatTable", &[data])[0]), [f64::from(0.1f32)]);
    let e = err(&mut w, "packFloatTable", &[Value::Array(vec![1.0.into(), "x".into()])]);
    assert!(e.contains("element 2 must be a number"), "{e}");
}

#[test]
fn start_index_count_and_byte_offset() {
    let mut w = world();
    let t = v(&[1.0, 2.0, 3.0, 4.0, 5.0]);
    let packed = |w: &mut Sim, s: i64, c: i64| {
        let data = ok(w, "packDoubleTable", &[t.clone(), s.into(), c.into()]).remove(0);
        floats(&ok(w, "unpackDoubleTable", &[data])[0])
    };
    assert_eq!(packed(&mut w, 0, 0), [1.0, 2.0, 3.0, 4.0, 5.0]);
    assert_eq!(packed(&mut w, 1, 2), [2.0, 3.0]);
    assert_eq!(packed(&mut w, 3, 0), [4.0, 5.0]);
    assert_eq!(packed(&mut w, 3, 10), [4.0, 5.0]);
    assert!(packed(&mut w, 9, 0).is_empty());
    let data = ok(&mut w, "packDoubleTable", std::slice::from_ref(&t)).remove(0);
    let u = |w: &mut Sim, args: &[i64]| {
        let mut a = vec![data.clone()];
        a.extend(args.iter().map(|&x| Value::Int(x)));
        floats(&ok(w, "unpackDoubleTable", &a)[0])
    };
    assert_eq!(u(&mut w, &[2]), [3.0, 4.0, 5.0]);
    assert_eq!(u(&mut w, &[2, 2]), [3.0, 4.0]);
    assert!(u(&mut w, &[5]).is_empty());
    assert!(u(&mut w, &[i64::MAX / 2]).is_empty());
    // A byte offset of one whole value skips it; a partial value at the end is ignored.
    assert_eq!(u(&mut w, &[0, 0, 8]), [2.0, 3.0, 4.0, 5.0]);
    assert_eq!(u(&mut w, &[0, 0, 3]).len(), 4);
    // Header bytes before packed floats, as in a vision sensor packet.
    let mut with_header = vec![0xaa, 0xbb];
    with_header.extend(bytes(&ok(&mut w, "packFloatTable", &[v(&[1.5, -2.0])])[0]));
    assert_eq!(
        floats(
            &ok(
                &mut w,
                "unpackFloatTable",
                &[Value::Bytes(with_header), 0.into(), 0.into(), 2.into()]
            )[0]
        ),
        [1.5, -2.0]
    );
    // uint8 has no byte offset: its start index is one.
    let d = ok(
        &mut w,
        "packUInt8Table",
        &[Value::Array(vec![9.into(), 8.into(), 7.into()])],
    )
    .remove(0);
    assert_eq!(
        floats(&ok(&mut w, "unpackUInt8Table", &[d, 1.into(), 1.into()])[0]),
        [8.0]
    );
    // Text strings are byte strings too.
    assert_eq!(floats(&ok(&mut w, "unpackUInt8Table", &["AB".into()])[0]), [65.0, 66.0]);
    for (name, args) in [
        ("packDoubleTable", vec![t.clone(), (-1).into()]),
        ("unpackDoubleTable", vec![data.clone(), 0.into(), (-3).into()]),
        ("unpackInt32Table", vec![data.clone(), 0.into(), 0.into(), (-1).into()]),
    ] {
        let e = err(&mut w, name, &args);
        assert!(e.contains("must be 0 or more"), "{name}: {e}");
    }
}

#[test]
fn integers_must_fit() {
    let mut w = world();
    let cases: &[(&str, Value, &str)] = &[
        ("packUInt8Table", 256.into(), "does not fit in a uint8"),
        ("packUInt8Table", (-1).into(), "does not fit in a uint8"),
        ("packUInt16Table", 65536.into(), "does not fit in a uint16"),
        ("packUInt32Table", (-1).into(), "does not fit in a uint32"),
        ("packInt32Table", (1_i64 << 31).into(), "does not fit in a int32"),
        ("packInt32Table", 1.5.into(), "must be an integer, got 1.5"),
        ("packInt32Table", Value::Bool(true), "must be an integer, got boolean"),
    ];
    for (name, item, expected) in cases {
        let e = err(&mut w, name, &[Value::Array(vec![0.into(), item.clone()])]);
        assert!(
            e.contains("argument 1: element 2") && e.contains(expected),
            "{name}: {e}"
        );
    }
    // Integral floats are integers (Python and Lua clients send 3.0 for 3).
    assert_eq!(bytes(&ok(&mut w, "packUInt8Table", &[v(&[3.0])])[0]), [3]);
}

#[test]
fn tables_pack_and_unpack() {
    let mut w = world();
    let table = Value::Map(vec![
        ("name".into(), "arm".into()),
        ("q".into(), v(&[0.5, -1.25])),
        ("n".into(), 42.into()),
        ("on".into(), Value::Bool(true)),
        ("raw".into(), Value::Bytes(vec![0, 255, 10])),
        (
            7.into(),
            Value::Array(vec![Value::Nil, Value::Array(vec![]), Value::Map(vec![])]),
        ),
    ]);
    for scheme in [None, Some(0), Some(1)] {
        let mut args = vec![table.clone()];
        args.extend(scheme.map(Value::Int));
        let data = ok(&mut w, "packTable", &args).remove(0);
        assert!(matches!(data, Value::Bytes(_)));
        assert_eq!(ok(&mut w, "unpackTable", &[data]), std::slice::from_ref(&table));
    }
    let arr = Value::Array(vec![1.into(), 2.5.into(), "x".into()]);
    let data = ok(&mut w, "packTable", std::slice::from_ref(&arr)).remove(0);
    assert_eq!(ok(&mut w, "unpackTable", &[data]), [arr]);
    let e = err(&mut w, "packTable", &[table.clone(), 2.into()]);
    assert!(e.contains("argument 2 (scheme)"), "{e}");
    let e = err(&mut w, "packTable", &[3.into()]);
    assert!(e.contains("argument 1: expected a table"), "{e}");
    // Too deep to read back: refused when packing.
    let mut deep = Value::Array(vec![]);
    for _ in 0..100 {
        deep = Value::Array(vec![deep]);
    }
    let e = err(&mut w, "packTable", &[deep]);
    assert!(e.contains("nested deeper"), "{e}");
}

#[test]
fn unpack_table_is_total_on_malformed_data() {
    let mut w = world();
    let good = bytes(&ok(&mut w, "packTable", &[Value::Map(vec![("a".into(), v(&[1.0, 2.0]))])])[0]);
    let mut cases: Vec<Vec<u8>> = vec![
        vec![],
        vec![0xff],
        vec![0x1c],
        good[..good.len() - 1].to_vec(),
        [good.clone(), vec![0]].concat(),
        // A claimed length far beyond the input.
        vec![0x9b, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff],
        // Nesting past the limit.
        vec![0x81; 200],
        // Text that is not UTF-8.
        vec![0x62, 0xc3, 0x28],
    ];
    // Every truncation of a valid packed table, and pseudo-random bytes.
    cases.extend((0..good.len()).map(|n| good[..n].to_vec()));
    let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
    for len in 0..200 {
        cases.push(
            (0..len)
                .map(|_| {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    x as u8
                })
                .collect(),
        );
    }
    for data in cases {
        // Either a value or an error message; never a panic.
        if let Err(e) = util::call(&mut w, "unpackTable", &[Value::Bytes(data.clone())]) {
            assert!(e.starts_with("argument 1: not a packed table"), "{data:?}: {e}");
        }
    }
    let e = err(&mut w, "unpackTable", &[Value::Bytes(vec![0x81; 200])]);
    assert!(e.contains("nesting"), "{e}");
    let e = err(&mut w, "unpackTable", &[1.into()]);
    assert!(e.contains("argument 1"), "{e}");
}
