#!/usr/bin/env bash
# Every test suite of gantry, with what they need installed: the one command the README
# gives and that CI runs (.ci/run). Safe to re-run; each stage says what it does.
#
#   bash tools/test-all.sh
#
# Stages: formatting, lints, the dependency-direction rule, the Rust tests (unit,
# crate contracts, end-to-end against the real binary), a short run of every fuzz
# target, the Python suite that drives a real gantry with CoppeliaSim's own ZMQ client
# (and loads public robots from PyPI packages, checked against Pinocchio),
# a 20 s soak under hundreds of clients, the browser test (headless Chromium from
# Debian, driven by Playwright), and the script debugger's end-to-end tests with
# Microsoft's DAP test client (node; installed from Debian when missing).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
stage() { printf '\n== %s\n' "$*"; }

stage "toolchain"
cargo --version
if ! cargo fmt --version >/dev/null 2>&1 || ! cargo clippy --version >/dev/null 2>&1; then
    rustup component add rustfmt clippy
fi

stage "formatting (cargo fmt --check)"
cargo fmt --all -- --check

stage "lints (cargo clippy -D warnings)"
cargo clippy --workspace --all-targets -- -D warnings

stage "dependency direction: protocol and coppelia-file stay pure (no tokio runtime, rapier or mlua); floors inside sim-core and the Lua host"
if cargo tree -p gantry-protocol -e normal --prefix none | grep -E '^(tokio|rapier3d|mlua|parry3d) ' ; then
    echo "gantry-protocol must not depend on the crates listed above" >&2
    exit 1
fi
if cargo tree -p gantry-coppelia-file -e normal --prefix none | grep -E '^(tokio|rapier3d|mlua|parry3d|nalgebra) ' ; then
    echo "gantry-coppelia-file must not depend on the crates listed above" >&2
    exit 1
fi
if cargo tree -p gantry-sim-core -e normal --prefix none | grep -E '^(tokio|mlua) ' ; then
    echo "gantry-sim-core must not depend on tokio or mlua" >&2
    exit 1
fi
# Inside the crates: sim-core's floors (world, subsystems, Sim, api) and the Lua host's.
python3 tools/layers.py

stage "Rust tests (cargo test --workspace)"
cargo test --workspace

stage "fuzz smoke: every cargo-fuzz target for 15 s from its seeds (installs nightly and cargo-fuzz if missing)"
bash tools/fuzz-smoke.sh --seconds 15

stage "Python suite: CoppeliaSim's ZMQ client against a real gantry; public robots against Pinocchio"
bash .ci/python-tests.sh

stage "soak: 200 text, 20 ZMQ and 4 viewer clients for 20 s, some killed mid-request; fds, memory, real-time factor"
bash tools/soak.sh --seconds 20

stage "browser test: the viewer page in headless chromium (Playwright) against a real gantry"
bash tools/browser-test.sh

stage "debugger: Microsoft's DAP test client (@vscode/debugadapter-testsupport) against gantry --debug"
GANTRY_BIN="$root/target/release/gantry" bash tools/dap-tests.sh

echo
echo "all test suites passed"
