//! The long tail of V-REP / CoppeliaSim scene functions that public scripts call, run
//! from Lua as those scripts call them: named collections (`sim.createCollection(name,
//! options)`, `sim.getCollectionHandle`, `sim.getCollectionName`), compound shapes
//! (`sim.groupShapes`, `sim.ungroupShape`), shape information (`sim.getShapeGeomInfo`,
//! `sim.getShapeInertia`, `sim.getShapeMassAndInertia`), graph curves, the contacts of
//! the last step (`sim.getContactInfo`) and the light functions' refusals of objects
//! that are not lights.

use crate::util;

use gantry_sim_core::Value;
use gantry_test_support::{assert_close, assert_contains, floats, int, ints, num, text};
use util::Scene;

/// Two 0.2 m cubes of 1 kg on the X axis (`a` at x = 0, `b` at x = 1), a 0.2 × 0.4 ×
/// 0.6 m box of 6 kg at (0, 2, 0.5), a sphere and a graph.
const SCENE: &str = r#"
[[object]]
name = "holder"
kind = "dummy"
script = "probe.lua"

[[object]]
name = "a"
kind = "shape"
shape = "box"
size = [0.2, 0.2, 0.2]
mass = 1.0
position = [0, 0, 0.5]

[[object]]
name = "b"
kind = "shape"
shape = "box"
size = [0.2, 0.2, 0.2]
mass = 1.0
position = [1, 0, 0.5]

[[object]]
name = "brick"
kind = "shape"
shape = "box"
size = [0.2, 0.4, 0.6]
mass = 6.0
position = [0, 2, 0.5]

[[object]]
name = "ball"
kind = "shape"
shape = "sphere"
radius = 0.1
position = [0, -2, 0.5]

[[object]]
name = "graph"
kind = "graph"
"#;

const PROBE: &str = r#"
function sysCall_init()
    a = sim.getObject('/a')
    b = sim.getObject('/b')
    brick = sim.getObject('/brick')
    ball = sim.getObject('/ball')
    holder = sim.getObject('/holder')
    graph = sim.getObject('/graph')
    xs = sim.addGraphStream(graph, 'x', 'm')
    ys = sim.addGraphStream(graph, 'y', 'm')
    curve = sim.addGraphCurve(graph, 'xy', 2, {xs, ys}, {0, -1}, 'm', 0, {0, 1, 0}, 3)
    n = 0
end

-- Step n sets x = n and y = 10 n, except that y is missing at step 2.
function sysCall_sensing()
    n = n + 1
    sim.setGraphStreamValue(graph, xs, n)
    if n ~= 2 then sim.setGraphStreamValue(graph, ys, 10 * n) end
    sim.handleGraph(graph, sim.getSimulationTime() + sim.getSimulationTimeStep())
end

function curves()
    local again = sim.addGraphCurve(graph, 'xy', 2, {xs, ys}, {0, -1}, 'm')
    local files = sim.exportGraphStreams('out')
    sim.resetGraph(graph)
    local times = sim.getGraphStreamValues(graph, xs)
    return curve, again == curve, files, #times
end

function curve_errors()
    return err(sim.addGraphCurve, graph, 'c', 4, {xs, ys}, {0, 0}, ''),
        err(sim.addGraphCurve, graph, 'c', 2, {xs, 777}, {0, 0}, ''),
        err(sim.addGraphCurve, graph, 'c', 2, {xs}, {0, 0}, ''),
        err(sim.addGraphCurve, holder, 'c', 2, {xs, ys}, {0, 0}, ''),
        err(sim.handleGraph, holder, 0), err(sim.resetGraph, brick)
end

function collections()
    local named = sim.createCollection('obstacles', 0)
    sim.addItemToCollection(named, sim.handle_single, brick, 0)
    local unnamed = sim.createCollection(0)
    return sim.getCollectionHandle('obstacles') == named, sim.getCollectionName(named),
        sim.getCollectionName(unnamed), sim.getCollectionHandle('nothing@silentError'),
        sim.getCollectionObjects(sim.getCollectionHandle('obstacles'))
end

function collection_errors()
    sim.createCollection('taken', 0)
    return err(sim.getCollectionHandle, 'nothing'), err(sim.createCollection, 'taken', 0),
        err(sim.getCollectionName, 12345), err(sim.getCollectionHandle, 7)
end

function geom_info()
    local r1, t1, d1 = sim.getShapeGeomInfo(brick)
    local r2, t2, d2 = sim.getShapeGeomInfo(ball)
    return r1, t1, d1, r2, t2, d2
end

function group()
    local g = sim.groupShapes({a, b})
    local gone = not pcall(sim.getObjectPosition, a, -1) and not pcall(sim.getObjectPosition, b, -1)
    local r, t = sim.getShapeGeomInfo(g)
    local inertia, frame = sim.getShapeInertia(g)
    return g, gone, sim.getObjectPosition(g, -1), sim.getShapeMass(g), sim.getShapeBB(g), r, t,
        inertia, frame, sim.getObject('/b') == g
end

function ungroup(g)
    local parts = sim.ungroupShape(g)
    local positions = {}
    for i, p in ipairs(parts) do
        local pos = sim.getObjectPosition(p, -1)
        positions[#positions + 1] = pos[1]
    end
    return #parts, positions, sim.getShapeMass(parts[1]), sim.getShapeGeomInfo(parts[1]),
        not pcall(sim.getObjectPosition, g, -1)
end

function group_errors()
    return err(sim.groupShapes, {brick}), err(sim.groupShapes, {brick, holder}),
        err(sim.groupShapes, {brick, brick}), err(sim.getShapeGeomInfo, holder),
        err(sim.getShapeInertia, holder), err(sim.ungroupShape, holder)
end

function inertia()
    local i, frame = sim.getShapeInertia(brick)
    local m, iPerKg, com = sim.getShapeMassAndInertia(brick)
    local m2, iWorld, comWorld = sim.getShapeMassAndInertia(brick, {1,0,0,0, 0,1,0,0, 0,0,1,0})
    local m3, iTurned = sim.getShapeMassAndInertia(brick, {0,-1,0,0, 1,0,0,0, 0,0,1,0})
    return i, frame, m, iPerKg, com, comWorld, iTurned
end

function lights()
    return err(sim.setLightParameters, holder, 1, nil, {1, 1, 1}, {1, 1, 1}),
        err(sim.getLightParameters, holder), err(sim.getLightParameters, 999999)
end
"#;

fn scene(tag: &str) -> Scene {
    Scene::probe(tag, SCENE, PROBE)
}

#[test]
fn a_named_collection_is_found_by_its_name() {
    let mut sc = scene("old-collections");
    let r = sc.call("collections", &[]);
    assert_eq!(
        r[0],
        Value::Bool(true),
        "getCollectionHandle finds the named collection"
    );
    assert_eq!(text(&r[1]), "obstacles");
    assert_eq!(text(&r[2]), "", "a 4.x collection has no name");
    assert_eq!(int(&r[3]), -1, "@silentError gives -1 for a missing collection");
    let brick = sc.find("/brick");
    assert_eq!(ints(&r[4]), vec![brick]);
}

#[test]
fn collection_lookups_fail_clearly() {
    let mut sc = scene("old-collection-errors");
    let r = sc.call("collection_errors", &[]);
    assert_contains(
        text(&r[0]),
        &["collection does not exist: 'nothing'", "sim.getCollectionHandle"],
    );
    assert_contains(text(&r[1]), &["'taken' already exists", "sim.createCollection"]);
    assert_contains(
        text(&r[2]),
        &["collection 12345 does not exist", "sim.getCollectionName"],
    );
    assert_contains(text(&r[3]), &["argument 1", "sim.getCollectionHandle"]);
}

#[test]
fn pure_shapes_report_their_primitive_and_dimensions() {
    let mut sc = scene("old-geom-info");
    let r = sc.call("geom_info", &[]);
    // Simple pure convex cuboid: bits 1 and 2, sim.primitiveshape_cuboid.
    assert_eq!(int(&r[0]), 0b110);
    assert_eq!(int(&r[1]), 3);
    assert_close(&floats(&r[2]), &[0.2, 0.4, 0.6, 1.0], 1e-12);
    // A sphere: sim.primitiveshape_spheroid with its diameter.
    assert_eq!(int(&r[3]), 0b110);
    assert_eq!(int(&r[4]), 4);
    assert_close(&floats(&r[5]), &[0.2, 0.2, 0.2, 1.0], 1e-12);
}

#[test]
fn grouping_shapes_makes_one_compound_in_the_last_shapes_frame() {
    let mut sc = scene("old-group");
    let r = sc.call("group", &[]);
    let g = int(&r[0]);
    assert_eq!(r[1], Value::Bool(true), "the grouped shapes are removed");
    assert_close(&floats(&r[2]), &[1.0, 0.0, 0.5], 1e-9);
    assert_close(&[num(&r[3])], &[2.0], 1e-9);
    // The parts keep their places: 1.2 m along X in the compound's frame.
    assert_close(&floats(&r[4]), &[1.2, 0.2, 0.2], 1e-9);
    // Compound, pure and convex parts; no primitive type for a compound.
    assert_eq!((int(&r[5]), int(&r[6])), (0b111, 0));
    // Two 1 kg cubes 1 m apart: the centre of mass halfway (x = -0.5 in the compound's
    // frame), Iyy = Izz = 2·(1·0.08/12) + 2·1·0.5², Ixx = 2·(1·0.08/12).
    let own = 2.0 * 0.08 / 12.0;
    let i = floats(&r[7]);
    assert_close(&i, &[own, 0.0, 0.0, 0.0, own + 0.5, 0.0, 0.0, 0.0, own + 0.5], 1e-9);
    assert_close(
        &floats(&r[8]),
        &[1.0, 0.0, 0.0, -0.5, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        1e-9,
    );
    assert_eq!(r[9], Value::Bool(true), "the compound keeps the last shape's alias");

    let u = sc.call("ungroup", &[Value::Int(g)]);
    assert_eq!(int(&u[0]), 2);
    assert_close(&floats(&u[1]), &[0.0, 1.0], 1e-9);
    assert_close(&[num(&u[2])], &[1.0], 1e-9);
    assert_eq!(int(&u[3]), 0b110, "each part is a simple shape again");
    assert_eq!(u[4], Value::Bool(true), "the compound is removed");
}

#[test]
fn grouping_refuses_bad_lists() {
    let mut sc = scene("old-group-errors");
    let r = sc.call("group_errors", &[]);
    assert_contains(text(&r[0]), &["at least 2 shapes", "sim.groupShapes"]);
    assert_contains(text(&r[1]), &["shape", "sim.groupShapes"]);
    assert_contains(text(&r[2]), &["listed twice", "sim.groupShapes"]);
    assert_contains(text(&r[3]), &["shape", "sim.getShapeGeomInfo"]);
    assert_contains(text(&r[4]), &["shape", "sim.getShapeInertia"]);
    assert_contains(text(&r[5]), &["shape", "sim.ungroupShape"]);
}

#[test]
fn inertia_is_about_the_centre_of_mass() {
    let mut sc = scene("old-inertia");
    let r = sc.call("inertia", &[]);
    // 6 kg box 0.2 × 0.4 × 0.6: Ixx = 6·(0.4² + 0.6²)/12, Iyy = 6·(0.2² + 0.6²)/12,
    // Izz = 6·(0.2² + 0.4²)/12.
    let (ixx, iyy, izz) = (0.26, 0.2, 0.1);
    assert_close(&floats(&r[0]), &[ixx, 0.0, 0.0, 0.0, iyy, 0.0, 0.0, 0.0, izz], 1e-9);
    assert_close(
        &floats(&r[1]),
        &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        1e-12,
    );
    // V-REP 3: mass, then the inertia divided by the mass, then the centre of mass.
    assert_close(&[num(&r[2])], &[6.0], 1e-9);
    assert_close(
        &floats(&r[3]),
        &[ixx / 6.0, 0.0, 0.0, 0.0, iyy / 6.0, 0.0, 0.0, 0.0, izz / 6.0],
        1e-9,
    );
    assert_close(&floats(&r[4]), &[0.0, 0.0, 0.0], 1e-12);
    // Relative to the world frame, the centre of mass is where the box is.
    assert_close(&floats(&r[5]), &[0.0, 2.0, 0.5], 1e-9);
    // In a frame turned 90° about Z, the X and Y moments swap.
    assert_close(
        &floats(&r[6]),
        &[iyy / 6.0, 0.0, 0.0, 0.0, ixx / 6.0, 0.0, 0.0, 0.0, izz / 6.0],
        1e-9,
    );
}

#[test]
fn a_graph_curve_pairs_its_streams_and_is_exported_with_them() {
    let mut sc = scene("old-curves");
    for _ in 0..3 {
        sc.sim.step();
    }
    let r = sc.call("curves", &[]);
    assert_eq!(r[1], Value::Bool(true), "re-adding a curve by name keeps its id");
    let files: Vec<String> = match &r[2] {
        Value::Array(v) => v.iter().map(|f| text(f).to_owned()).collect(),
        other => panic!("expected the exported files, got {other:?}"),
    };
    let curve_file = files
        .iter()
        .find(|f| f.ends_with("graph.xy.csv"))
        .unwrap_or_else(|| panic!("no curve file among {files:?}"));
    let csv = std::fs::read_to_string(curve_file).expect("the curve file is readable");
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("time,x [m],y [m]"));
    let points: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').skip(1).map(|v| v.parse().expect(l)).collect())
        .collect();
    // Step 2 has no y value: the curve's default (-1) stands in.
    assert_eq!(points, vec![vec![1.0, 10.0], vec![2.0, -1.0], vec![3.0, 30.0]]);
    assert_eq!(int(&r[3]), 0, "sim.resetGraph drops the recorded values");
}

#[test]
fn graph_curves_refuse_bad_arguments() {
    let mut sc = scene("old-curve-errors");
    let r = sc.call("curve_errors", &[]);
    assert_contains(text(&r[0]), &["dim must be 2", "sim.addGraphCurve"]);
    assert_contains(text(&r[1]), &["no stream with id 777", "sim.addGraphCurve"]);
    assert_contains(text(&r[2]), &["expected 2 stream ids", "sim.addGraphCurve"]);
    assert_contains(text(&r[3]), &["graph", "sim.addGraphCurve"]);
    assert_contains(text(&r[4]), &["graph", "sim.handleGraph"]);
    assert_contains(text(&r[5]), &["graph", "sim.resetGraph"]);
}

/// A 1 kg cube resting on a static floor whose top is at z = 0.
const RESTING: &str = r#"
[[object]]
name = "holder"
kind = "dummy"
script = "probe.lua"

[[object]]
name = "floor"
kind = "shape"
shape = "box"
size = [2, 2, 0.1]
position = [0, 0, -0.05]

[[object]]
name = "cube"
kind = "shape"
shape = "box"
size = [0.1, 0.1, 0.1]
mass = 1.0
dynamic = true
position = [0, 0, 0.05]
"#;

const CONTACT_PROBE: &str = r#"
function contacts()
    local cube = sim.getObject('/cube')
    local floor = sim.getObject('/floor')
    local fz, n, others, normalZ, pointZ = 0, 0, true, 0, 0
    while true do
        local objs, pt, force, normal = sim.getContactInfo(sim.handle_all, cube, n)
        if not objs then break end
        others = others and objs[1] == cube and objs[2] == floor
        fz = fz + force[3]
        normalZ = normal[3]
        pointZ = math.max(pointZ, math.abs(pt[3]))
        n = n + 1
    end
    local none = sim.getContactInfo(sim.handle_all, sim.getObject('/holder'), 0)
    return n, others, fz, normalZ, pointZ, none == nil
end

function contact_errors()
    local cube = sim.getObject('/cube')
    return err(sim.getContactInfo, 3, cube, 0), err(sim.getContactInfo, sim.handle_all, cube, -1),
        err(sim.getContactInfo, sim.handle_all, 4242, 0)
end
"#;

#[test]
fn contact_info_lists_the_last_steps_contacts_of_an_object() {
    let mut sc = Scene::probe("old-contacts", RESTING, CONTACT_PROBE);
    for _ in 0..40 {
        sc.sim.step();
    }
    let r = sc.call("contacts", &[]);
    assert!(int(&r[0]) >= 1, "the resting cube touches the floor: {r:?}");
    assert_eq!(
        r[1],
        Value::Bool(true),
        "the cube asked for comes first, then the floor"
    );
    // At rest the floor carries the cube's weight: 1 kg · 9.81 m/s² upwards.
    assert_close(&[num(&r[2])], &[9.81], 0.3);
    // The normal points from the cube down into the floor; contacts lie on its top.
    assert_close(&[num(&r[3])], &[-1.0], 1e-3);
    assert!(num(&r[4]) < 0.01, "contact points lie at z = 0: {r:?}");
    assert_eq!(r[5], Value::Bool(true), "nil past the last contact");

    let e = sc.call("contact_errors", &[]);
    assert_contains(text(&e[0]), &["dynamicPass", "sim.getContactInfo"]);
    assert_contains(text(&e[1]), &["index must be 0 or more", "sim.getContactInfo"]);
    assert_contains(text(&e[2]), &["does not exist", "sim.getContactInfo"]);
}

#[test]
fn light_functions_refuse_objects_that_are_not_lights() {
    let mut sc = scene("old-lights");
    let r = sc.call("lights", &[]);
    assert_contains(text(&r[0]), &["not a light", "sim.setLightParameters"]);
    assert_contains(text(&r[1]), &["not a light", "sim.getLightParameters"]);
    assert_contains(text(&r[2]), &["does not exist", "sim.getLightParameters"]);
}

#[test]
fn remote_clients_get_the_same_shape_information() {
    let mut sc = scene("old-remote");
    let brick = sc.find("/brick");
    let r = sc.remote("getShapeGeomInfo", &[Value::Int(brick)]);
    assert_eq!((int(&r[0]), int(&r[1])), (0b110, 3));
    let r = sc.remote("getShapeMassAndInertia", &[Value::Int(brick)]);
    assert_close(&[num(&r[0])], &[6.0], 1e-9);
}
