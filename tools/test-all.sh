#!/usr/bin/env bash
# Every test suite of gantry, with what they need installed: the one command the README
# gives and that CI runs (.ci/run). Safe to re-run; each stage says what it does.
#
#   bash tools/test-all.sh
#
# Stages: formatting, lints, the dependency-direction rule, the Rust tests (unit,
# crate contracts, end-to-end against the real binary), the fuzz crate's build, the
# Python suite that drives a real gantry with CoppeliaSim's own ZMQ client, and the
# browser test (headless Chromium from Debian, driven by Playwright).
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

stage "dependency direction: protocol stays pure (no tokio runtime, rapier or mlua)"
if cargo tree -p gantry-protocol -e normal --prefix none | grep -E '^(tokio|rapier3d|mlua|parry3d) ' ; then
    echo "gantry-protocol must not depend on the crates listed above" >&2
    exit 1
fi
if cargo tree -p gantry-sim-core -e normal --prefix none | grep -E '^(tokio|mlua) ' ; then
    echo "gantry-sim-core must not depend on tokio or mlua" >&2
    exit 1
fi

stage "Rust tests (cargo test --workspace)"
cargo test --workspace

stage "fuzz targets compile (running them needs nightly: see fuzz/README.md)"
(cd fuzz && cargo check --quiet)

stage "Python suite: CoppeliaSim's ZMQ client against a real gantry"
bash .ci/python-tests.sh

stage "browser test: the viewer page in headless chromium (Playwright) against a real gantry"
bash tools/browser-test.sh

echo
echo "all test suites passed"
