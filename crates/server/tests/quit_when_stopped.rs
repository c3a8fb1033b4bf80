//! A headless run (`gantry run --no-listen`) ends when a script stops the simulation,
//! as CoppeliaSim's `-q` does: nothing could start it again, so waiting would hang the
//! run forever (CoppeliaSim's simROS2 service client example ends this way).

use std::sync::mpsc;
use std::time::Duration;

use gantry_server::{SimConfig, channel, run_sim_thread};
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene};

#[test]
fn a_script_stop_ends_a_run_that_quits_when_stopped() {
    let dir = std::env::temp_dir().join(format!("gantry-quit-when-stopped-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    std::fs::write(
        dir.join("scene.toml"),
        "[simulation]\ndt = 0.05\n\n[[object]]\nname = \"node\"\nkind = \"dummy\"\nscript = \"stop.lua\"\n",
    )
    .expect("scene");
    std::fs::write(
        dir.join("stop.lua"),
        "function sysCall_actuation()\n    if sim.getSimulationTime() >= 0.2 then sim.stopSimulation() end\nend\n",
    )
    .expect("script");
    let model = load_scene(&DiskFiles, &dir.join("scene.toml"), &LoadOptions::default()).expect("scene loads");
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
    let _ = std::fs::remove_dir_all(&dir);
}
