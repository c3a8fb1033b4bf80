//! Issue 3's acceptance test: BubbleRob's controller (`scripts/bubble_rob.lua`) drives the
//! rover of `bubble_rob.toml` for 2 simulated minutes without getting stuck.

use crate::util;
use util::Drive;

use gantry_engine::Engine;
use gantry_lua::{ScriptLimits, ScriptState};
use gantry_sim_core::Value;
use gantry_test_support::{int, load, repo};
use util::{find, world_position};

/// 2 simulated minutes of 50 ms steps.
const STEPS: usize = 2400;

/// What a two-minute run did.
#[derive(Debug)]
struct Run {
    /// Path length of `/bubbleRob` in the floor plane, m.
    travelled: f64,
    /// Rising edges of the nose sensor's detection.
    detections: usize,
    /// Times the controller switched from driving forward to backing up (the left
    /// wheel's target speed turning negative).
    backups: usize,
    /// Shortest path length over any 20 s window, m.
    least_in_window: f64,
    /// Final position.
    end: [f64; 3],
    /// Largest distance from the arena centre along X or Y, m.
    max_extent: f64,
    /// Lowest and highest body height, m.
    height: (f64, f64),
}

fn drive(sim: &mut Engine) -> Run {
    let rob = find(sim, "/bubbleRob");
    let nose = find(sim, "/bubbleRob/sensingNose");
    let left = find(sim, "/bubbleRob/leftMotor");
    let (mut backups, mut backing) = (0, false);
    let mut prev = world_position(sim, rob);
    let mut per_step = Vec::with_capacity(STEPS);
    let (mut detections, mut detected) = (0, false);
    let mut max_extent = 0.0f64;
    let mut height = (f64::INFINITY, f64::NEG_INFINITY);
    for _ in 0..STEPS {
        sim.step();
        let p = world_position(sim, rob);
        per_step.push((p[0] - prev[0]).hypot(p[1] - prev[1]));
        prev = p;
        max_extent = max_extent.max(p[0].abs()).max(p[1].abs());
        height = (height.0.min(p[2]), height.1.max(p[2]));
        let r = sim
            .call("readProximitySensor", &[Value::Int(nose)])
            .expect("read the nose sensor");
        let now = int(&r[0]) == 1;
        if now && !detected {
            detections += 1;
        }
        detected = now;
        let target = sim.world().joint(left).expect("left motor").target_velocity;
        if target < 0.0 && !backing {
            backups += 1;
        }
        backing = target < 0.0;
    }
    let window = 400; // 20 s
    let least_in_window = per_step
        .windows(window)
        .map(|w| w.iter().sum::<f64>())
        .fold(f64::INFINITY, f64::min);
    Run {
        travelled: per_step.iter().sum(),
        detections,
        backups,
        least_in_window,
        end: prev,
        max_extent,
        height,
    }
}

fn assert_roams(run: &Run) {
    assert!(run.travelled >= 3.0, "travelled {:.2} m in 2 min", run.travelled);
    assert!(run.backups >= 2, "backed away {} times", run.backups);
    assert!(
        run.backups <= run.detections,
        "each backup starts with a detection: {run:?}"
    );
    assert!(
        run.least_in_window > 0.2,
        "stuck: {:.3} m in the slowest 20 s",
        run.least_in_window
    );
    assert!(run.max_extent < 2.45, "left the arena: {run:?}");
    assert!(
        run.height.0 > 0.05 && run.height.1 < 0.2,
        "tipped over or jumped: {run:?}"
    );
}

#[test]
fn the_shipped_bubble_rob_roams_for_two_minutes() {
    let model = load(&repo("assets/scenes/bubble_rob.toml"));
    let mut sim = util::engine(model, ScriptLimits::default()).expect("builds");
    let run = drive(&mut sim);
    eprintln!(
        "bubble_rob (shipped script): travelled {:.2} m, {} backups, {} detections (rising edges), \
         slowest 20 s: {:.2} m, end at ({:.2}, {:.2}), max |x|,|y| {:.2} m, height {:.3}..{:.3} m, t = {:.2} s",
        run.travelled,
        run.backups,
        run.detections,
        run.least_in_window,
        run.end[0],
        run.end[1],
        run.max_extent,
        run.height.0,
        run.height.1,
        sim.world().time()
    );
    for (path, _, state) in sim.scripts() {
        assert_eq!(state, ScriptState::Running, "{}", path.display());
    }
    assert!((sim.world().time() - 120.0).abs() < 1e-6);
    assert_roams(&run);
}
