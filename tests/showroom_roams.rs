//! Issue 15: the default scene must not get stuck. `gantry` with no arguments shows the
//! showroom, and a newcomer watches its BubbleRob for minutes; the rover used to drive into
//! the side of a cylinder 17 s in, where its nose sensor cannot see, and push against it
//! with its wheels turning for the rest of the run.
//!
//! The test runs the shipped `assets/scenes/showroom.toml` headless for 200 simulated
//! seconds and checks that the rover keeps moving in every 10 s window and never stays
//! against an obstacle. To see where the rover is, it runs a copy of the scene with one
//! addition, a script on the floor that records the rover's position in graph streams
//! (written out by `--export-graphs`). The script only reads, and the test checks that the
//! copy's run is the one `gantry` shows: its clearance stream equals the embedded default
//! scene's, sample for sample.

use std::path::Path;
use std::process::{Command, Output};

use gantry_test_support::{TempDir, repo};

/// 200 s of 50 ms steps: the old scene was pinned from 17 s on, and a rover that roams
/// meets every obstacle of the arena several times in that time.
const STEPS: usize = 4000;
/// The scene's time step, s.
const DT: f64 = 0.05;
/// Length of the sliding window over which the rover must move, s.
const WINDOW_S: f64 = 10.0;
/// Least path length in any window, m. Driving forward at the tutorial's 0.122 m/s covers
/// 1.2 m in 10 s, and even a rover doing nothing but 4 s back-ups (0.038 m/s) covers 0.38 m;
/// one wedged against an obstacle only jitters (0.03 to 0.14 m per 10 s in the old scene).
const MIN_PATH_M: f64 = 0.25;
/// Clearance below which the rover touches something, m.
const TOUCH_M: f64 = 1e-3;
/// Longest the rover may stay touching, s: long enough for a blind 4 s back-up into an
/// obstacle (the tutorial's controller has no rear sensor), far shorter than a pinned
/// rover's minutes.
const MAX_TOUCH_S: f64 = 10.0;

/// Records the rover's floor-plane position each step, in two streams of the rover's own
/// graph. It only reads the world.
const OBSERVER: &str = "\
function sysCall_init()
    rover = sim.getObject('/bubbleRob')
    graph = sim.getObject('/bubbleRob/graph')
    xs = sim.addGraphStream(graph, 'x', 'm')
    ys = sim.addGraphStream(graph, 'y', 'm')
end
function sysCall_sensing()
    local p = sim.getObjectPosition(rover, -1)
    sim.setGraphStreamValue(graph, xs, p[1])
    sim.setGraphStreamValue(graph, ys, p[2])
end
";

/// `gantry run [SCENE] --fast --no-listen --steps STEPS --export-graphs GRAPHS`; no scene
/// runs the embedded showroom.
fn run(scene: Option<&Path>, graphs: &Path) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_gantry"));
    cmd.arg("run");
    if let Some(scene) = scene {
        cmd.arg(scene);
    }
    let out = cmd
        .args([
            "--fast",
            "--no-listen",
            "--steps",
            &STEPS.to_string(),
            "--export-graphs",
        ])
        .arg(graphs)
        .output()
        .expect("gantry runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("script error"), "{stderr}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(&format!("steps={STEPS} ")),
        "the summary line reports every step: {stdout}"
    );
    out
}

/// The columns of an exported graph CSV by header, each a `(time, value)` list; rows
/// where a stream has no value are skipped for it.
fn columns(csv: &Path) -> Vec<(String, Vec<(f64, f64)>)> {
    let text = std::fs::read_to_string(csv).unwrap_or_else(|e| panic!("{}: {e}", csv.display()));
    let mut lines = text.lines();
    let header = lines.next().expect("a header line");
    let mut cols: Vec<(String, Vec<(f64, f64)>)> = header
        .split(',')
        .skip(1)
        .map(|name| (name.to_owned(), Vec::new()))
        .collect();
    for line in lines {
        let mut cells = line.split(',');
        let t: f64 = cells.next().expect("a time").parse().expect("a numeric time");
        for ((_, col), cell) in cols.iter_mut().zip(cells) {
            if !cell.is_empty() {
                col.push((t, cell.parse().expect("a numeric value")));
            }
        }
    }
    cols
}

fn column<'a>(cols: &'a [(String, Vec<(f64, f64)>)], name: &str) -> &'a [(f64, f64)] {
    &cols
        .iter()
        .find(|(n, _)| n == name)
        .unwrap_or_else(|| {
            panic!(
                "no column {name:?} in {:?}",
                cols.iter().map(|c| &c.0).collect::<Vec<_>>()
            )
        })
        .1
}

#[test]
fn the_showroom_rover_keeps_roaming() {
    let dir = TempDir::new("roams");
    let scenes = repo("assets/scenes");
    let shipped = std::fs::read_to_string(scenes.join("showroom.toml")).expect("the showroom is readable");
    // The copy lives elsewhere, so its file references must point back at the repository.
    let reference = "\"../";
    assert!(
        shipped.contains("\"../../scripts/bubble_rob.lua\""),
        "the showroom no longer runs scripts/bubble_rob.lua"
    );
    let copy = shipped.replace(reference, &format!("\"{}/../", scenes.display()))
        + "\n[[script]]\nobject = \"Floor\"\nfile = \"observer.lua\"\n";
    dir.write("observer.lua", OBSERVER);
    let scene = dir.write("showroom.toml", copy);

    // The observed copy and the embedded default scene, side by side.
    let (observed, default) = (dir.path().join("observed"), dir.path().join("default"));
    std::thread::scope(|s| {
        let embedded = s.spawn(|| run(None, &default));
        run(Some(&scene), &observed);
        embedded.join().expect("the embedded run");
    });

    let cols = columns(&observed.join("graph.csv"));
    let (xs, ys) = (column(&cols, "x [m]"), column(&cols, "y [m]"));
    assert_eq!(xs.len(), STEPS, "a position for every step");
    assert_eq!(ys.len(), STEPS, "a position for every step");
    let travelled: Vec<f64> = xs
        .windows(2)
        .zip(ys.windows(2))
        .map(|(x, y)| (x[1].1 - x[0].1).hypot(y[1].1 - y[0].1))
        .collect();
    let window = (WINDOW_S / DT).round() as usize;
    let (slowest, from) = travelled
        .windows(window)
        .enumerate()
        .map(|(i, w)| (w.iter().sum::<f64>(), xs[i].0))
        .fold((f64::INFINITY, 0.0), |a, b| if b.0 < a.0 { b } else { a });
    eprintln!(
        "rover: {:.1} m in {:.0} s, slowest {WINDOW_S} s from t = {from:.2} s: {slowest:.3} m",
        travelled.iter().sum::<f64>(),
        STEPS as f64 * DT
    );
    assert!(
        slowest >= MIN_PATH_M,
        "the rover stalled: {slowest:.3} m in the {WINDOW_S} s from t = {from:.2} s (at least {MIN_PATH_M} m)"
    );

    let clearance = column(&cols, "bubbleRob clearance [m]");
    assert!(clearance.len() >= STEPS - 1, "{} clearance samples", clearance.len());
    let (mut longest, mut since, mut touching_from) = (0.0f64, None, 0.0);
    for &(t, d) in clearance {
        match (d < TOUCH_M, since) {
            (true, None) => since = Some(t),
            (true, Some(t0)) if t - t0 > longest => (longest, touching_from) = (t - t0, t0),
            (false, _) => since = None,
            _ => {}
        }
    }
    assert!(
        longest <= MAX_TOUCH_S,
        "the rover stayed against an obstacle for {longest:.2} s from t = {touching_from:.2} s"
    );

    // The observer changed nothing: the copy ran exactly what `gantry` shows.
    let shown = columns(&default.join("graph.csv"));
    let shown = column(&shown, "bubbleRob clearance [m]");
    let first_difference = clearance.iter().zip(shown).find(|(a, b)| a != b);
    assert!(
        clearance.len() == shown.len() && first_difference.is_none(),
        "the observed copy ran differently from the embedded showroom: {} and {} clearance samples, \
         first different (time, clearance): {first_difference:?}",
        clearance.len(),
        shown.len()
    );
}
