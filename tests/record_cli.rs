//! `gantry run --record` (issue 31): a file that cannot be created fails the run before
//! it starts, naming the file and saying why.

use std::process::Command;

fn gantry() -> Command {
    Command::new(env!("CARGO_BIN_EXE_gantry"))
}

#[test]
fn a_recording_in_a_missing_folder_fails_before_the_run_naming_the_file() {
    let path = std::env::temp_dir()
        .join(format!("gantry-no-such-folder-{}", std::process::id()))
        .join("run.mcap");
    let out = gantry()
        .args(["run", "--steps", "5", "--fast", "--no-listen", "--record"])
        .arg(&path)
        .output()
        .expect("runs");
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(&format!("cannot record to {}", path.display())),
        "{stderr}"
    );
    assert!(stderr.contains("No such file or directory"), "{stderr}");
    assert!(
        out.stdout.is_empty(),
        "nothing ran: {}",
        String::from_utf8_lossy(&out.stdout)
    );
}

#[test]
fn a_record_rate_must_be_positive() {
    let out = gantry()
        .args([
            "run",
            "--steps",
            "5",
            "--fast",
            "--no-listen",
            "--record",
            "x.mcap",
            "--record-rate",
            "0",
        ])
        .output()
        .expect("runs");
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("--record-rate 0"), "{stderr}");
}

/// `/dev/full` opens but every write fails with ENOSPC: a disk that is full. The MCAP
/// header is written (and flushed) when the recording starts, so the run is refused
/// before it starts. (A disk that fills up during the run is
/// `crates/record/tests/recorder.rs`'s `a_full_disk_stops_the_recording_and_the_simulation_goes_on`.)
#[cfg(target_os = "linux")]
#[test]
fn a_full_disk_at_the_start_fails_before_the_run() {
    let out = gantry()
        .args(["run", "--steps", "5", "--fast", "--no-listen", "--record", "/dev/full"])
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(stderr.contains("cannot record to /dev/full"), "{stderr}");
    assert!(stderr.contains("No space left on device"), "{stderr}");
    assert!(out.stdout.is_empty(), "nothing ran");
}
