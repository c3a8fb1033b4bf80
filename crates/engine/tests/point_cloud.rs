//! Point clouds from Lua, end to end: CoppeliaSim's snippet (`sim.createPointCloud`,
//! `sim.setObjectName` with `sim.handleflag_silenterror`, `sim.setObjectQuaternion`,
//! `sim.insertPointsIntoPointCloud`) in `sysCall_init`, world-frame insertions from a
//! moving cloud during the steps, errors raised in Lua, and the same points for a
//! remote client.

use crate::util;

use gantry_sim_core::Value;
use gantry_test_support::{assert_close, assert_contains, floats, int, num, text};
use util::Scene;

const SCENE: &str = r#"
[[object]]
name = "robot"
kind = "dummy"
script = "probe.lua"
"#;

/// The snippet, then a second cloud that moves 0.1 m along world X each step and gets,
/// each step, the world point (1, 0, 0) in a colour of its own.
const PROBE: &str = r#"
function sysCall_init()
    cloudHandle=sim.createPointCloud(0.01, 10, 0, 10)
    sim.setObjectName(cloudHandle+sim.handleflag_silenterror,'cloud')
    sim.setObjectQuaternion(cloudHandle,-1,{0,0,0,1})
    local pts = {}
    for k=0,9 do
        pts[#pts+1]=0.1*k; pts[#pts+1]=0.2; pts[#pts+1]=0.3
    end
    total = sim.insertPointsIntoPointCloud(cloudHandle, 1, pts, {255, 128, 0})
    -- A duplicate of the first point within 5 mm is not inserted; a far one is.
    total2 = sim.insertPointsIntoPointCloud(cloudHandle, 1, {0.001,0.2,0.3, 5,5,5}, nil, 0.005)

    mover = sim.createPointCloud(0.05, 20, 0, 4)
    sim.setObjectAlias(mover, 'mover')
    steps = 0
end

function sysCall_actuation()
    steps = steps + 1
    sim.setObjectPosition(mover, -1, {0.1*steps, 0, 0})
    sim.insertPointsIntoPointCloud(mover, 2, {1, 0, 0}, {steps, 0, 0})
end

function state()
    return total, total2, sim.getObjectType(cloudHandle) == sim.object_pointcloud_type,
        sim.getObject('/cloud') == cloudHandle, sim.getPointCloudPoints(cloudHandle),
        {sim.getPointCloudOptions(cloudHandle)}, sim.getPointCloudPoints(mover), steps
end

function errors()
    return err(sim.insertPointsIntoPointCloud, cloudHandle, 0, {1, 2}),
        err(sim.insertPointsIntoPointCloud, sim.getObject('/robot'), 0, {1, 2, 3}),
        err(sim.insertPointsIntoPointCloud, cloudHandle, 2, {1,2,3, 4,5,6}, {255, 0, 0}),
        err(sim.createPointCloud, -1, 10, 0, 2)
end

function clear()
    return sim.removePointsFromPointCloud(cloudHandle, 0, nil, 0), #sim.getPointCloudPoints(cloudHandle)
end
"#;

fn scene(tag: &str) -> Scene {
    Scene::probe(tag, SCENE, PROBE)
}

#[test]
fn coppeliasims_snippet_runs_and_points_read_back() {
    let mut sc = scene("pc-snippet");
    let r = sc.call("state", &[]);
    assert_eq!(int(&r[0]), 10, "insertPointsIntoPointCloud returns the total");
    assert_eq!(int(&r[1]), 11, "the duplicate was skipped, the far point inserted");
    assert_eq!((r[2].clone(), r[3].clone()), (Value::Bool(true), Value::Bool(true)));
    let mut expected: Vec<f64> = (0..10).flat_map(|k| [0.1 * f64::from(k), 0.2, 0.3]).collect();
    expected.extend([5.0, 5.0, 5.0]);
    assert_close(&floats(&r[4]), &expected, 1e-12);
    let options = floats(&r[5]);
    assert_close(&options, &[0.01, 10.0, 0.0, 8.0], 1e-12);

    // A remote client reads the same points.
    let cloud = sc.find("/cloud");
    let remote = sc.remote("getPointCloudPoints", &[Value::Int(cloud)]);
    assert_close(&floats(&remote[0]), &expected, 1e-12);
}

#[test]
fn world_points_follow_the_moving_cloud() {
    let mut sc = scene("pc-moving");
    for _ in 0..3 {
        sc.sim.step();
    }
    let r = sc.call("state", &[]);
    assert_eq!(int(&r[7]), 3);
    // At step k the cloud is at x = 0.1 k, so world (1, 0, 0) is stored at 1 - 0.1 k.
    assert_close(&floats(&r[6]), &[0.9, 0.0, 0.0, 0.8, 0.0, 0.0, 0.7, 0.0, 0.0], 1e-12);
    let mover = sc.find("/mover");
    let world = sc.sim.world();
    let gantry_sim_core::world::ObjectKind::PointCloud(cloud) = &world.object(mover).expect("mover").kind else {
        panic!("/mover is not a point cloud");
    };
    assert_eq!(cloud.colors(), [[1, 0, 0], [2, 0, 0], [3, 0, 0]]);
}

#[test]
fn errors_reach_lua_with_the_function_name() {
    let mut sc = scene("pc-errors");
    let r = sc.call("errors", &[]);
    assert_contains(
        text(&r[0]),
        &["3 numbers per point", "(in function 'sim.insertPointsIntoPointCloud')"],
    );
    assert_contains(text(&r[1]), &["is a dummy, not a point cloud"]);
    assert_contains(text(&r[2]), &["at least 6 colour values"]);
    assert_contains(text(&r[3]), &["max voxel size", "(in function 'sim.createPointCloud')"]);

    let r = sc.call("clear", &[]);
    assert_eq!((int(&r[0]), num(&r[1])), (0, 0.0));
}
