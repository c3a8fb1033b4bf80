//! Shared helpers for end-to-end tests: start a real `gantry` process on free ports
//! and stop it when the test ends, whatever happens.

use std::io::{BufRead, BufReader};
use std::net::SocketAddr;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use gantry_test_support::repo;

/// A running gantry; killed on drop.
pub struct Gantry {
    pub child: Child,
    pub text: SocketAddr,
    /// Lines gantry writes to stderr after the listening lines. Held, unread, so that the
    /// background thread keeps draining the pipe and gantry never blocks on a full one.
    _stderr: mpsc::Receiver<String>,
}

impl Drop for Gantry {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Starts `gantry run SCENE` with the text channel on a free port, plus `extra` args.
pub fn start(scene: &str, extra: &[&str]) -> Gantry {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_gantry"));
    cmd.arg("run")
        .arg(repo(scene))
        .args(["--text-port", "0", "--zmq-port", "0"])
        .args(extra);
    cmd.stdout(Stdio::null()).stderr(Stdio::piped()).stdin(Stdio::null());
    let mut child = cmd.spawn().expect("gantry starts");
    let stderr = child.stderr.take().expect("stderr piped");
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines() {
            let Ok(line) = line else { break };
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let mut text = None;
    while text.is_none() {
        let line = rx
            .recv_timeout(Duration::from_secs(30))
            .expect("gantry prints its listening address");
        if let Some(a) = line.strip_prefix("listening text=") {
            text = Some(a.parse().expect("socket address"));
        }
    }
    Gantry {
        child,
        text: text.expect("set above"),
        _stderr: rx,
    }
}

/// Open file descriptors of a process (Linux), to detect socket leaks.
pub fn open_fds(pid: u32) -> usize {
    std::fs::read_dir(format!("/proc/{pid}/fd"))
        .map(|d| d.count())
        .unwrap_or(0)
}

/// Resident memory of a process in KiB (Linux).
pub fn rss_kib(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .unwrap_or(0)
}
