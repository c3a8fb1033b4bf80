//! A headless run (`gantry run --no-listen`) ends when a script stops the simulation,
//! as CoppeliaSim's `-q` does: nothing could start it again, so waiting would hang the
//! run forever (CoppeliaSim's simROS2 service client example ends this way).

use std::sync::mpsc;
use std::time::Duration;

use gantry_server::{SimConfig, channel, run_sim_thread};
use gantry_test_support::{TempDir, load};

#[test]
fn a_script_stop_ends_a_run_that_quits_when_stopped() {
    let dir = TempDir::new("quit-when-stopped");
    dir.write(
        "scene.toml",
        "[simulation]\ndt = 0.05\n\n[[object]]\nname = \"node\"\nkind = \"dummy\"\nscript = \"stop.lua\"\n",
    );
    dir.write(
        "stop.lua",
        "function sysCall_actuation()\n    if sim.getSimulationTime() >= 0.2 then sim.stopSimulation() end\nend\n",
    );
    let model = load(&dir.path().join("scene.toml"));
    // The handle stays alive: the run must end because of the stop, not because every
    // transport went away.
    let (_handle, rx) = channel();
    let (done_tx, done) = mpsc::channel();
    std::thread::spawn(move || {
        let config = SimConfig {
            fast: true,
            autostart: true,
            quit_when_stopped: true,
            ..SimConfig::default()
        };
        let _ = done_tx.send(run_sim_thread(model, config, rx, || false));
    });
    let summary = done
        .recv_timeout(Duration::from_secs(60))
        .expect("the run ended after the script stopped the simulation")
        .expect("the run succeeded");
    // Steps at t = 0.05 .. 0.25 s: the stop requested in the step that reaches 0.2 s
    // takes effect after it.
    assert!((4..=6).contains(&summary.steps), "{summary:?}");
}

#[test]
fn a_stop_in_sys_call_init_ends_a_run_that_quits_when_stopped() {
    let dir = TempDir::new("quit-in-init");
    dir.write(
        "scene.toml",
        "[[object]]\nname = \"node\"\nkind = \"dummy\"\nscript = \"stop.lua\"\n",
    );
    dir.write("stop.lua", "function sysCall_init()\n    sim.stopSimulation()\nend\n");
    let model = load(&dir.path().join("scene.toml"));
    let (_handle, rx) = channel();
    let (done_tx, done) = mpsc::channel();
    std::thread::spawn(move || {
        let config = SimConfig {
            fast: true,
            autostart: true,
            quit_when_stopped: true,
            ..SimConfig::default()
        };
        let _ = done_tx.send(run_sim_thread(model, config, rx, || false));
    });
    let summary = done
        .recv_timeout(Duration::from_secs(60))
        .expect("the run ended: the script stopped the simulation as it started")
        .expect("the run succeeded");
    assert_eq!(summary.steps, 0, "{summary:?}");
}
