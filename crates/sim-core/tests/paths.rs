//! Paths through the API: CoppeliaSim 4.3+'s path math (`sim.getPathLengths`,
//! `sim.getPathInterpolatedConfig`, `sim.resamplePath`) against values computed by hand,
//! and path objects (`sim.createPath` in both forms) with V-REP 3's functions on them.

use crate::util;

use gantry_sim_core::Value;
use gantry_sim_core::math::Pose;
use gantry_test_support::{assert_close, floats, num};
use util::{err, ok};

fn scene() -> gantry_sim_core::Sim {
    util::asset_scene("scenes/bubble_rob.toml")
}

fn map(pairs: &[(&str, Value)]) -> Value {
    Value::Map(pairs.iter().map(|(k, v)| (Value::from(*k), v.clone())).collect())
}

#[test]
fn path_lengths_and_interpolated_configs() {
    let mut w = scene();
    // Two 3D poses 3-4-0 apart, a quarter turn about z between them: 5 m, the
    // quaternion not counted.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let path = Value::floats(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 3.0, 4.0, 0.0, 0.0, 0.0, h, h]);
    let r = ok(&mut w, "sim.getPathLengths", &[path.clone(), Value::Int(7)]);
    assert_close(&floats(&r[0]), &[0.0, 5.0], 1e-9);
    assert_eq!(num(&r[1]), 5.0);
    // At 2 m of 5: 40 % of the way, the quaternion slerped 40 % of 90 degrees about z.
    let types = Value::floats(&[0.0, 0.0, 0.0, 2.0, 2.0, 2.0, 2.0]);
    let c = ok(
        &mut w,
        "sim.getPathInterpolatedConfig",
        &[path.clone(), r[0].clone(), Value::Float(2.0), Value::Nil, types],
    );
    let half = 0.4 * std::f64::consts::FRAC_PI_4;
    assert_close(&floats(&c[0]), &[1.2, 1.6, 0.0, 0.0, 0.0, half.sin(), half.cos()], 1e-9);
    // A 2pi-cyclic value takes the short way: from 3 to -3 rad through pi.
    let c = ok(
        &mut w,
        "sim.getPathInterpolatedConfig",
        &[
            Value::floats(&[3.0, -3.0]),
            Value::floats(&[0.0, 1.0]),
            Value::Float(0.5),
            Value::Nil,
            Value::floats(&[1.0]),
        ],
    );
    assert_close(&floats(&c[0]), &[std::f64::consts::PI], 1e-9);
    // Quadratic Bezier: the corner of (0,0) (2,0) (2,1) is rounded from (1,0) to
    // (2,0.5); at length 1.75, half way: 0.25 (1,0) + 0.5 (2,0) + 0.25 (2,0.5).
    let l = Value::floats(&[0.0, 2.0, 3.0]);
    let corner = Value::floats(&[0.0, 0.0, 2.0, 0.0, 2.0, 1.0]);
    let bezier = map(&[
        ("type", Value::from("quadraticBezier")),
        ("strength", Value::Float(1.0)),
    ]);
    let c = ok(
        &mut w,
        "sim.getPathInterpolatedConfig",
        &[corner.clone(), l.clone(), Value::Float(1.75), bezier.clone()],
    );
    assert_close(&floats(&c[0]), &[1.75, 0.125], 1e-9);
    let linear = ok(
        &mut w,
        "sim.getPathInterpolatedConfig",
        &[corner.clone(), l.clone(), Value::Float(1.75)],
    );
    assert_close(&floats(&linear[0]), &[1.75, 0.0], 1e-9);
    // Resampled to 4 configurations at lengths 0, 1, 2, 3.
    let r = ok(&mut w, "sim.resamplePath", &[corner.clone(), l.clone(), Value::Int(4)]);
    assert_close(&floats(&r[0]), &[0.0, 0.0, 1.0, 0.0, 2.0, 0.0, 2.0, 1.0], 1e-9);

    let e = err(
        &mut w,
        "sim.getPathInterpolatedConfig",
        &[corner.clone(), Value::floats(&[0.0, 1.0, 2.0, 3.0]), Value::Float(1.0)],
    );
    assert!(
        e.contains("getPathInterpolatedConfig") && e.contains("configuration per length"),
        "{e}"
    );
    let e = err(
        &mut w,
        "sim.getPathInterpolatedConfig",
        &[
            corner.clone(),
            l.clone(),
            Value::Float(1.0),
            map(&[("type", Value::from("cubic"))]),
        ],
    );
    assert!(e.contains("quadraticBezier"), "{e}");
    let e = err(&mut w, "sim.getPathLengths", &[corner, Value::Int(4)]);
    assert!(e.contains("whole configurations of 4"), "{e}");
}

#[test]
fn created_paths_read_as_dummies_and_carry_their_points() {
    let mut w = scene();
    // 4.3+: three control points along x then y, closed, smoothed to 50 points.
    let q = [0.0, 0.0, 0.0, 1.0];
    let mut ctrl = Vec::new();
    for p in [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]] {
        ctrl.extend(p);
        ctrl.extend(q);
    }
    let straight = ok(
        &mut w,
        "sim.createPath",
        &[Value::floats(&ctrl), Value::Int(0), Value::Int(100), Value::Float(0.0)],
    );
    let sp = straight[0].clone();
    assert_eq!(
        num(&ok(&mut w, "sim.getObjectType", std::slice::from_ref(&sp))[0]),
        4.0,
        "sim.object_dummy_type"
    );
    assert_eq!(num(&ok(&mut w, "sim.getPathLength", std::slice::from_ref(&sp))[0]), 2.0);
    let at = |w: &mut gantry_sim_core::Sim, h: &Value, rel: f64| {
        floats(&ok(w, "sim.getPositionOnPath", &[h.clone(), Value::Float(rel)])[0])
    };
    assert_close(&at(&mut w, &sp, 0.25), &[0.5, 0.0, 0.0], 1e-9);
    assert_close(&at(&mut w, &sp, 0.75), &[1.0, 0.5, 0.0], 1e-9);
    // The points are the path's custom data, 7 doubles each, as 4.3+ scripts read them.
    let block = ok(&mut w, "sim.readCustomDataBlock", &[sp.clone(), Value::from("PATH")]);
    let unpacked = ok(&mut w, "sim.unpackDoubleTable", &[block[0].clone()]);
    assert_eq!(floats(&unpacked[0]).len(), 21, "3 points of 7 values");

    let smooth = ok(
        &mut w,
        "sim.createPath",
        &[Value::floats(&ctrl), Value::Int(4), Value::Int(50), Value::Float(1.0)],
    );
    let h = smooth[0].clone();
    let block = ok(&mut w, "sim.readCustomDataBlock", &[h.clone(), Value::from("PATH")]);
    let pts = floats(&ok(&mut w, "sim.unpackDoubleTable", &[block[0].clone()])[0]);
    assert_eq!(pts.len(), 50 * 7);
    // Closed: back to the start; smoothed: the corner at (1,0) is cut.
    assert_close(&pts[..3], &pts[pts.len() - 7..pts.len() - 4], 1e-9);
    assert!(pts.chunks(7).all(|p| (p[0] - 1.0).abs() + p[1].abs() > 1e-3));
    let len = num(&ok(&mut w, "sim.getPathLength", std::slice::from_ref(&h))[0]);
    // Shorter than the triangle (2 + sqrt 2), longer than the triangle through its
    // sides' midpoints, where the roundings of strength 1 start and end.
    let perimeter = 2.0 + 2f64.sqrt();
    assert!(len > perimeter / 2.0 && len < perimeter - 0.1, "{len}");
    // Moving the dummy moves the path.
    let handle = h.as_i64().unwrap();
    w.world
        .set_world_pose(handle, Pose::translation(0.0, 0.0, 1.0))
        .unwrap();
    assert!((at(&mut w, &h, 0.0)[2] - 1.0).abs() < 1e-12);
    let e = err(
        &mut w,
        "sim.createPath",
        &[Value::floats(&ctrl), Value::Int(0), Value::Nil, Value::Float(1.5)],
    );
    assert!(e.contains("argument 4 (smoothness)") && e.contains("createPath"), "{e}");
    let e = err(
        &mut w,
        "sim.createPath",
        &[
            Value::floats(&ctrl),
            Value::Int(0),
            Value::Nil,
            Value::Nil,
            Value::Int(-1),
        ],
    );
    assert!(
        e.contains("argument 5 (orientationMode)") && e.contains("got -1"),
        "{e}"
    );
    let e = err(&mut w, "sim.createPath", &[Value::floats(&ctrl[..7])]);
    assert!(e.contains("at least 2 control points"), "{e}");
    // Removed with its object.
    ok(&mut w, "sim.removeObjects", &[Value::Array(vec![h.clone()])]);
    assert!(err(&mut w, "sim.getPathLength", &[h]).contains("getPathLength"));
}

#[test]
fn v_rep_3_paths_from_control_points() {
    let mut w = scene();
    let h = ok(&mut w, "sim.createPath", &[Value::Int(-1)])[0].clone();
    // (0,0,0), (0,0,2), (0,1,2) in 11 values each, the last turned a quarter about z.
    let mut data = vec![0.0; 33];
    data[11 + 2] = 2.0;
    data[22 + 1] = 1.0;
    data[22 + 2] = 2.0;
    data[22 + 5] = std::f64::consts::FRAC_PI_2;
    ok(
        &mut w,
        "sim.insertPathCtrlPoints",
        &[
            h.clone(),
            Value::Int(0),
            Value::Int(0),
            Value::Int(3),
            Value::floats(&data),
        ],
    );
    assert_eq!(num(&ok(&mut w, "sim.getPathLength", std::slice::from_ref(&h))[0]), 3.0);
    let pos = floats(&ok(&mut w, "sim.getPositionOnPath", &[h.clone(), Value::Float(0.5)])[0]);
    assert_close(&pos, &[0.0, 0.0, 1.5], 1e-9);
    let end = floats(&ok(&mut w, "sim.getOrientationOnPath", &[h.clone(), Value::Float(1.0)])[0]);
    assert_close(&end, &[0.0, 0.0, std::f64::consts::FRAC_PI_2], 1e-9);
    // V-REP's path position stays on an open path.
    ok(&mut w, "sim.setPathPosition", &[h.clone(), Value::Float(7.0)]);
    assert_eq!(
        num(&ok(&mut w, "sim.getPathPosition", std::slice::from_ref(&h))[0]),
        3.0
    );
    ok(
        &mut w,
        "sim.setPathTargetNominalVelocity",
        &[h.clone(), Value::Float(0.1)],
    );
    ok(
        &mut w,
        "sim.cutPathCtrlPoints",
        &[h.clone(), Value::Int(-1), Value::Int(0)],
    );
    let e = err(&mut w, "sim.getPositionOnPath", &[h.clone(), Value::Float(0.0)]);
    assert!(e.contains("no control points"), "{e}");
    // With auxiliary data (options bit 1), 16 values a point: (0,0,0) and (0,0,0.5).
    let mut aux = vec![0.0; 32];
    aux[16 + 2] = 0.5;
    ok(
        &mut w,
        "sim.insertPathCtrlPoints",
        &[
            h.clone(),
            Value::Int(2),
            Value::Int(0),
            Value::Int(2),
            Value::floats(&aux),
        ],
    );
    assert_eq!(num(&ok(&mut w, "sim.getPathLength", std::slice::from_ref(&h))[0]), 0.5);
    let e = err(
        &mut w,
        "sim.insertPathCtrlPoints",
        &[
            h,
            Value::Int(0),
            Value::Int(0),
            Value::Int(2),
            Value::floats(&[0.0; 11]),
        ],
    );
    assert!(e.contains("22 values") && e.contains("insertPathCtrlPoints"), "{e}");
    let body = util::find(&w, "/bubbleRob");
    let e = err(&mut w, "sim.getPathLength", &[Value::Int(body)]);
    assert!(e.contains("not a path"), "{e}");
}
