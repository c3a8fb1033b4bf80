//! OC trees through the API: the object in the tree, voxels from points (1 to 8 per
//! point, as in CoppeliaSim), frames (world-frame points stored relative to a moved
//! octree), colours and tags, occupancy, removal, voxelising and subtracting a shape and
//! a point cloud, the voxel limit, and bad input.

use crate::util;

use std::f64::consts::FRAC_PI_2;

use gantry_sim_core::SimError;
use gantry_sim_core::api::{CallContext, MODULES, call};
use gantry_sim_core::world::{MAX_OCTREE_VOXELS, ObjectKind};
use gantry_sim_core::{Handle, Sim, Value};
use gantry_test_support::{assert_close, floats, int};

/// Voxel option bit 0: points in the octree's frame.
const RELATIVE: i64 = 1;
/// `insertVoxelsIntoOctree` option bit 1: one colour per point.
const PER_POINT_COLORS: i64 = 2;
/// `insertVoxelsIntoOctree` option bit 2: one tag per point.
const PER_POINT_TAGS: i64 = 4;
/// PyRep's voxel size in its octree tests, m.
const VOXEL: f64 = 0.025;

/// `box`: a 10 cm cube centred half a voxel (of 2.5 cm) off the grid of an octree at
/// x = 0.5, so its faces lie mid-voxel rather than on voxel boundaries.
const SCENE: &str = r#"
[[object]]
name = "base"
kind = "dummy"
position = [1.0, 2.0, 0.5]

[[object]]
name = "box"
kind = "shape"
shape = "box"
size = [0.1, 0.1, 0.1]
position = [0.5125, 0.0125, 0.0125]

[[object]]
name = "far"
kind = "shape"
shape = "box"
size = [0.1, 0.1, 0.1]
position = [5.0, 5.0, 5.0]
"#;

fn sim() -> Sim {
    util::text_scene("octrees.toml", SCENE)
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

fn ints(v: &[i64]) -> Value {
    Value::Array(v.iter().map(|&b| Value::Int(b)).collect())
}

fn create(s: &mut Sim, voxel: f64) -> Handle {
    int(&ok(s, "createOctree", &[f(voxel), i(0), f(1.0)])[0])
}

fn insert(s: &mut Sim, o: Handle, options: i64, pts: &[f64], extra: &[Value]) -> i64 {
    let mut args = vec![h(o), i(options), list(pts)];
    args.extend_from_slice(extra);
    int(&ok(s, "insertVoxelsIntoOctree", &args)[0])
}

fn voxels(s: &mut Sim, o: Handle) -> Vec<f64> {
    floats(&ok(s, "getOctreeVoxels", &[h(o)])[0])
}

/// `checkOctreePointOccupancy`'s result and tag.
fn occupancy(s: &mut Sim, o: Handle, options: i64, pts: &[f64]) -> (i64, i64) {
    let r = ok(s, "checkOctreePointOccupancy", &[h(o), i(options), list(pts)]);
    (int(&r[0]), int(&r[1]))
}

fn find(s: &Sim, path: &str) -> Handle {
    util::find(s, path)
}

#[test]
fn created_octree_is_an_object_of_the_tree() {
    let mut s = sim();
    let o = create(&mut s, VOXEL);
    let octree_type = MODULES[0]
        .constants
        .iter()
        .find(|(n, _)| *n == "object_octree_type")
        .map(|(_, v)| *v);
    assert_eq!(octree_type, Some(15));
    assert_eq!(int(&ok(&mut s, "getObjectType", &[h(o)])[0]), 15);
    assert_eq!(ok(&mut s, "getObjectAlias", &[h(o)])[0], Value::Str("Octree".into()));
    assert_eq!(int(&ok(&mut s, "getObjectParent", &[h(o)])[0]), -1);
    // Parented under a dummy, it is in that dummy's tree and follows it.
    let base = find(&s, "/base");
    ok(&mut s, "setObjectParent", &[h(o), h(base), Value::Bool(false)]);
    let tree = ok(&mut s, "getObjectsInTree", &[h(base), i(-2), i(0)]);
    assert!(
        matches!(&tree[0], Value::Array(a) if a.contains(&Value::Int(o))),
        "{tree:?}"
    );
    assert!(voxels(&mut s, o).is_empty());
    ok(&mut s, "removeObject", &[h(o)]);
    assert!(!s.world.handles().contains(&o));
    assert!(matches!(
        err(&mut s, "getOctreeVoxels", &[h(o)]).0,
        Some(SimError::NoSuchObject(_))
    ));
}

#[test]
fn a_point_fills_one_to_eight_voxels_and_is_removed_again() {
    let mut s = sim();
    let o = create(&mut s, VOXEL);
    // At the origin, a corner of 8 voxels: all of them, as in CoppeliaSim.
    assert_eq!(insert(&mut s, o, 0, &[0.0, 0.0, 0.0], &[]), 8);
    let v = voxels(&mut s, o);
    assert_eq!(v.len(), 24);
    assert!(v.iter().all(|c| (c.abs() - VOXEL / 2.0).abs() < 1e-12), "{v:?}");
    assert_eq!(occupancy(&mut s, o, 0, &[0.0, 0.0, 0.0]).0, 1);
    assert_eq!(occupancy(&mut s, o, 0, &[0.01, -0.02, 0.02]).0, 1);
    assert_eq!(occupancy(&mut s, o, 0, &[0.03, 0.0, 0.0]).0, 0);
    assert_eq!(
        int(&ok(&mut s, "removeVoxelsFromOctree", &[h(o), i(0), list(&[0.0; 3])])[0]),
        0
    );
    assert!(voxels(&mut s, o).is_empty());
    assert_eq!(occupancy(&mut s, o, 0, &[0.0, 0.0, 0.0]).0, 0);
    // Inside a voxel: that voxel only, reported by its centre. Another point in the
    // same voxel adds nothing.
    assert_eq!(insert(&mut s, o, 0, &[0.03, 0.06, -0.01], &[]), 1);
    assert_eq!(insert(&mut s, o, 0, &[0.04, 0.07, -0.02], &[]), 1);
    assert_close(&voxels(&mut s, o), &[0.0375, 0.0625, -0.0125], 1e-12);
    // On a face: the two voxels sharing it.
    assert_eq!(insert(&mut s, o, 0, &[0.21, 0.21, 0.2], &[]), 3);
}

#[test]
fn world_frame_points_are_stored_relative_to_a_moved_rotated_octree() {
    let mut s = sim();
    let o = create(&mut s, VOXEL);
    ok(&mut s, "setObjectPosition", &[h(o), i(-1), list(&[1.0, 0.0, 0.0])]);
    ok(
        &mut s,
        "setObjectOrientation",
        &[h(o), i(-1), list(&[0.0, 0.0, FRAC_PI_2])],
    );
    // World (1.01, 0.03, 0.01) is (0.03, -0.01, 0.01) in the octree's frame.
    assert_eq!(insert(&mut s, o, 0, &[1.01, 0.03, 0.01], &[]), 1);
    assert_close(&voxels(&mut s, o), &[0.0375, -0.0125, 0.0125], 1e-12);
    // The same point given in the octree's frame (option bit 0) is in that voxel.
    assert_eq!(occupancy(&mut s, o, RELATIVE, &[0.03, -0.01, 0.01]).0, 1);
    assert_eq!(occupancy(&mut s, o, 0, &[0.03, -0.01, 0.01]).0, 0);
    // The voxels follow the octree: moved back to the origin, the world point is free.
    ok(&mut s, "setObjectPosition", &[h(o), i(-1), list(&[0.0, 0.0, 0.0])]);
    assert_eq!(occupancy(&mut s, o, 0, &[1.01, 0.03, 0.01]).0, 0);
    assert_eq!(occupancy(&mut s, o, 0, &[0.01, 0.03, 0.01]).0, 1);
    // Removal takes the octree's frame too.
    let r = ok(
        &mut s,
        "removeVoxelsFromOctree",
        &[h(o), i(RELATIVE), list(&[0.03, -0.01, 0.01])],
    );
    assert_eq!(int(&r[0]), 0);
}

#[test]
fn colours_and_tags_are_kept_per_voxel_and_occupancy_reports_the_tag() {
    let mut s = sim();
    let o = create(&mut s, 0.1);
    let pts = [0.05, 0.05, 0.05, 0.25, 0.05, 0.05];
    let colors = ints(&[255, 0, 0, 0, 255, 0]);
    let total = insert(
        &mut s,
        o,
        PER_POINT_COLORS | PER_POINT_TAGS,
        &pts,
        &[colors, ints(&[11, 22])],
    );
    assert_eq!(total, 2);
    assert_eq!(occupancy(&mut s, o, 0, &[0.26, 0.01, 0.01]), (1, 22));
    assert_eq!(occupancy(&mut s, o, 0, &[0.01, 0.01, 0.01]), (1, 11));
    // Several points: occupied when any is (CoppeliaSim's rule); no single tag.
    assert_eq!(occupancy(&mut s, o, 0, &[5.0, 5.0, 5.0, 0.01, 0.01, 0.01]), (1, 0));
    assert_eq!(occupancy(&mut s, o, 0, &[5.0, 5.0, 5.0, -0.01, 0.01, 0.01]), (0, 0));
    // One colour and tag for all, replacing those of an occupied voxel.
    insert(&mut s, o, 0, &[0.05, 0.05, 0.05], &[ints(&[1, 2, 3]), ints(&[7])]);
    let ObjectKind::Octree(octree) = &s.world.object(o).expect("octree").kind else {
        panic!("not an octree");
    };
    let stored: Vec<([u8; 3], u32)> = octree.voxels().map(|(_, v)| (v.color, v.tag)).collect();
    assert_eq!(stored, [([1, 2, 3], 7), ([0, 255, 0], 22)]);
}

/// The voxel indices of an octree's centres, per axis, for an octree of `voxel` m.
fn indices(centres: &[f64], voxel: f64) -> Vec<[i64; 3]> {
    centres
        .chunks_exact(3)
        .map(|c| [0, 1, 2].map(|a| (c[a] / voxel - 0.5).round() as i64))
        .collect()
}

#[test]
fn a_box_shape_fills_the_voxels_of_its_surface_and_is_subtracted_again() {
    let mut s = sim();
    let o = create(&mut s, VOXEL);
    ok(&mut s, "setObjectPosition", &[h(o), i(-1), list(&[0.5, 0.0, 0.0])]);
    let bx = find(&s, "/box");
    // In the octree's frame the box spans -0.0375..0.0625 on each axis: voxels -2..=2,
    // 5 per axis, and its surface touches the shell of that 5x5x5 block (125 - 27).
    let total = int(&ok(
        &mut s,
        "insertObjectIntoOctree",
        &[h(o), h(bx), i(0), ints(&[0, 0, 255]), i(9)],
    )[0]);
    assert_eq!(total, 98);
    let idx = indices(&voxels(&mut s, o), VOXEL);
    assert!(
        idx.iter()
            .all(|k| k.iter().all(|&n| (-2..=2).contains(&n)) && k.iter().any(|&n| n == -2 || n == 2)),
        "{idx:?}"
    );
    // The inside is not filled (as in CoppeliaSim); the surface carries the tag.
    assert_eq!(occupancy(&mut s, o, 0, &[0.5125, 0.0125, 0.0125]), (0, 0));
    assert_eq!(occupancy(&mut s, o, 0, &[0.5625, 0.0125, 0.0125]), (1, 9));
    // A voxel away from the box stays after the subtraction; every voxel the box
    // touches goes.
    insert(&mut s, o, 0, &[1.51, 1.51, 1.51], &[]);
    let left = int(&ok(&mut s, "subtractObjectFromOctree", &[h(o), h(bx), i(0)])[0]);
    assert_eq!(left, 1);
    assert_eq!(occupancy(&mut s, o, 0, &[1.51, 1.51, 1.51]).0, 1);
    // Subtracting a shape that touches nothing changes nothing.
    let far = find(&s, "/far");
    assert_eq!(
        int(&ok(&mut s, "subtractObjectFromOctree", &[h(o), h(far), i(0)])[0]),
        1
    );
    // Inserting it again, then clearing with nil points.
    ok(&mut s, "insertObjectIntoOctree", &[h(o), h(bx), i(0)]);
    assert_eq!(
        int(&ok(&mut s, "removeVoxelsFromOctree", &[h(o), i(0), Value::Nil])[0]),
        0
    );
    assert!(voxels(&mut s, o).is_empty());
}

#[test]
fn a_rotated_shape_is_voxelised_in_the_octrees_frame() {
    let mut s = sim();
    let bx = find(&s, "/box");
    // Turned 45 degrees about z, the 10 cm box spans about 14 cm across in x and y.
    ok(
        &mut s,
        "setObjectOrientation",
        &[h(bx), i(-1), list(&[0.0, 0.0, FRAC_PI_2 / 2.0])],
    );
    let o = create(&mut s, 0.01);
    // Centred on the box in x and y; 5 mm lower, so no face lies on a voxel boundary.
    ok(
        &mut s,
        "setObjectPosition",
        &[h(o), i(-1), list(&[0.5125, 0.0125, 0.0175])],
    );
    let total = int(&ok(&mut s, "insertObjectIntoOctree", &[h(o), h(bx), i(0)])[0]);
    let idx = indices(&voxels(&mut s, o), 0.01);
    let span = |a: usize| {
        let (lo, hi) = (idx.iter().map(|k| k[a]).min(), idx.iter().map(|k| k[a]).max());
        hi.zip(lo).map(|(hi, lo)| hi - lo + 1)
    };
    // x: -0.0707..0.0707 is voxels -8..=7; z: -0.055..0.045 is voxels -6..=4.
    assert_eq!(span(0), Some(16));
    assert_eq!(span(1), Some(16));
    assert_eq!(span(2), Some(11));
    // Surface area 0.06 m² over 1 cm voxels: some 600 to 1500 voxels.
    assert!((600..1500).contains(&total), "{total} voxels");
    assert_eq!(int(&ok(&mut s, "subtractObjectFromOctree", &[h(o), h(bx), i(0)])[0]), 0);
}

#[test]
fn a_point_cloud_inserts_and_subtracts_its_points() {
    let mut s = sim();
    let o = create(&mut s, 0.1);
    let c = int(&ok(&mut s, "createPointCloud", &[f(0.01), i(10), i(0), f(2.0)])[0]);
    ok(&mut s, "setObjectPosition", &[h(c), i(-1), list(&[1.0, 0.0, 0.0])]);
    let pts = list(&[0.05, 0.05, 0.05, 0.07, 0.05, 0.05, 0.35, 0.05, 0.05]);
    ok(&mut s, "insertPointsIntoPointCloud", &[h(c), i(1), pts]);
    assert_eq!(int(&ok(&mut s, "insertObjectIntoOctree", &[h(o), h(c), i(0)])[0]), 2);
    assert_close(&voxels(&mut s, o), &[1.05, 0.05, 0.05, 1.35, 0.05, 0.05], 1e-9);
    assert_eq!(int(&ok(&mut s, "subtractObjectFromOctree", &[h(o), h(c), i(0)])[0]), 0);
}

#[test]
fn too_many_voxels_are_refused_and_change_nothing() {
    let mut s = sim();
    let o = create(&mut s, 0.0001);
    insert(&mut s, o, RELATIVE, &[0.00005, 0.00005, 0.00005], &[]);
    // A 10 cm box's surface against 0.1 mm voxels: about 6 million voxels.
    let bx = find(&s, "/box");
    let (kind, msg) = err(&mut s, "insertObjectIntoOctree", &[h(o), h(bx), i(0)]);
    assert!(matches!(kind, Some(SimError::Refused(_))), "{kind:?}");
    assert!(msg.contains(&MAX_OCTREE_VOXELS.to_string()), "{msg}");
    assert_eq!(voxels(&mut s, o).len(), 3);
}

#[test]
fn bad_input_is_an_error() {
    let mut s = sim();
    for size in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        let (kind, msg) = err(&mut s, "createOctree", &[f(size), i(0), f(1.0)]);
        assert!(matches!(kind, Some(SimError::BadArgument(_))), "{size}: {kind:?}");
        assert!(msg.contains("argument 1"), "{msg}");
    }
    let o = create(&mut s, VOXEL);
    let (_, msg) = err(&mut s, "insertVoxelsIntoOctree", &[h(o), i(0), list(&[0.0; 4])]);
    assert!(msg.contains("3 numbers per point"), "{msg}");
    let (_, msg) = err(
        &mut s,
        "insertVoxelsIntoOctree",
        &[h(o), i(0), list(&[0.0, f64::NAN, 0.0])],
    );
    assert!(msg.contains("finite"), "{msg}");
    let (_, msg) = err(&mut s, "insertVoxelsIntoOctree", &[h(o), i(0), Value::Nil]);
    assert!(msg.contains("argument 3"), "{msg}");
    let (_, msg) = err(
        &mut s,
        "insertVoxelsIntoOctree",
        &[h(o), i(0), list(&[1e300, 0.0, 0.0])],
    );
    assert!(msg.contains("too far"), "{msg}");
    let (_, msg) = err(
        &mut s,
        "insertVoxelsIntoOctree",
        &[h(o), i(PER_POINT_COLORS), list(&[0.0; 6]), ints(&[1, 2, 3])],
    );
    assert!(msg.contains("at least 6 colour values"), "{msg}");
    let (_, msg) = err(
        &mut s,
        "insertVoxelsIntoOctree",
        &[h(o), i(0), list(&[0.0; 3]), Value::Nil, ints(&[-1])],
    );
    assert!(msg.contains("tag"), "{msg}");
    let (_, msg) = err(&mut s, "checkOctreePointOccupancy", &[h(o), i(0), list(&[])]);
    assert!(msg.contains("at least one point"), "{msg}");
    // Nothing was inserted by the failed calls.
    assert!(voxels(&mut s, o).is_empty());
    // Not an octree, no such object, not insertable, itself.
    let base = find(&s, "/base");
    for name in ["getOctreeVoxels", "insertVoxelsIntoOctree", "checkOctreePointOccupancy"] {
        let (kind, _) = err(&mut s, name, &[h(base), i(0), list(&[0.0; 3])]);
        assert!(matches!(kind, Some(SimError::WrongKind { .. })), "{name}: {kind:?}");
    }
    assert!(matches!(
        err(&mut s, "getOctreeVoxels", &[h(9999)]).0,
        Some(SimError::NoSuchObject(_))
    ));
    let (_, msg) = err(&mut s, "insertObjectIntoOctree", &[h(o), h(base), i(0)]);
    assert!(msg.contains("only shapes and point clouds"), "{msg}");
    let (_, msg) = err(&mut s, "subtractObjectFromOctree", &[h(o), h(o), i(0)]);
    assert!(msg.contains("itself"), "{msg}");
    assert!(matches!(
        err(&mut s, "insertObjectIntoOctree", &[h(o), h(9999), i(0)]).0,
        Some(SimError::NoSuchObject(_))
    ));
}

#[test]
fn octrees_collide_with_shapes_and_octrees_voxel_by_voxel() {
    let mut s = sim();
    let bx = find(&s, "/box");
    let o = create(&mut s, VOXEL);
    // One voxel, 0.55..0.575 in x, across the box's +x face (the box spans
    // 0.4625..0.5625 in x).
    insert(&mut s, o, 0, &[0.56, 0.01, 0.01], &[]);
    let hit = |s: &mut Sim, x: Handle, y: Handle| {
        let r = ok(s, "checkCollision", &[h(x), h(y)]);
        (int(&r[0]), r[1].clone())
    };
    assert_eq!(hit(&mut s, o, bx), (1, ints(&[o, bx])));
    assert_eq!(hit(&mut s, bx, o), (1, ints(&[bx, o])));
    // Moved 10 cm along x, the voxel (then 0.65..0.675) misses the box.
    ok(&mut s, "setObjectPosition", &[h(o), i(-1), list(&[0.1, 0.0, 0.0])]);
    assert_eq!(hit(&mut s, o, bx).0, 0);
    // Two octrees overlap where their voxels do, whatever their voxel sizes.
    let o2 = create(&mut s, 0.1);
    insert(&mut s, o2, 0, &[0.67, 0.05, 0.05], &[]);
    assert_eq!(hit(&mut s, o, o2), (1, ints(&[o, o2])));
    ok(&mut s, "setObjectPosition", &[h(o2), i(-1), list(&[0.0, 0.3, 0.0])]);
    assert_eq!(hit(&mut s, o, o2).0, 0);
    // An empty octree collides with nothing.
    ok(&mut s, "removeVoxelsFromOctree", &[h(o), i(0), Value::Nil]);
    ok(&mut s, "setObjectPosition", &[h(o), i(-1), list(&[0.0, 0.0, 0.0])]);
    assert_eq!(hit(&mut s, o, bx).0, 0);
}

#[test]
fn distances_from_an_octree_to_shapes_and_dummies() {
    let mut s = sim();
    let o = create(&mut s, 0.1);
    // One voxel, the cube 0..0.1 on every axis.
    insert(&mut s, o, 0, &[0.05, 0.05, 0.05], &[]);
    let dist = |s: &mut Sim, x: Handle, y: Handle| {
        let r = ok(s, "checkDistance", &[h(x), h(y)]);
        assert_eq!(int(&r[0]), 1);
        (floats(&r[1]), r[2].clone())
    };
    // The dummy at (1, 2, 0.5): nearest the voxel's corner (0.1, 0.1, 0.1).
    let base = find(&s, "/base");
    let (d, pair) = dist(&mut s, o, base);
    assert_close(
        &d,
        &[0.1, 0.1, 0.1, 1.0, 2.0, 0.5, (0.81f64 + 3.61 + 0.16).sqrt()],
        1e-5,
    );
    assert_eq!(pair, ints(&[o, base]));
    let (d, pair) = dist(&mut s, base, o);
    assert_close(
        &d,
        &[1.0, 2.0, 0.5, 0.1, 0.1, 0.1, (0.81f64 + 3.61 + 0.16).sqrt()],
        1e-5,
    );
    assert_eq!(pair, ints(&[base, o]));
    // The box `far` spans 4.95..5.05 on every axis: corner to corner.
    let far = find(&s, "/far");
    let (d, _) = dist(&mut s, o, far);
    assert_close(&d, &[0.1, 0.1, 0.1, 4.95, 4.95, 4.95, 4.85 * 3f64.sqrt()], 1e-4);
    // Below the threshold only.
    let r = ok(&mut s, "checkDistance", &[h(o), h(far), f(1.0)]);
    assert_eq!(int(&r[0]), 0);
}
