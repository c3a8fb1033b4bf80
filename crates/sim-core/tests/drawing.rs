//! Drawing objects and graph streams through the API, on the BubbleRob scene: the seed
//! controller's exact calls, frames, limits, CSV export and bad arguments.

use crate::util;

use std::path::PathBuf;

use gantry_sim_core::drawing::{FIRST_DRAWING_HANDLE, HANDLEFLAG_ADD_MULTIPLE};
use gantry_sim_core::graph::MAX_STREAM_SAMPLES;
use gantry_sim_core::{Handle, Sim, Value};
use gantry_test_support::{assert_close, floats, int};
use util::{err, find, ok};

// sim.* constants the seed uses.
const DRAWING_LINES: i64 = 1;
const DRAWING_POINTS: i64 = 0;
const DRAWING_LINESTRIP: i64 = 8;
const DRAWING_CYCLIC: i64 = 0x1000;
const DRAWING_LOCAL: i64 = 0x80_0000;
const HANDLE_ALL: i64 = -2;
const HANDLE_TREE: i64 = -6;

fn world() -> Sim {
    util::asset_scene("scenes/bubble_rob.toml")
}

fn h(v: Handle) -> Value {
    Value::Int(v)
}

fn f(v: f64) -> Value {
    Value::Float(v)
}

fn v3(x: f64, y: f64, z: f64) -> Value {
    Value::floats(&[x, y, z])
}

/// `sim.getDrawingObjectItems(h)` → (type, size, color, world-frame vertex floats).
fn items(w: &mut Sim, d: Handle) -> (i64, f64, Vec<f64>, Vec<f64>) {
    let r = ok(w, "getDrawingObjectItems", &[h(d)]);
    (int(&r[0]), r[1].as_f64().expect("size"), floats(&r[2]), floats(&r[3]))
}

fn add_item(w: &mut Sim, d: Handle, data: Value) -> i64 {
    int(&ok(w, "addDrawingObjectItem", &[h(d), data])[0])
}

/// A fresh directory under the system temp dir, removed first if a previous run left it.
fn temp_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("gantry-drawing-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn seed_distance_segment_keeps_one_green_line() {
    let mut w = world();
    let base = find(&w, "/bubbleRob");
    // distanceSegment=sim.addDrawingObject(sim.drawing_lines,4,0,-1,1,{0,1,0})
    let seg = int(&ok(
        &mut w,
        "addDrawingObject",
        &[
            Value::Int(DRAWING_LINES),
            f(4.0),
            f(0.0),
            h(-1),
            Value::Int(1),
            v3(0.0, 1.0, 0.0),
        ],
    )[0]);
    assert!(seg >= FIRST_DRAWING_HANDLE);
    let coll = int(&ok(&mut w, "createCollection", &[Value::Int(0)])[0]);
    ok(
        &mut w,
        "addItemToCollection",
        &[h(coll), h(HANDLE_TREE), h(base), Value::Int(0)],
    );
    let r = ok(&mut w, "checkDistance", &[h(coll), h(HANDLE_ALL)]);
    assert_eq!(int(&r[0]), 1, "the robot sees an obstacle");
    let dist_data = r[1].clone();
    let d = floats(&dist_data);
    assert_eq!(d.len(), 7);
    // The seed's sensing: clear, then draw distData (7 numbers: the segment and the distance).
    for _ in 0..3 {
        assert_eq!(add_item(&mut w, seg, Value::Nil), 0, "clearing adds nothing");
        assert_eq!(add_item(&mut w, seg, dist_data.clone()), 1);
    }
    let (ty, size, color, verts) = items(&mut w, seg);
    assert_eq!((ty, size, color), (DRAWING_LINES, 4.0, vec![0.0, 1.0, 0.0]));
    assert_close(&verts, &d[..6], 1e-12);
    // Without a clear a second segment does not fit: refused, the first stays.
    assert_eq!(add_item(&mut w, seg, Value::floats(&[0.0, 0.0, 0.0, 1.0, 1.0, 1.0])), 0);
    assert_close(&items(&mut w, seg).3, &d[..6], 1e-12);
    // After a clear the new segment replaces it.
    add_item(&mut w, seg, Value::Nil);
    assert_eq!(add_item(&mut w, seg, Value::floats(&[0.0, 0.0, 0.0, 1.0, 1.0, 1.0])), 1);
    assert_eq!(items(&mut w, seg).3, [0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
}

#[test]
fn seed_trace_is_a_cyclic_strip_of_200_points() {
    let mut w = world();
    // robotTrace=sim.addDrawingObject(sim.drawing_linestrip+sim.drawing_cyclic,2,0,-1,200,{1,1,0},nil,nil,{1,1,0})
    let trace = int(&ok(
        &mut w,
        "addDrawingObject",
        &[
            Value::Int(DRAWING_LINESTRIP + DRAWING_CYCLIC),
            Value::Int(2),
            Value::Int(0),
            Value::Int(-1),
            Value::Int(200),
            v3(1.0, 1.0, 0.0),
            Value::Nil,
            Value::Nil,
            v3(1.0, 1.0, 0.0),
        ],
    )[0]);
    for i in 0..250 {
        assert_eq!(add_item(&mut w, trace, v3(f64::from(i) * 0.01, 0.0, 0.0)), 1);
    }
    let (ty, size, color, verts) = items(&mut w, trace);
    assert_eq!(ty, DRAWING_LINESTRIP | DRAWING_CYCLIC);
    assert_eq!((size, color), (2.0, vec![1.0, 1.0, 0.0]));
    assert_eq!(verts.len(), 200 * 3);
    // The 50 oldest points were dropped; the newest is last.
    assert!((verts[0] - 0.50).abs() < 1e-12, "first x {}", verts[0]);
    assert!((verts[597] - 2.49).abs() < 1e-12, "last x {}", verts[597]);
    let object = w.drawings.object(trace).expect("trace");
    assert_eq!(object.emission(), Some([1.0, 1.0, 0.0]));
    assert_eq!(object.item_count(), 200);
}

#[test]
fn seed_sensing_over_real_steps() {
    // The seed controller's sensing phase, every step for 15 s of simulated time.
    let mut w = world();
    let base = find(&w, "/bubbleRob");
    let graph = find(&w, "/bubbleRob/graph");
    let seg = int(&ok(
        &mut w,
        "addDrawingObject",
        &[
            Value::Int(DRAWING_LINES),
            f(4.0),
            f(0.0),
            h(-1),
            Value::Int(1),
            v3(0.0, 1.0, 0.0),
        ],
    )[0]);
    let trace = int(&ok(
        &mut w,
        "addDrawingObject",
        &[
            Value::Int(DRAWING_LINESTRIP + DRAWING_CYCLIC),
            f(2.0),
            f(0.0),
            h(-1),
            Value::Int(200),
            v3(1.0, 1.0, 0.0),
        ],
    )[0]);
    let stream = int(&ok(
        &mut w,
        "addGraphStream",
        &[
            h(graph),
            "bubbleRob clearance".into(),
            "m".into(),
            Value::Int(0),
            v3(1.0, 0.0, 0.0),
        ],
    )[0]);
    let coll = int(&ok(&mut w, "createCollection", &[Value::Int(0)])[0]);
    ok(
        &mut w,
        "addItemToCollection",
        &[h(coll), h(HANDLE_TREE), h(base), Value::Int(0)],
    );
    // Forward at the tutorial's initial speed, 3.054 rad/s.
    for motor in ["/bubbleRob/leftMotor", "/bubbleRob/rightMotor"] {
        let m = find(&w, motor);
        w.world.set_joint_target_velocity(m, 3.054).expect("joint");
    }
    let steps = 300;
    for _ in 0..steps {
        w.step_dynamics();
        let r = ok(&mut w, "checkDistance", &[h(coll), h(HANDLE_ALL)]);
        if int(&r[0]) > 0 {
            add_item(&mut w, seg, Value::Nil);
            add_item(&mut w, seg, r[1].clone());
            let d7 = floats(&r[1])[6];
            ok(&mut w, "setGraphStreamValue", &[h(graph), h(stream), f(d7)]);
        }
        let p = ok(&mut w, "getObjectPosition", &[h(base), h(-1)]).remove(0);
        add_item(&mut w, trace, p);
        w.finish_step();
    }
    assert_eq!(w.drawings.object(seg).expect("segment").item_count(), 1);
    assert_eq!(w.drawings.object(trace).expect("trace").item_count(), 200);
    let r = ok(&mut w, "getGraphStreamValues", &[h(graph), h(stream)]);
    let (times, values) = (floats(&r[0]), floats(&r[1]));
    assert_eq!(times.len(), steps, "one clearance sample per step");
    assert_eq!(values.len(), steps);
    assert!(values.iter().all(|v| *v > 0.0), "clearances are positive distances");
    // Stamped at each step's end, like CoppeliaSim's sim.handleGraph: dt, 2 dt, ...
    let dt = w.world.settings().dt;
    assert!((times[0] - dt).abs() < 1e-12 && (times[steps - 1] - dt * steps as f64).abs() < 1e-9);
    // The trace's newest point is where the robot is.
    let now = w.world.object(base).expect("base").world.translation.vector;
    let view = w
        .drawings
        .iter_world(&w.world)
        .find(|v| v.handle == trace)
        .expect("trace");
    let last = view.vertices().last().expect("points");
    assert!((last - now).norm() < 1e-12);
}

#[test]
fn duplicate_tolerance_applies_to_single_vertex_items() {
    let mut w = world();
    let pts = int(&ok(
        &mut w,
        "addDrawingObject",
        &[Value::Int(DRAWING_POINTS), f(3.0), f(0.01), h(-1), Value::Int(0)],
    )[0]);
    assert_eq!(add_item(&mut w, pts, v3(0.0, 0.0, 0.0)), 1);
    assert_eq!(add_item(&mut w, pts, v3(0.005, 0.0, 0.0)), 0, "within tolerance");
    assert_eq!(
        add_item(&mut w, pts, v3(0.0, 0.01, 0.0)),
        0,
        "the tolerance is inclusive"
    );
    assert_eq!(add_item(&mut w, pts, v3(0.02, 0.0, 0.0)), 1);
    assert_eq!(items(&mut w, pts).3.len(), 6);
    // Lines have two vertices per item: no duplicate check, as in CoppeliaSim.
    let lines = int(&ok(
        &mut w,
        "addDrawingObject",
        &[Value::Int(DRAWING_LINES), f(1.0), f(0.5), h(-1), Value::Int(0)],
    )[0]);
    let seg = Value::floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0]);
    assert_eq!(add_item(&mut w, lines, seg.clone()), 1);
    assert_eq!(add_item(&mut w, lines, seg), 1);
    // The default colour and item count (0 means 1000) apply.
    let object = w.drawings.object(lines).expect("lines");
    assert_eq!(object.max_items(), 1000);
    assert_eq!(object.color(), [0.5, 0.5, 0.5]);
}

#[test]
fn items_follow_their_parent() {
    let mut w = world();
    let base = find(&w, "/bubbleRob");
    let start = w.world.object(base).expect("base").world;
    // World coordinates with a parent: drawn where given, then carried along.
    let world_pts = int(&ok(
        &mut w,
        "addDrawingObject",
        &[Value::Int(DRAWING_POINTS), f(3.0), f(0.0), h(base), Value::Int(10)],
    )[0]);
    assert_eq!(add_item(&mut w, world_pts, v3(1.0, 2.0, 3.0)), 1);
    assert_close(&items(&mut w, world_pts).3, &[1.0, 2.0, 3.0], 1e-12);
    // Local coordinates: relative to the parent frame.
    let local_pts = int(&ok(
        &mut w,
        "addDrawingObject",
        &[
            Value::Int(DRAWING_POINTS | DRAWING_LOCAL),
            f(3.0),
            f(0.0),
            h(base),
            Value::Int(10),
        ],
    )[0]);
    assert_eq!(add_item(&mut w, local_pts, v3(0.1, 0.0, 0.0)), 1);
    let expected = start.transform_point(&nalgebra::Point3::new(0.1, 0.0, 0.0));
    assert_close(&items(&mut w, local_pts).3, expected.coords.as_slice(), 1e-12);
    // A world-fixed object does not move with anything.
    let fixed = int(&ok(
        &mut w,
        "addDrawingObject",
        &[Value::Int(DRAWING_POINTS), f(3.0), f(0.0), h(-1), Value::Int(10)],
    )[0]);
    add_item(&mut w, fixed, v3(1.0, 2.0, 3.0));
    // Move the robot by +0.5 m in y: both parented objects follow, the fixed one stays.
    let p = start.translation.vector;
    ok(&mut w, "setObjectPosition", &[h(base), v3(p.x, p.y + 0.5, p.z), h(-1)]);
    assert_close(&items(&mut w, world_pts).3, &[1.0, 2.5, 3.0], 1e-9);
    let moved = items(&mut w, local_pts).3;
    assert_close(&moved, &[expected.x, expected.y + 0.5, expected.z], 1e-9);
    assert_close(&items(&mut w, fixed).3, &[1.0, 2.0, 3.0], 0.0);
    // The Rust view agrees with the API, in creation order.
    let handles: Vec<Handle> = w.drawings.iter_world(&w.world).map(|v| v.handle).collect();
    assert_eq!(handles, [world_pts, local_pts, fixed]);
    let view = w.drawings.iter_world(&w.world).nth(1).expect("local");
    let v: Vec<f64> = view.vertices().flat_map(|v| [v.x, v.y, v.z]).collect();
    assert_close(&v, &moved, 0.0);
}

#[test]
fn add_multiple_packs_items() {
    let mut w = world();
    let lines = int(&ok(
        &mut w,
        "addDrawingObject",
        &[Value::Int(DRAWING_LINES), f(1.0), f(0.0), h(-1), Value::Int(0)],
    )[0]);
    let packed = Value::floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 9.0]);
    assert_eq!(add_item(&mut w, lines | HANDLEFLAG_ADD_MULTIPLE, packed), 1);
    assert_eq!(
        w.drawings.object(lines).expect("lines").item_count(),
        2,
        "the trailing 9 is ignored"
    );
}

#[test]
fn removal() {
    let mut w = world();
    let mk = |w: &mut Sim| {
        int(&ok(
            w,
            "addDrawingObject",
            &[Value::Int(DRAWING_POINTS), f(1.0), f(0.0), h(-1), Value::Int(0)],
        )[0])
    };
    let (a, b, c) = (mk(&mut w), mk(&mut w), mk(&mut w));
    assert!(a < b && b < c, "handles increase");
    ok(&mut w, "removeDrawingObject", &[h(b)]);
    assert!(err(&mut w, "getDrawingObjectItems", &[h(b)]).contains("does not exist"));
    assert!(err(&mut w, "addDrawingObjectItem", &[h(b), v3(0.0, 0.0, 0.0)]).contains("does not exist"));
    assert!(err(&mut w, "removeDrawingObject", &[h(b)]).contains("does not exist"));
    assert_eq!(w.drawings.len(), 2);
    ok(&mut w, "removeDrawingObject", &[h(HANDLE_ALL)]);
    assert!(w.drawings.is_empty());
    assert!(err(&mut w, "getDrawingObjectItems", &[h(a)]).contains("does not exist"));
    assert!(mk(&mut w) >= FIRST_DRAWING_HANDLE);
}

#[test]
fn drawing_bad_arguments() {
    let mut w = world();
    let add = "addDrawingObject";
    let good = |t: Value, size: Value, tol: Value, parent: Value, max: Value| vec![t, size, tol, parent, max];
    let i = Value::Int;
    assert!(err(&mut w, add, &good("lines".into(), f(1.0), f(0.0), i(-1), i(0))).contains("argument 1"));
    assert!(err(&mut w, add, &good(i(1), f(f64::NAN), f(0.0), i(-1), i(0))).contains("argument 2"));
    assert!(err(&mut w, add, &good(i(1), f(1.0), f(f64::INFINITY), i(-1), i(0))).contains("argument 3"));
    assert!(err(&mut w, add, &good(i(1), f(1.0), f(0.0), i(9999), i(0))).contains("does not exist"));
    assert!(err(&mut w, add, &good(i(1), f(1.0), f(0.0), i(-1), i(-5))).contains("argument 5"));
    assert!(
        err(
            &mut w,
            add,
            &[i(1), f(1.0), f(0.0), i(-1), i(0), Value::floats(&[1.0, 0.0])]
        )
        .contains("argument 6")
    );
    assert!(err(&mut w, add, &[i(1), f(1.0)]).contains("argument 3"));
    assert!(w.drawings.is_empty(), "no failed call created an object");

    let lines = int(&ok(&mut w, add, &good(i(1), f(1.0), f(0.0), i(-1), i(0)))[0]);
    let item = "addDrawingObjectItem";
    assert!(err(&mut w, item, &[h(lines), v3(0.0, 0.0, 0.0)]).contains("at least 6 numbers"));
    let nan = Value::floats(&[0.0, 0.0, f64::NAN, 1.0, 1.0, 1.0]);
    assert!(err(&mut w, item, &[h(lines), nan]).contains("element 3"));
    let mixed = Value::Array(vec![f(0.0), "x".into(), f(0.0), f(1.0), f(1.0), f(1.0)]);
    assert!(err(&mut w, item, &[h(lines), mixed]).contains("element 2"));
    assert!(err(&mut w, item, &[h(lines), "points".into()]).contains("argument 2"));
    assert!(
        err(&mut w, item, &[h(0), v3(0.0, 0.0, 0.0)]).contains("does not exist"),
        "an object handle"
    );
    assert!(err(&mut w, item, &[h(lines | HANDLEFLAG_ADD_MULTIPLE), v3(0.0, 0.0, 0.0)]).contains("6 numbers"));
    assert!(err(&mut w, "getDrawingObjectItems", &[Value::Nil]).contains("argument 1"));
    assert!(err(&mut w, "removeDrawingObject", &[h(-1)]).contains("does not exist"));
    // Out-of-range values are clamped the way CoppeliaSim does, not refused.
    let big = int(&ok(
        &mut w,
        add,
        &[i(0), f(1e6), f(-1.0), i(-1), i(10_000_000), v3(2.0, -1.0, 0.5)],
    )[0]);
    let o = w.drawings.object(big).expect("object");
    assert_eq!(
        (o.size(), o.duplicate_tolerance(), o.max_items()),
        (100.0, 0.0, 100_000)
    );
    assert_eq!(o.color(), [1.0, 0.0, 0.5]);
    assert!(
        w.world.log.lines().any(|l| l.message.contains("capped")),
        "the cap is logged"
    );
}

#[test]
fn graph_stream_records_with_step_end_times() {
    let mut w = world();
    let graph = find(&w, "/bubbleRob/graph");
    let s = int(&ok(&mut w, "addGraphStream", &[h(graph), "speed".into(), "m/s".into()])[0]);
    let dt = w.world.settings().dt;
    for k in 0..5 {
        if k != 2 {
            ok(&mut w, "setGraphStreamValue", &[h(graph), h(s), f(f64::from(k))]);
        }
        w.finish_step();
    }
    // Two values in one step: the last one counts.
    ok(&mut w, "setGraphStreamValue", &[h(graph), h(s), f(10.0)]);
    ok(&mut w, "setGraphStreamValue", &[h(graph), h(s), f(11.0)]);
    let r = ok(&mut w, "getGraphStreamValues", &[h(graph), h(s)]);
    let times = floats(&r[0]);
    assert_close(&times, &[dt, 2.0 * dt, 4.0 * dt, 5.0 * dt, 6.0 * dt], 1e-12);
    assert_eq!(floats(&r[1]), [0.0, 1.0, 3.0, 4.0, 11.0]);
    // Re-adding the name updates the stream and keeps its values.
    let again = int(&ok(
        &mut w,
        "addGraphStream",
        &[h(graph), "speed".into(), "km/h".into(), Value::Int(1)],
    )[0]);
    assert_eq!(again, s);
    let stream = w.graphs.stream(graph, s).expect("stream");
    assert_eq!((stream.params().unit.as_str(), stream.params().options), ("km/h", 1));
    assert_eq!(stream.params().color, [1.0, 0.0, 0.0], "default colour is red");
    assert_eq!(stream.len(), 5);
}

#[test]
fn graph_stream_buffer_is_bounded() {
    let mut w = world();
    let graph = find(&w, "/bubbleRob/graph");
    let s = int(&ok(&mut w, "addGraphStream", &[h(graph), "n".into(), "".into()])[0]);
    let total = MAX_STREAM_SAMPLES + 10;
    for k in 0..total {
        w.graphs.record(graph, s, k as f64, k as f64).expect("record");
    }
    let stream = w.graphs.stream(graph, s).expect("stream");
    assert_eq!(stream.len(), MAX_STREAM_SAMPLES);
    assert_eq!(stream.samples().next(), Some((10.0, 10.0)), "the oldest were dropped");
    assert_eq!(stream.samples().last(), Some(((total - 1) as f64, (total - 1) as f64)));
}

/// Splits a CSV line without quotes, or with one quoted header field.
fn csv_cells(line: &str) -> Vec<String> {
    let mut cells = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            ',' if !quoted => cells.push(std::mem::take(&mut cur)),
            c => cur.push(c),
        }
    }
    cells.push(cur);
    cells
}

#[test]
fn graph_streams_export_to_csv() {
    let mut w = world();
    let graph = find(&w, "/bubbleRob/graph");
    let a = int(&ok(
        &mut w,
        "addGraphStream",
        &[h(graph), "bubbleRob clearance".into(), "m".into()],
    )[0]);
    let b = int(&ok(
        &mut w,
        "addGraphStream",
        &[h(graph), "speed, left".into(), "rad/s".into()],
    )[0]);
    for k in 0..4 {
        ok(&mut w, "setGraphStreamValue", &[h(graph), h(a), f(0.1 * f64::from(k))]);
        if k % 2 == 1 {
            ok(&mut w, "setGraphStreamValue", &[h(graph), h(b), f(-f64::from(k))]);
        }
        w.finish_step();
    }
    let dir = temp_dir("export");
    let r = ok(&mut w, "exportGraphStreams", &[dir.to_string_lossy().as_ref().into()]);
    let Value::Array(paths) = &r[0] else {
        panic!("paths: {r:?}")
    };
    assert_eq!(paths.len(), 1, "one graph with streams");
    let path = PathBuf::from(paths[0].as_str().expect("path"));
    assert_eq!(path, dir.join("graph.csv"), "named after the graph's alias");
    let text = std::fs::read_to_string(&path).expect("csv written");
    let mut lines = text.lines();
    let header = csv_cells(lines.next().expect("header"));
    assert_eq!(header, ["time", "bubbleRob clearance [m]", "speed, left [rad/s]"]);
    let dt = w.world.settings().dt;
    let rows: Vec<Vec<String>> = lines.map(csv_cells).collect();
    assert_eq!(rows.len(), 4);
    for (k, row) in rows.iter().enumerate() {
        let t: f64 = row[0].parse().expect("time");
        assert!((t - dt * (k + 1) as f64).abs() < 1e-12, "row {k} time {t}");
        let va: f64 = row[1].parse().expect("a");
        assert!((va - 0.1 * k as f64).abs() < 1e-12);
        if k % 2 == 1 {
            assert_eq!(row[2].parse::<f64>().expect("b"), -(k as f64));
        } else {
            assert_eq!(row[2], "", "no value for b at step {k}");
        }
    }
    // The Rust entry point the CLI uses: custom names, same content, no temporaries left.
    let dir2 = temp_dir("export-rust");
    let written = w.graphs.export_csv(&dir2, |g| format!("robot/{g}")).expect("export");
    assert_eq!(written, [dir2.join(format!("robot_{graph}.csv"))]);
    assert_eq!(std::fs::read_to_string(&written[0]).expect("read"), text);
    let leftovers = std::fs::read_dir(&dir2).expect("dir").count();
    assert_eq!(leftovers, 1, "only the CSV, no temporary file");
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&dir2);
}

#[test]
fn graph_bad_arguments() {
    let mut w = world();
    let graph = find(&w, "/bubbleRob/graph");
    let base = find(&w, "/bubbleRob");
    let add = "addGraphStream";
    assert!(err(&mut w, add, &[h(base), "x".into()]).contains("not a graph"));
    assert!(err(&mut w, add, &[h(9999), "x".into()]).contains("does not exist"));
    assert!(err(&mut w, add, &[h(graph), "".into()]).contains("must not be empty"));
    assert!(err(&mut w, add, &[h(graph), Value::Int(3)]).contains("argument 2"));
    assert!(err(&mut w, add, &[h(graph), "x".into(), Value::Int(3)]).contains("argument 3"));
    assert!(err(&mut w, add, &[h(graph), "x".into(), "m".into(), f(0.5)]).contains("argument 4"));
    assert!(
        err(
            &mut w,
            add,
            &[h(graph), "x".into(), "m".into(), h(0), Value::floats(&[1.0])]
        )
        .contains("argument 5")
    );
    assert!(w.graphs.streams().next().is_none(), "no failed call created a stream");
    let s = int(&ok(&mut w, add, &[h(graph), "x".into()])[0]);
    let set = "setGraphStreamValue";
    assert!(err(&mut w, set, &[h(graph), h(s), f(f64::NAN)]).contains("finite"));
    assert!(err(&mut w, set, &[h(graph), h(s), "1".into()]).contains("argument 3"));
    assert!(err(&mut w, set, &[h(graph), h(s + 1), f(1.0)]).contains("no stream"));
    assert!(err(&mut w, set, &[h(base), h(s), f(1.0)]).contains("not a graph"));
    assert!(err(&mut w, "getGraphStreamValues", &[h(graph), h(-3)]).contains("no stream"));
    assert!(err(&mut w, "exportGraphStreams", &[Value::Int(1)]).contains("argument 1"));
    assert!(err(&mut w, "exportGraphStreams", &["".into()]).contains("must not be empty"));
    // A directory that cannot be created: a path below a regular file.
    let dir = temp_dir("bad-export");
    std::fs::create_dir_all(&dir).expect("dir");
    let file = dir.join("file");
    std::fs::write(&file, b"x").expect("file");
    ok(&mut w, set, &[h(graph), h(s), f(1.0)]);
    let below = file.join("sub");
    assert!(err(&mut w, "exportGraphStreams", &[below.to_string_lossy().as_ref().into()]).contains("cannot export"));
    let _ = std::fs::remove_dir_all(&dir);
}
