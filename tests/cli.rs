//! The `gantry` command line: every shipped scene runs headless, the summary line is
//! machine-readable, `check` reports errors with file, line and column, and the
//! embedded default scene works from any directory.

use crate::common;

use std::process::Command;

use gantry_test_support::repo;

fn gantry() -> Command {
    Command::new(env!("CARGO_BIN_EXE_gantry"))
}

/// Parses `steps=N sim_time=S wall_s=W steps_per_s=R rtf=X`.
fn summary(stdout: &[u8]) -> Vec<(String, f64)> {
    let text = String::from_utf8_lossy(stdout);
    let line = text.lines().last().expect("a summary line");
    line.split_whitespace()
        .map(|kv| {
            let (k, v) = kv.split_once('=').expect("key=value");
            (k.to_owned(), v.parse().expect("number"))
        })
        .collect()
}

#[test]
fn every_scene_runs_200_steps_headless() {
    for scene in [
        "assets/scenes/fk_arm.toml",
        "assets/scenes/bubble_rob.toml",
        "assets/scenes/showroom.toml",
        "assets/robots/arm6/arm6.urdf",
    ] {
        let out = gantry()
            .args(["run", "--steps", "200", "--fast", "--no-listen"])
            .arg(repo(scene))
            .output()
            .expect("runs");
        assert!(
            out.status.success(),
            "{scene}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let s = summary(&out.stdout);
        let keys: Vec<&str> = s.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(keys, ["steps", "sim_time", "wall_s", "steps_per_s", "rtf"], "{scene}");
        assert_eq!(s[0].1, 200.0, "{scene}");
        assert!((s[1].1 - 10.0).abs() < 1e-9, "{scene}: 200 steps of 50 ms");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("script error"), "{scene}: {stderr}");
    }
}

#[test]
fn overrides_and_embedded_scene_from_another_directory() {
    let out = gantry()
        .args([
            "--steps",
            "20",
            "--fast",
            "--no-listen",
            "--dt",
            "0.01",
            "--substeps",
            "2",
        ])
        .current_dir(std::env::temp_dir())
        .output()
        .expect("runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let s = summary(&out.stdout);
    assert!((s[1].1 - 0.2).abs() < 1e-9, "20 steps of 10 ms: {s:?}");
}

#[test]
fn the_default_scene_starts_without_a_warning() {
    // The lab sheet's UI used to warn about its `resizeable` attribute at every start.
    let out = gantry()
        .args(["--steps", "40", "--fast", "--no-listen"])
        .current_dir(std::env::temp_dir())
        .output()
        .expect("runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let err = String::from_utf8_lossy(&out.stderr);
    let noisy: Vec<&str> = err
        .lines()
        .filter(|l| l.contains("WARN") || l.contains("ERROR"))
        .collect();
    assert!(noisy.is_empty(), "{noisy:#?}");
}

#[test]
fn check_reports_file_line_and_column() {
    let dir = std::env::temp_dir().join(format!("gantry-cli-check-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("tmp dir");
    let bad = dir.join("bad.toml");
    std::fs::write(
        &bad,
        "[simulation]\ndt = 0.05\n\n[[object]]\nname = \"a\"\nkind = \"dummy\"\nparent = \"nowhere\"\n",
    )
    .expect("write");
    let out = gantry().arg("check").arg(&bad).output().expect("runs");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.toml:7:10") && err.contains("'nowhere'"), "{err}");

    std::fs::write(&bad, "[simulation]\ndt = [\n").expect("write");
    let out = gantry().arg("check").arg(&bad).output().expect("runs");
    assert!(!out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("bad.toml:2:"),
        "malformed TOML names the line"
    );

    let script = dir.join("broken.lua");
    std::fs::write(&script, "function sysCall_init()\n  x = = 1\nend\n").expect("write");
    std::fs::write(
        &bad,
        "[[object]]\nname = \"a\"\nkind = \"dummy\"\nscript = \"broken.lua\"\n",
    )
    .expect("write");
    let out = gantry().arg("check").arg(&bad).output().expect("runs");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("broken.lua:2:"),
        "script syntax errors name file and line: {err}"
    );

    let ok = gantry()
        .arg("check")
        .arg(repo("assets/scenes/showroom.toml"))
        .output()
        .expect("runs");
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue #9 from the command line: a missing scene, a malformed URDF and a URDF joint
/// cycle each fail `check` and `run` with the file (and line and column) on stderr;
/// unknown keys only warn, with a hint, and the scene still checks out and runs.
#[test]
fn bad_scene_files_fail_with_their_place_and_unknown_keys_only_warn() {
    let dir = std::env::temp_dir().join(format!("gantry-cli-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("tmp dir");
    let stderr = |out: &std::process::Output| String::from_utf8_lossy(&out.stderr).into_owned();

    let missing = dir.join("missing.toml");
    let check = gantry().arg("check").arg(&missing).output().expect("runs");
    let run = gantry()
        .args(["run", "--no-listen"])
        .arg(&missing)
        .output()
        .expect("runs");
    for (cmd, out) in [("check", check), ("run", run)] {
        assert!(!out.status.success(), "{cmd} of a missing scene succeeded");
        let err = stderr(&out);
        assert!(
            err.contains(&missing.display().to_string()) && err.contains("cannot read"),
            "{cmd}: {err}"
        );
    }

    let urdf = dir.join("bot.urdf");
    std::fs::write(&urdf, "<robot name=\"bot\">\n  <link name=\"a\">\n</robot>\n").expect("write");
    let out = gantry().arg("check").arg(&urdf).output().expect("runs");
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("bot.urdf:3:1: malformed URDF XML: expected 'link' tag, not 'robot'"),
        "{}",
        stderr(&out)
    );
    std::fs::write(
        &urdf,
        "<robot name=\"bot\">\n<link name=\"root\"/><link name=\"a\"/><link name=\"b\"/>\n\
         <joint name=\"ab\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/></joint>\n\
         <joint name=\"ba\" type=\"fixed\"><parent link=\"b\"/><child link=\"a\"/></joint>\n</robot>\n",
    )
    .expect("write");
    let out = gantry()
        .args(["run", "--steps", "5", "--fast", "--no-listen"])
        .arg(&urdf)
        .output()
        .expect("runs");
    assert!(!out.status.success(), "a robot with a joint cycle ran");
    assert!(
        stderr(&out).contains("bot.urdf:3:1: the joints 'ab' -> 'ba' form a cycle"),
        "{}",
        stderr(&out)
    );

    let scene = dir.join("typo.toml");
    std::fs::write(
        &scene,
        "[simulation]\nsubstep = 4\n\n[[object]]\nname = \"a\"\nkind = \"dummy\"\nparnet = \"b\"\n",
    )
    .expect("write");
    let hints = [
        "warning: unknown key 'simulation.substep' (did you mean 'substeps'?)",
        "warning: unknown key 'object[0] ('a').parnet' (did you mean 'parent'?)",
    ];
    let out = gantry().arg("check").arg(&scene).output().expect("runs");
    assert!(out.status.success(), "{}", stderr(&out));
    for hint in hints {
        assert!(stderr(&out).contains(hint), "check: {}", stderr(&out));
    }
    let out = gantry()
        .args(["run", "--steps", "5", "--fast", "--no-listen"])
        .arg(&scene)
        .output()
        .expect("runs");
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(summary(&out.stdout)[0], ("steps".to_owned(), 5.0));
    // Each warning once: the loader's are the front end's to report, the engine
    // reports only what building the world added.
    for key in [
        "unknown key 'simulation.substep'",
        "unknown key 'object[0] ('a').parnet'",
    ] {
        assert_eq!(stderr(&out).matches(key).count(), 1, "run: {}", stderr(&out));
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn send_exits_non_zero_on_errors_and_failed_connections() {
    let g = common::start("assets/scenes/fk_arm.toml", &[]);
    let addr = g.text.to_string();
    let ok = gantry()
        .args(["send", "--addr", &addr, "<FK#J1=0.1>", "<JOINTS#>"])
        .output()
        .expect("runs");
    assert!(ok.status.success());
    let stdout = String::from_utf8_lossy(&ok.stdout);
    assert!(
        stdout.starts_with("<FK#J1=0.1>\n<JOINTS#J1=0.10000000000000001,"),
        "{stdout}"
    );
    let err = gantry()
        .args(["send", "--addr", &addr, "<FK#J1=abc>"])
        .output()
        .expect("runs");
    assert!(!err.status.success());
    drop(g);
    let refused = gantry()
        .args(["send", "--addr", &addr, "<FK#J1=0>"])
        .output()
        .expect("runs");
    assert!(!refused.status.success());
}

/// The shared CoppeliaSim files (`$GANTRY_COPPELIA_FILES`, else `shared/coppelia-files`
/// beside the checkout or one of its ancestors, so a worktree finds them too).
fn coppelia_files() -> Option<std::path::PathBuf> {
    if let Some(dir) = std::env::var_os("GANTRY_COPPELIA_FILES") {
        return Some(dir.into());
    }
    repo("")
        .ancestors()
        .map(|a| a.join("shared/coppelia-files"))
        .find(|d| d.join("SOURCES.md").is_file())
}

/// `gantry convert SCENE DIR`, then `gantry check` on what it wrote.
fn convert_and_check(scene: &std::path::Path, dir: &std::path::Path, stem: &str) -> String {
    let out = gantry().arg("convert").arg(scene).arg(dir).output().expect("runs");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let toml = dir.join(format!("{stem}.toml"));
    assert!(stdout.contains(&format!("wrote {}", toml.display())), "{stdout}");
    let check = gantry().arg("check").arg(&toml).output().expect("runs");
    assert!(
        check.status.success(),
        "{}: {}",
        toml.display(),
        String::from_utf8_lossy(&check.stderr)
    );
    stdout
}

#[test]
fn convert_writes_a_scene_that_checks_and_refuses_to_overwrite_without_force() {
    let dir = std::env::temp_dir().join(format!("gantry-cli-convert-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    // Any scene gantry loads converts: a URDF robot, on any clone.
    let urdf = repo("assets/robots/arm6/arm6.urdf");
    let stdout = convert_and_check(&urdf, &dir.join("arm6"), "arm6");
    assert!(
        stdout.contains("converted to") && stdout.contains("(17 objects"),
        "{stdout}"
    );

    // Again into the same folder: refused, naming the files, and nothing is touched.
    let toml = dir.join("arm6/arm6.toml");
    std::fs::write(&toml, "# edited by hand\n").expect("write");
    let again = gantry()
        .arg("convert")
        .arg(&urdf)
        .arg(dir.join("arm6"))
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&again.stderr);
    assert!(!again.status.success());
    assert!(
        stderr.contains(&toml.display().to_string()) && stderr.contains("--force"),
        "{stderr}"
    );
    assert_eq!(std::fs::read_to_string(&toml).expect("read"), "# edited by hand\n");
    let forced = gantry()
        .arg("convert")
        .arg("--force")
        .arg(&urdf)
        .arg(dir.join("arm6"))
        .output()
        .expect("runs");
    assert!(forced.status.success(), "{}", String::from_utf8_lossy(&forced.stderr));
    assert!(std::fs::read_to_string(&toml).expect("read").contains("[[object]]"));

    // A missing scene is an error naming it.
    let missing = gantry()
        .arg("convert")
        .arg(dir.join("nothing.ttt"))
        .arg(dir.join("x"))
        .output()
        .expect("runs");
    assert!(!missing.status.success());
    assert!(String::from_utf8_lossy(&missing.stderr).contains("nothing.ttt"));

    // The paper's CoppeliaSim scene: its scripts become Lua files the TOML attaches.
    match coppelia_files() {
        Some(files) => {
            let stdout = convert_and_check(
                &files.join("paper__Blue_Robot.ttt"),
                &dir.join("blue"),
                "paper__Blue_Robot",
            );
            assert!(stdout.contains("scripts/") && stdout.contains(".lua"), "{stdout}");
            let toml = std::fs::read_to_string(dir.join("blue/paper__Blue_Robot.toml")).expect("read");
            assert!(
                toml.contains("[[script]]") && toml.contains("mesh = \"meshes/"),
                "{toml}"
            );
        }
        None => println!("coppelia-files not found; the .ttt part skipped (set GANTRY_COPPELIA_FILES)"),
    }
    let _ = std::fs::remove_dir_all(&dir);
}
