//! Safe by default, from the real binary (issue 9, security): loopback unless `--bind`
//! says otherwise and a warning when it does, the access token from `--token` or
//! `GANTRY_TOKEN` shown only in the viewer URL, ZMQ kept on loopback with a token, and
//! `gantry send --token`.

use crate::common;

use std::process::{Command, Output};

use gantry_test_support::repo;

const TOKEN: &str = "cli-token-abcdef123456";

fn gantry() -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_gantry"));
    // A token in the test runner's environment must not leak into these runs.
    cmd.env_remove("GANTRY_TOKEN");
    cmd
}

/// `gantry run fk_arm` with every listener on a free port, a few fast steps, plus `extra`.
fn run_briefly(cmd: &mut Command, extra: &[&str]) -> Output {
    cmd.arg("run")
        .arg(repo("assets/scenes/fk_arm.toml"))
        .args([
            "--text-port",
            "0",
            "--zmq-port",
            "0",
            "--http-port",
            "0",
            "--steps",
            "5",
            "--fast",
        ])
        .args(extra)
        .output()
        .expect("gantry runs")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn listeners_bind_loopback_by_default_and_a_wider_bind_warns() {
    let out = run_briefly(&mut gantry(), &[]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    for channel in ["text", "zmq", "http"] {
        assert!(err.contains(&format!("listening {channel}=127.0.0.1:")), "{err}");
    }
    assert!(!err.contains("not loopback"), "{err}");

    let out = run_briefly(&mut gantry(), &["--bind", "0.0.0.0"]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("listening text=0.0.0.0:"), "{err}");
    assert!(
        err.contains("listening on 0.0.0.0 (not loopback): anyone who can reach this machine can drive the simulation"),
        "{err}"
    );
    assert!(err.contains("--token"), "the warning names the remedy: {err}");
}

#[test]
fn the_token_appears_only_in_the_viewer_url() {
    let out = run_briefly(&mut gantry(), &["--token", TOKEN, "-vv"]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    let with_token: Vec<&str> = err.lines().filter(|l| l.contains(TOKEN)).collect();
    assert_eq!(with_token.len(), 1, "{with_token:?}");
    let url = with_token[0]
        .strip_prefix("viewer url=http://127.0.0.1:")
        .unwrap_or_else(|| panic!("{}", with_token[0]));
    assert!(url.ends_with(&format!("/?token={TOKEN}")), "{url}");
    assert!(
        err.contains("access token required"),
        "the log says a token is needed: {err}"
    );
}

#[test]
fn gantry_token_in_the_environment_sets_the_token() {
    let out = run_briefly(gantry().env("GANTRY_TOKEN", TOKEN), &[]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains(&format!("?token={TOKEN}")), "{err}");
}

#[test]
fn a_malformed_token_is_refused_without_echoing_it() {
    let out = run_briefly(&mut gantry(), &["--token", "short"]);
    let err = stderr(&out);
    assert!(!out.status.success());
    assert!(err.contains("--token") && err.contains("8 to 256 characters"), "{err}");
    assert!(!err.contains("short"), "{err}");

    let secret = "almost-right but with a space";
    let out = run_briefly(&mut gantry(), &["--token", secret]);
    let err = stderr(&out);
    assert!(!out.status.success());
    assert!(err.contains("may only contain") && err.contains("' '"), "{err}");
    assert!(!err.contains("almost-right"), "{err}");
}

#[test]
fn with_a_token_a_wide_bind_keeps_zmq_on_loopback() {
    let out = run_briefly(&mut gantry(), &["--bind", "0.0.0.0", "--token", TOKEN]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("listening text=0.0.0.0:"), "{err}");
    assert!(err.contains("listening http=0.0.0.0:"), "{err}");
    assert!(err.contains("listening zmq=127.0.0.1:"), "{err}");
    assert!(err.contains("ZMQ remote API kept on 127.0.0.1:"), "{err}");
    assert!(err.contains("require the access token"), "{err}");

    let out = run_briefly(&mut gantry(), &["--bind", "0.0.0.0", "--token", TOKEN, "--expose-zmq"]);
    let err = stderr(&out);
    assert!(err.contains("listening zmq=0.0.0.0:"), "{err}");
    assert!(
        err.contains("has no authentication: --token does not protect it"),
        "{err}"
    );
}

#[test]
fn gantry_send_authenticates_with_the_token() {
    let g = common::start("assets/scenes/fk_arm.toml", &["--token", TOKEN]);
    let addr = g.text.to_string();
    let send = |token: Option<&str>| {
        let mut cmd = gantry();
        cmd.args(["send", "--addr", &addr]);
        if let Some(t) = token {
            cmd.args(["--token", t]);
        }
        cmd.arg("<JOINTS#>").output().expect("gantry send runs")
    };
    let ok = send(Some(TOKEN));
    assert!(ok.status.success(), "{}", stderr(&ok));
    assert!(String::from_utf8_lossy(&ok.stdout).starts_with("<JOINTS#J1="));

    let without = send(None);
    assert!(!without.status.success());
    let stdout = String::from_utf8_lossy(&without.stdout);
    assert!(stdout.starts_with("<ERR#access token required"), "{stdout}");

    let wrong = send(Some("not-the-right-token"));
    assert!(!wrong.status.success());
    assert!(
        stderr(&wrong).contains("the access token was not accepted: <ERR#wrong access token"),
        "{}",
        stderr(&wrong)
    );
}
