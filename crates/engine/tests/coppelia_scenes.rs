//! Runs the scripts embedded in every public CoppeliaSim file of the shared folder
//! (`../shared/coppelia-files/` from the repository root, or `$GANTRY_COPPELIA_FILES`)
//! for 10 s of simulation, as `gantry run x.ttt` would, and measures how many of the
//! distinct scripts run without a Lua error. Prints the figure and each failing
//! script's first error; the assertion is a floor under the figure, so that it only
//! rises. Where the folder is absent the test says so and passes.

use crate::util;
use util::Drive;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use gantry_lua::{ScriptLimits, ScriptState, uses_luasocket};
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene};
use gantry_test_support::coppelia_files;

/// Simulated time each scene runs, s (the measure).
const RUN_TIME: f64 = 10.0;

/// Distinct scripts that ran clean when this floor was set, per cent; raise it as the
/// figure rises.
const FLOOR_PERCENT: f64 = 80.0;

/// Scripts CoppeliaSim writes itself rather than a user: the force sensors'
/// customization scripts that break the sensor on a trigger.
fn generated(source: &str) -> bool {
    source.contains("sysCall_trigger") && source.contains("breakForceSensor") && source.len() < 2000
}

/// Scripts that wait for a network client in their hooks (LuaSocket servers), which a
/// run with no client would wait on for ever; `blue_robot.rs` runs them with one.
fn serves_sockets(source: &str) -> bool {
    uses_luasocket(source)
}

/// What happened to one script: `None` when it ran clean, else its first error.
type Outcome = Option<String>;

/// Runs one file's scripts; those that serve sockets are left out (and named in
/// `served`), the others run.
fn run_file(path: &Path, served: &mut Vec<String>) -> Vec<(String, Outcome)> {
    let mut model = load_scene(&DiskFiles, path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    model.scripts.retain(|s| {
        let keep = !serves_sockets(&s.source);
        if !keep {
            served.push(s.path.display().to_string());
        }
        keep
    });
    let sources: Vec<String> = model.scripts.iter().map(|s| s.source.clone()).collect();
    let paths: Vec<PathBuf> = model.scripts.iter().map(|s| s.path.clone()).collect();
    let dt = model.settings.dt;
    let mut sim = util::engine(model, ScriptLimits::default()).unwrap_or_else(|e| panic!("{e}"));
    // Customization scripts see the scene before the run, as in CoppeliaSim.
    sim.non_simulation();
    sim.start();
    let steps = (RUN_TIME / dt).round() as usize;
    for k in 0..steps {
        sim.step();
        if k % 10 == 0 {
            sim.non_simulation();
        }
    }
    // Read before the stop, which restores the scene and its scripts.
    let states = sim.scripts();
    sim.stop();
    assert_eq!(
        states.len(),
        sources.len(),
        "{}: one script per attached source",
        path.display()
    );
    sources
        .into_iter()
        .zip(paths)
        .zip(states)
        .map(|((source, p), (q, _, state))| {
            assert_eq!(p, q, "scripts in the model's order");
            let outcome = match state {
                ScriptState::Errored(e) => Some(e.lines().next().unwrap_or("").to_owned()),
                _ => None,
            };
            (source, outcome)
        })
        .collect()
}

#[test]
fn embedded_scripts_of_the_shared_files_run() {
    let dir = coppelia_files();
    if !dir.join("SOURCES.md").is_file() {
        println!(
            "coppelia-files not found at {}; skipped (set GANTRY_COPPELIA_FILES)",
            dir.display()
        );
        return;
    }
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("folder")
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".ttt") || n.ends_with(".ttm"))
        .collect();
    names.sort();
    // Each distinct script once: clean only if it ran clean in every file holding it.
    let mut distinct: BTreeMap<String, (String, Outcome)> = BTreeMap::new();
    let mut served = Vec::new();
    for name in &names {
        for (source, outcome) in run_file(&dir.join(name), &mut served) {
            if generated(&source) {
                continue;
            }
            let entry = distinct.entry(source).or_insert_with(|| (name.clone(), None));
            if entry.1.is_none() && outcome.is_some() {
                *entry = (name.clone(), outcome);
            }
        }
    }
    let total = distinct.len();
    let clean = distinct.values().filter(|(_, o)| o.is_none()).count();
    let percent = 100.0 * clean as f64 / total.max(1) as f64;
    println!(
        "embedded scripts: {clean} of {total} distinct scripts run {RUN_TIME} s without a Lua error ({percent:.0} %)"
    );
    for s in &served {
        println!("  {s}: a LuaSocket server, run with a client by blue_robot.rs");
    }
    for (file, outcome) in distinct.values() {
        if let Some(e) = outcome {
            println!("  {file}: {e}");
        }
    }
    assert!(total > 0, "the shared files hold scripts");
    assert!(
        percent >= FLOOR_PERCENT,
        "{percent:.0} % of the distinct scripts ran clean, below the floor of {FLOOR_PERCENT} %"
    );
}
