//! `--record` through the server's simulation thread (issue 31): the recorder observes
//! every step, keeps recording after a script fails (its error is a `/rosout` line),
//! takes the cleanup hooks' log lines after the last step, and ends the file with its
//! summary.

use std::path::PathBuf;

use gantry_record::RecordParams;
use gantry_server::{ServeConfig, Shutdown, SimConfig};
use gantry_test_support::{TempDir, load};

const SCENE: &str = r#"
[simulation]
dt = 0.05

[[object]]
name = "box"
alias = "box"
kind = "dummy"
script = "logger.lua"
"#;

const SCRIPT: &str = r#"
function sysCall_init() print("init line") end
function sysCall_actuation()
    if sim.getSimulationTime() > 0.4 and not failed then
        failed = true
        error("boom at 0.45 s")
    end
end
function sysCall_cleanup() print("cleanup line") end
"#;

#[test]
fn the_sim_thread_records_every_step_script_errors_and_cleanup_lines() {
    let dir = TempDir::new("server-record");
    dir.write("scene.toml", SCENE);
    dir.write("logger.lua", SCRIPT);
    let model = load(&dir.path().join("scene.toml"));
    let file: PathBuf = dir.path().join("run.mcap");
    let sim = SimConfig {
        steps: Some(20),
        fast: true,
        autostart: true,
        record: Some(RecordParams {
            path: file.clone(),
            ..RecordParams::default()
        }),
        ..SimConfig::default()
    };
    let summary = gantry_server::run(model, sim, ServeConfig::default(), Shutdown::default(), |_| {}).expect("runs");
    assert_eq!(summary.steps, 20, "the run went on after the script error");
    let bytes = std::fs::read(&file).expect("recorded");

    let mcap_summary = mcap::Summary::read(&bytes)
        .expect("reads")
        .expect("ended with a summary");
    let stats = mcap_summary.stats.expect("statistics");
    let count = |topic: &str| {
        let id = mcap_summary
            .channels
            .values()
            .find(|c| c.topic == topic)
            .map(|c| c.id)
            .expect(topic);
        stats.channel_message_counts[&id]
    };
    assert_eq!(count("/tf"), 21, "the start and each of the 20 steps");
    let lines: Vec<String> = mcap::MessageStream::new(&bytes)
        .expect("stream")
        .map(|m| m.expect("message"))
        .filter(|m| m.channel.topic == "/rosout")
        .map(|m| String::from_utf8_lossy(&m.data).into_owned())
        .collect();
    let has = |text: &str| lines.iter().any(|l| l.contains(text));
    assert!(has("init line"), "{lines:?}");
    assert!(has("boom at 0.45 s"), "the script error: {lines:?}");
    assert!(
        has("cleanup line"),
        "the cleanup hook ran after the last step: {lines:?}"
    );
}
