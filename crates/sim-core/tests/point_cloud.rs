//! Point clouds through the API: insertion and its total, the voxel settings (which
//! split voxels in CoppeliaSim and never drop a point), duplicate tolerance, frames
//! (world-frame points stored relative to a moved, rotated, re-parented cloud), removal,
//! intersection, options, the object's life in the tree, and bad input.

use crate::util;

use std::f64::consts::FRAC_PI_2;

use gantry_sim_core::SimError;
use gantry_sim_core::api::{CallContext, call};
use gantry_sim_core::world::{MAX_POINT_CLOUD_POINTS, ObjectKind};
use gantry_sim_core::{Handle, Sim, Value};
use gantry_test_support::{assert_close, floats, int, num};

/// `sim.insertPointsIntoPointCloud` option: points in the cloud's frame.
const RELATIVE: i64 = 1;
/// Option: one colour per point.
const PER_POINT_COLORS: i64 = 2;
/// `sim.object_pointcloud_type`.
const POINTCLOUD_TYPE: i64 = 16;

const SCENE: &str = r#"
[[object]]
name = "base"
kind = "dummy"
position = [1.0, 2.0, 0.5]
"#;

fn sim() -> Sim {
    util::text_scene("point_cloud.toml", SCENE)
}

fn try_call(s: &mut Sim, name: &str, args: &[Value]) -> Result<Vec<Value>, (Option<SimError>, String)> {
    call(s, &CallContext::default(), name, args).map_err(|e| (e.error().cloned(), e.to_string()))
}

fn ok(s: &mut Sim, name: &str, args: &[Value]) -> Vec<Value> {
    try_call(s, name, args).unwrap_or_else(|(_, e)| panic!("{name}: {e}"))
}

/// Calls a function that must fail; its error kind and message.
fn err(s: &mut Sim, name: &str, args: &[Value]) -> (Option<SimError>, String) {
    match try_call(s, name, args) {
        Ok(r) => panic!("{name}({args:?}) should fail, returned {r:?}"),
        Err(e) => e,
    }
}

fn h(v: Handle) -> Value {
    Value::Int(v)
}

fn i(v: i64) -> Value {
    Value::Int(v)
}

fn f(v: f64) -> Value {
    Value::Float(v)
}

fn list(v: &[f64]) -> Value {
    Value::floats(v)
}

fn bytes(v: &[i64]) -> Value {
    Value::Array(v.iter().map(|&b| Value::Int(b)).collect())
}

/// `sim.createPointCloud(voxel, perVoxel, options, pointSize)`.
fn create(s: &mut Sim, voxel: f64, per_voxel: i64, options: i64, size: f64) -> Handle {
    int(&ok(s, "createPointCloud", &[f(voxel), i(per_voxel), i(options), f(size)])[0])
}

fn insert(s: &mut Sim, c: Handle, options: i64, pts: &[f64], extra: &[Value]) -> i64 {
    let mut args = vec![h(c), i(options), list(pts)];
    args.extend_from_slice(extra);
    int(&ok(s, "insertPointsIntoPointCloud", &args)[0])
}

fn points(s: &mut Sim, c: Handle) -> Vec<f64> {
    floats(&ok(s, "getPointCloudPoints", &[h(c)])[0])
}

#[test]
fn created_cloud_is_an_object_of_the_tree() {
    let mut s = sim();
    let c = create(&mut s, 0.01, 10, 0, 10.0);
    assert_eq!(int(&ok(&mut s, "getObjectType", &[h(c)])[0]), POINTCLOUD_TYPE);
    assert_eq!(
        ok(&mut s, "getObjectAlias", &[h(c)])[0],
        Value::Str("PointCloud".into())
    );
    assert_eq!(int(&ok(&mut s, "getObjectParent", &[h(c)])[0]), -1);
    // The snippet's 4.0-4.2 rename, with the silent-error flag on the handle.
    let silent = c + 0x0200_0000;
    ok(&mut s, "setObjectName", &[h(silent), Value::Str("cloud".into())]);
    assert_eq!(s.world.find("/cloud", None, 0), Ok(c));
    // The flag silences a missing object, but only with it.
    ok(&mut s, "setObjectName", &[h(999 + 0x0200_0000), Value::Str("x".into())]);
    assert!(matches!(
        err(&mut s, "setObjectName", &[h(999), Value::Str("x".into())]).0,
        Some(SimError::NoSuchObject(_))
    ));
    assert!(s.world.handles().contains(&c));
    // An empty cloud has no points.
    assert!(points(&mut s, c).is_empty());
    assert_eq!(insert(&mut s, c, 0, &[], &[]), 0);
}

#[test]
fn insertion_returns_the_total_and_points_read_back_with_their_colours() {
    let mut s = sim();
    let c = create(&mut s, 0.01, 10, 0, 4.0);
    assert_eq!(insert(&mut s, c, RELATIVE, &[0.1, 0.2, 0.3, -0.1, 0.0, 0.05], &[]), 2);
    let colors = bytes(&[255, 0, 0, 0, 128, 255]);
    assert_eq!(
        insert(
            &mut s,
            c,
            RELATIVE | PER_POINT_COLORS,
            &[1.0, 0.0, 0.0, 2.0, 0.0, 0.0],
            &[colors]
        ),
        4
    );
    assert_eq!(
        insert(&mut s, c, RELATIVE, &[3.0, 0.0, 0.0], &[bytes(&[10, 20, 30])]),
        5
    );
    assert_close(
        &points(&mut s, c),
        &[
            0.1, 0.2, 0.3, -0.1, 0.0, 0.05, 1.0, 0.0, 0.0, 2.0, 0.0, 0.0, 3.0, 0.0, 0.0,
        ],
        1e-9,
    );
    let ObjectKind::PointCloud(cloud) = &s.world.object(c).expect("cloud").kind else {
        panic!("not a point cloud");
    };
    assert_eq!(
        cloud.colors(),
        [
            [255, 255, 255],
            [255, 255, 255],
            [255, 0, 0],
            [0, 128, 255],
            [10, 20, 30]
        ],
        "white by default, then per point, then one for all"
    );
}

#[test]
fn a_full_voxel_splits_and_keeps_every_point() {
    // CoppeliaSim splits a voxel holding more than maxPtCntPerVoxel points into 8
    // smaller ones: 50 points in one 1 cm voxel with at most 2 per voxel are all kept.
    let mut s = sim();
    let c = create(&mut s, 0.01, 2, 0, 2.0);
    let pts: Vec<f64> = (0..50).flat_map(|k| [0.0001 * f64::from(k), 0.0005, 0.0005]).collect();
    assert_eq!(insert(&mut s, c, RELATIVE, &pts, &[]), 50);
    assert_close(&points(&mut s, c), &pts, 1e-9);
    // The same points again with a duplicate tolerance are all duplicates.
    assert_eq!(insert(&mut s, c, RELATIVE, &pts, &[Value::Nil, f(0.00005)]), 50);
}

#[test]
fn duplicates_within_the_tolerance_are_not_inserted() {
    let mut s = sim();
    let c = create(&mut s, 0.01, 10, 0, 2.0);
    assert_eq!(insert(&mut s, c, RELATIVE, &[0.0, 0.0, 0.0], &[]), 1);
    // 4 mm from the first point, then 4 mm from each other, across voxel boundaries:
    // with 5 mm, the first is a duplicate of the stored point, the second is new, the
    // third a duplicate of the second (inserted in the same call).
    let batch = [0.004, 0.0, 0.0, 0.0, 0.009, 0.0, 0.0, 0.013, 0.0];
    assert_eq!(insert(&mut s, c, RELATIVE, &batch, &[Value::Nil, f(0.005)]), 2);
    assert_close(&points(&mut s, c), &[0.0, 0.0, 0.0, 0.0, 0.009, 0.0], 1e-9);
    // Strictly closer: at exactly the tolerance a point is inserted.
    assert_eq!(
        insert(&mut s, c, RELATIVE, &[0.0, 0.0, 0.005], &[Value::Nil, f(0.005)]),
        3
    );
    // Without a tolerance, duplicates are kept (the default is 0).
    assert_eq!(insert(&mut s, c, RELATIVE, &[0.0, 0.0, 0.0], &[]), 4);
    // Without a calculation structure (option 8), CoppeliaSim skips the check.
    let flat = create(&mut s, 0.01, 10, 8, 2.0);
    assert_eq!(insert(&mut s, flat, RELATIVE, &[0.0; 6], &[Value::Nil, f(0.5)]), 2);
}

#[test]
fn world_frame_points_are_stored_relative_to_a_moved_rotated_cloud() {
    let mut s = sim();
    let c = create(&mut s, 0.01, 10, 0, 2.0);
    ok(&mut s, "setObjectPosition", &[h(c), i(-1), list(&[1.0, 0.0, 0.0])]);
    ok(
        &mut s,
        "setObjectOrientation",
        &[h(c), i(-1), list(&[0.0, 0.0, FRAC_PI_2])],
    );
    // World (1, 1, 0) is (1, 0, 0) in a frame at x = 1 turned 90 degrees about z.
    insert(&mut s, c, 0, &[1.0, 1.0, 0.0], &[]);
    assert_close(&points(&mut s, c), &[1.0, 0.0, 0.0], 1e-9);
    // Relative points are stored as given.
    insert(&mut s, c, RELATIVE, &[0.0, 0.0, 0.5], &[]);
    assert_close(&points(&mut s, c), &[1.0, 0.0, 0.0, 0.0, 0.0, 0.5], 1e-9);

    // The points follow the cloud: moved under a parent, the stored points are the same
    // and their world position is the new pose applied to them.
    let base = s.world.find("/base", None, 0).expect("base");
    ok(&mut s, "setObjectParent", &[h(c), h(base), Value::Bool(false)]);
    assert_close(&points(&mut s, c), &[1.0, 0.0, 0.0, 0.0, 0.0, 0.5], 1e-9);
    let pose = s.world.object(c).expect("cloud").world;
    let w = pose.transform_point(&[1.0, 0.0, 0.0].into());
    assert_close(&[w.x, w.y, w.z], &[2.0, 3.0, 0.5], 1e-9);
    // And world-frame removal and insertion use the new pose: world (2, 3, 0.5) is the
    // first stored point.
    assert_eq!(
        int(&ok(
            &mut s,
            "removePointsFromPointCloud",
            &[h(c), i(0), list(&[2.0, 3.0, 0.5]), f(0.001)]
        )[0]),
        1
    );
    assert_close(&points(&mut s, c), &[0.0, 0.0, 0.5], 1e-9);
}

#[test]
fn removal_intersection_and_clearing() {
    let mut s = sim();
    let c = create(&mut s, 0.05, 10, 0, 2.0);
    let row: Vec<f64> = (0..10).flat_map(|k| [0.1 * f64::from(k), 0.0, 0.0]).collect();
    insert(&mut s, c, RELATIVE, &row, &[]);
    let remove = |s: &mut Sim, pts: Value, tol: f64| {
        int(&ok(s, "removePointsFromPointCloud", &[h(c), i(RELATIVE), pts, f(tol)])[0])
    };
    // Points strictly within 0.15 of x = 0.5: 0.4, 0.5 and 0.6.
    assert_eq!(remove(&mut s, list(&[0.5, 0.0, 0.0]), 0.15), 7);
    // A zero tolerance removes nothing.
    assert_eq!(remove(&mut s, list(&[0.0, 0.0, 0.0]), 0.0), 7);
    // Intersection keeps the points near the given ones.
    let kept = ok(
        &mut s,
        "intersectPointsWithPointCloud",
        &[h(c), i(RELATIVE), list(&[0.0, 0.0, 0.0, 0.9, 0.0, 0.01]), f(0.05)],
    );
    assert_eq!(int(&kept[0]), 2);
    assert_close(&points(&mut s, c), &[0.0, 0.0, 0.0, 0.9, 0.0, 0.0], 1e-9);
    // nil points remove everything, whatever the tolerance (CoppeliaSim's idiom passes 0).
    assert_eq!(remove(&mut s, Value::Nil, 0.0), 0);
    assert!(points(&mut s, c).is_empty());
    insert(&mut s, c, RELATIVE, &row, &[]);
    let none = ok(
        &mut s,
        "intersectPointsWithPointCloud",
        &[h(c), i(0), Value::Nil, f(0.1)],
    );
    assert_eq!(int(&none[0]), 0);
}

#[test]
fn options_are_clamped_read_back_and_changed() {
    let mut s = sim();
    // The snippet's call: 10 pixels are more than CoppeliaSim's 8.
    let c = create(&mut s, 0.01, 10, 0, 10.0);
    let o = ok(&mut s, "getPointCloudOptions", &[h(c)]);
    assert_eq!((num(&o[0]), int(&o[1]), int(&o[2]), num(&o[3])), (0.01, 10, 0, 8.0));
    // Out-of-range sizes are clamped; unknown option bits dropped.
    let big = create(&mut s, 100.0, 10000, 0xff, 2.4);
    let o = ok(&mut s, "getPointCloudOptions", &[h(big)]);
    assert_eq!(
        (num(&o[0]), int(&o[1]), int(&o[2]), num(&o[3])),
        (1.0, 100, 1 | 2 | 8 | 16, 2.0)
    );

    insert(&mut s, c, RELATIVE, &[0.0, 0.0, 0.0, 0.5, 0.5, 0.5], &[]);
    ok(&mut s, "setPointCloudOptions", &[h(c), f(0.2), i(5), i(1), f(3.0)]);
    let o = ok(&mut s, "getPointCloudOptions", &[h(c)]);
    assert_eq!((num(&o[0]), int(&o[1]), int(&o[2]), num(&o[3])), (0.2, 5, 1, 3.0));
    // The points stay, and the new voxel size still finds them.
    assert_close(&points(&mut s, c), &[0.0, 0.0, 0.0, 0.5, 0.5, 0.5], 1e-9);
    let left = ok(
        &mut s,
        "removePointsFromPointCloud",
        &[h(c), i(RELATIVE), list(&[0.5, 0.5, 0.5]), f(0.01)],
    );
    assert_eq!(int(&left[0]), 1);
}

#[test]
fn clouds_are_removed_and_copied_like_other_objects() {
    let mut s = sim();
    let c = create(&mut s, 0.01, 10, 0, 2.0);
    insert(&mut s, c, RELATIVE, &[0.1, 0.2, 0.3], &[]);
    let copies = ok(&mut s, "copyPasteObjects", &[Value::Array(vec![h(c)])]);
    let copy = floats(&copies[0])[0] as Handle;
    assert_ne!(copy, c);
    assert_close(&points(&mut s, copy), &[0.1, 0.2, 0.3], 1e-9);
    // The copy is independent.
    insert(&mut s, copy, RELATIVE, &[1.0, 1.0, 1.0], &[]);
    assert_eq!(points(&mut s, c).len(), 3);
    ok(&mut s, "removeObject", &[h(c)]);
    let (kind, _) = err(&mut s, "getPointCloudPoints", &[h(c)]);
    assert!(matches!(kind, Some(SimError::NoSuchObject(_))));
    assert_eq!(points(&mut s, copy).len(), 6);
}

#[test]
fn bad_input_is_a_clear_error() {
    let mut s = sim();
    let c = create(&mut s, 0.01, 10, 0, 2.0);
    let base = s.world.find("/base", None, 0).expect("base");

    // Wrong kind of object, and no object.
    let (kind, msg) = err(&mut s, "insertPointsIntoPointCloud", &[h(base), i(0), list(&[0.0; 3])]);
    assert!(matches!(kind, Some(SimError::WrongKind { .. })));
    assert!(msg.contains("not a point cloud"), "{msg}");
    assert!(matches!(
        err(&mut s, "getPointCloudOptions", &[h(9999)]).0,
        Some(SimError::NoSuchObject(_))
    ));
    for name in ["getPointCloudPoints", "getPointCloudOptions"] {
        assert!(
            matches!(err(&mut s, name, &[h(base)]).0, Some(SimError::WrongKind { .. })),
            "{name}"
        );
    }

    // An odd number of coordinates, non-numbers, non-finite values.
    let (kind, msg) = err(&mut s, "insertPointsIntoPointCloud", &[h(c), i(0), list(&[0.0; 4])]);
    assert!(matches!(kind, Some(SimError::BadArgument(_))));
    assert!(msg.contains("3 numbers per point") && msg.contains("got 4"), "{msg}");
    let mixed = Value::Array(vec![f(0.0), Value::Str("x".into()), f(0.0)]);
    assert!(
        err(&mut s, "insertPointsIntoPointCloud", &[h(c), i(0), mixed])
            .1
            .contains("element 2")
    );
    let nan = list(&[0.0, f64::NAN, 0.0]);
    assert!(
        err(&mut s, "insertPointsIntoPointCloud", &[h(c), i(0), nan])
            .1
            .contains("finite")
    );
    assert!(
        err(&mut s, "insertPointsIntoPointCloud", &[h(c), i(0), Value::Nil])
            .1
            .contains("argument 3")
    );
    let (_, msg) = err(
        &mut s,
        "removePointsFromPointCloud",
        &[h(c), i(0), list(&[0.0; 5]), f(0.1)],
    );
    assert!(msg.contains("3 numbers per point"), "{msg}");

    // Colours: too few for one per point, too few for all, out of range.
    let two = list(&[0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
    let (kind, msg) = err(
        &mut s,
        "insertPointsIntoPointCloud",
        &[h(c), i(PER_POINT_COLORS), two.clone(), bytes(&[1, 2, 3, 4, 5])],
    );
    assert!(matches!(kind, Some(SimError::BadArgument(_))));
    assert!(msg.contains("at least 6 colour values"), "{msg}");
    let (_, msg) = err(
        &mut s,
        "insertPointsIntoPointCloud",
        &[h(c), i(0), two.clone(), bytes(&[1, 2])],
    );
    assert!(msg.contains("at least 3 colour values"), "{msg}");
    let (_, msg) = err(
        &mut s,
        "insertPointsIntoPointCloud",
        &[h(c), i(0), two.clone(), bytes(&[1, 2, 300])],
    );
    assert!(msg.contains("0 to 255"), "{msg}");

    // Negative sizes, tolerances.
    for (args, what) in [
        ([f(-0.01), i(10), i(0), f(2.0)], "voxel size"),
        ([f(0.01), i(-1), i(0), f(2.0)], "per voxel"),
        ([f(0.01), i(10), i(0), f(-2.0)], "point size"),
    ] {
        let (kind, msg) = err(&mut s, "createPointCloud", &args);
        assert!(matches!(kind, Some(SimError::BadArgument(_))), "{msg}");
        assert!(msg.contains(what), "{msg}");
    }
    assert!(err(&mut s, "createPointCloud", &[f(0.01)]).1.contains("argument 2"));
    let (_, msg) = err(
        &mut s,
        "insertPointsIntoPointCloud",
        &[h(c), i(0), two.clone(), Value::Nil, f(-1.0)],
    );
    assert!(msg.contains("tolerance"), "{msg}");
    let (_, msg) = err(
        &mut s,
        "removePointsFromPointCloud",
        &[h(c), i(0), two.clone(), f(-1.0)],
    );
    assert!(msg.contains("tolerance"), "{msg}");
    assert!(
        err(&mut s, "setPointCloudOptions", &[h(c), f(-1.0), i(1), i(0), f(1.0)])
            .1
            .contains("voxel")
    );

    // Nothing was inserted by the failed calls.
    assert!(points(&mut s, c).is_empty());
}

#[test]
fn a_cloud_has_a_bounded_number_of_points() {
    let mut s = sim();
    let c = create(&mut s, 1.0, 100, 8, 1.0);
    let chunk: Vec<f64> = vec![0.0; 3 * (MAX_POINT_CLOUD_POINTS / 2)];
    insert(&mut s, c, RELATIVE, &chunk, &[]);
    insert(&mut s, c, RELATIVE, &chunk, &[]);
    let (kind, msg) = err(
        &mut s,
        "insertPointsIntoPointCloud",
        &[h(c), i(RELATIVE), list(&[0.0; 6])],
    );
    assert!(matches!(kind, Some(SimError::Refused(_))));
    assert!(msg.contains(&MAX_POINT_CLOUD_POINTS.to_string()), "{msg}");
    // Refused as a whole: the cloud is as it was, and removal makes room again.
    let ObjectKind::PointCloud(cloud) = &s.world.object(c).expect("cloud").kind else {
        panic!("not a point cloud");
    };
    assert_eq!(cloud.len(), MAX_POINT_CLOUD_POINTS);
    ok(&mut s, "removePointsFromPointCloud", &[h(c), i(0), Value::Nil, f(0.0)]);
    assert_eq!(insert(&mut s, c, RELATIVE, &[0.0; 6], &[]), 2);
}
