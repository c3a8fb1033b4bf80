//! `sim.startRecording` / `sim.stopRecording` from a script: the engine starts the
//! recording the front end's factory makes, after the script's call; it holds the
//! steps between the two calls; `gantry verify` refuses it (it did not begin with the
//! run); a folder that does not exist is the script's error.

use std::path::Path;
use std::sync::Arc;

use gantry_engine::{Engine, EngineConfig, Input, LoopControl};
use gantry_record::{RecordedRun, RunDescription, RunRecorder, VerifyError};
use gantry_sim_core::scene::{DiskFiles, LoadOptions, LoggedFiles, load_scene};
use gantry_sim_core::sim::Control;
use gantry_test_support::{TempDir, load};

const SCENE: &str = r#"
[simulation]
dt = 0.05

[[object]]
name = "box"
alias = "box"
kind = "dummy"
script = "recorder.lua"
"#;

fn script(path: &Path) -> String {
    format!(
        r#"
function sysCall_actuation()
    local t = sim.getSimulationTime()
    if t > 0.49 and t < 0.51 then
        sim.startRecording({path:?}, {{rate = 20}})
        ok, err = pcall(sim.startRecording, "/no/such/folder/x.mcap")
        print(err)
    elseif t > 0.99 and t < 1.01 then
        sim.stopRecording()
    end
    sim.setObjectPosition(sim.getObject("/box"), {{t, 0, 0}}, sim.handle_world)
end
"#
    )
}

#[test]
fn a_script_records_part_of_a_run_which_verify_then_refuses() {
    let dir = TempDir::new("lua-recording-part");
    let file = dir.path().join("part.mcap");
    dir.write("scene.toml", SCENE);
    dir.write("recorder.lua", script(&file));
    let logged = LoggedFiles::new(&DiskFiles);
    let model = load_scene(&logged, &dir.path().join("scene.toml"), &LoadOptions::default()).expect("loads");
    let run = RunDescription {
        scene_name: model.name.clone(),
        scene_path: dir.path().join("scene.toml"),
        files: logged.into_read(),
        scripts: true,
        dt: model.settings.dt,
        substeps: model.settings.substeps,
        ..RunDescription::default()
    };
    let config = EngineConfig {
        realtime: false,
        recorder: Some(Arc::new(RunRecorder::new(run))),
        ..EngineConfig::default()
    };
    let mut engine = Engine::new(model, config, None).expect("engine");
    engine.serve(Input::Control(LoopControl::Control(Control::Start)));
    for _ in 0..40 {
        engine.step();
    }
    engine.finish();
    let log: Vec<String> = engine.world().log.lines().map(|l| l.message.clone()).collect();
    assert!(
        log.iter()
            .any(|l| l.contains("the folder /no/such/folder does not exist (in function 'sim.startRecording')")),
        "{log:?}"
    );

    let bytes = std::fs::read(&file).expect("recorded");
    let summary = mcap::Summary::read(&bytes).expect("reads").expect("summary");
    let stats = summary.stats.expect("statistics");
    let tf = summary.channels.values().find(|c| c.topic == "/tf").expect("/tf").id;
    // Asked for in step 11 (its actuation sees t = 0.5 s), started after it; stopped
    // after step 21: the snapshot at the start (t = 0.55 s) and steps 12 to 21.
    assert_eq!(stats.channel_message_counts[&tf], 11);
    let first_tf = mcap::MessageStream::new(&bytes)
        .expect("stream")
        .map(|m| m.expect("message"))
        .find(|m| m.channel.topic == "/tf")
        .expect("a /tf message");
    assert_eq!(first_tf.log_time, 550_000_000);
    let run = RecordedRun::from_bytes(&bytes).expect("a gantry recording");
    assert_eq!(run.metadata["started_at_step"], "11");
    let e = run.verify().expect_err("not from the start");
    assert!(matches!(e, VerifyError::StartedMidRun(11)), "{e}");
}

#[test]
fn without_a_recorder_a_scripts_request_is_a_logged_error() {
    let dir = TempDir::new("lua-recording-none");
    dir.write("scene.toml", SCENE);
    dir.write("recorder.lua", script(&dir.path().join("x.mcap")));
    let model = load(&dir.path().join("scene.toml"));
    let config = EngineConfig {
        realtime: false,
        ..EngineConfig::default()
    };
    let mut engine = Engine::new(model, config, None).expect("engine");
    engine.serve(Input::Control(LoopControl::Control(Control::Start)));
    for _ in 0..15 {
        engine.step();
    }
    let log: Vec<String> = engine.world().log.lines().map(|l| l.message.clone()).collect();
    assert!(
        log.iter().any(|l| l.contains("this front end cannot record")),
        "{log:?}"
    );
    assert!(!dir.path().join("x.mcap").exists());
}
