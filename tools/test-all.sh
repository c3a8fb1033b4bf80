#!/usr/bin/env bash
# Every test suite of gantry, with what they need installed: the one command the README
# gives and that CI runs (.ci/run). Safe to re-run; each stage says what it does, and a
# table of each stage's time closes the run.
#
#   bash tools/test-all.sh
#
# Stages: formatting, lints, the dependency direction (crates and files), the Rust tests
# (unit, crate contracts, end-to-end against the real binary), a short run of every fuzz
# target, the Python suite that drives a real gantry with CoppeliaSim's own ZMQ client
# (and loads public robots from PyPI packages, checked against Pinocchio), a 20 s soak
# under hundreds of clients, the browser test (headless Chromium from Debian, driven by
# Playwright), and the script debugger's end-to-end tests with Microsoft's DAP test
# client (node; installed from Debian when missing).
#
# Builds: the lints are a `cargo clippy` check; everything else that runs gantry comes
# from one optimised build in the `ci` profile (Cargo.toml): the Rust tests, the binary
# every end-to-end suite drives (target/ci/gantry, built once and passed on as
# GANTRY_BIN) and the Python extension (maturin, same profile, so it reuses every
# compiled dependency). The fuzz targets need their own nightly, instrumented build.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
# Stage timing: each stage's wall time, printed as a table at the end (and on failure).
export GANTRY_PROFILE=ci
stage_names=()
stage_secs=()
stage_name=""
stage_start=$SECONDS
run_start=$SECONDS
end_stage() {
    if [[ -n "$stage_name" ]]; then
        stage_names+=("$stage_name")
        stage_secs+=($((SECONDS - stage_start)))
    fi
}
stage() {
    end_stage
    stage_name="$1"
    stage_start=$SECONDS
    printf '\n== %s\n' "$*"
}
report_times() {
    end_stage
    stage_name=""
    echo
    echo "stage times (s):"
    for i in "${!stage_names[@]}"; do
        printf "  %5d  %s\n" "${stage_secs[$i]}" "${stage_names[$i]:0:72}"
    done
    printf '  %5d  total\n' $((SECONDS - run_start))
    # The CoppeliaSim file tests read the public files from the shared folder; without
    # it they test the reader on the synthetic files they build, and say so here.
    local coppelia="${GANTRY_COPPELIA_FILES:-$root/../shared/coppelia-files}"
    if [[ -d "$coppelia" ]]; then
        echo "coppelia-files: $(find "$coppelia" -maxdepth 1 -name '*.tt[tm]' | wc -l) public .ttt/.ttm files read from $coppelia"
    else
        echo "coppelia-files: ABSENT ($coppelia): the .ttt/.ttm tests ran on synthetic files only"
    fi
}
trap report_times EXIT

stage "toolchain"
cargo --version
if ! cargo fmt --version >/dev/null 2>&1 || ! cargo clippy --version >/dev/null 2>&1; then
    rustup component add rustfmt clippy
fi

stage "formatting (cargo fmt --check)"
cargo fmt --all -- --check

stage "lints (cargo clippy -D warnings)"
# In the ci profile, so that the build scripts (the vendored Lua's C compile among them)
# and proc-macros it builds are the ones the test build below reuses.
cargo clippy --workspace --all-targets --profile ci -- -D warnings

stage "API docs (cargo doc -D warnings: no broken or private links)"
# After clippy, whose metadata it reuses; the Python bindings' crate is left out (its
# docs are the Python package's).
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --exclude gantry-python --no-deps --profile ci --quiet

stage "dependency direction: protocol, coppelia-file and the scene model stay pure (no tokio runtime, rapier or mlua); ROS 2 over the world below the recorder, the graph and the Lua host; no circle among files; floors inside the simulation crates and the Lua host"
if cargo tree -p gantry-protocol -e normal --prefix none | grep -E '^(tokio|rapier3d|mlua|parry3d) ' ; then
    echo "gantry-protocol must not depend on the crates listed above" >&2
    exit 1
fi
if cargo tree -p gantry-coppelia-file -e normal --prefix none | grep -E '^(tokio|rapier3d|mlua|parry3d|nalgebra) ' ; then
    echo "gantry-coppelia-file must not depend on the crates listed above" >&2
    exit 1
fi
# The scene model knows no physics engine; the world and the registry no runtime or Lua.
if cargo tree -p gantry-scene -e normal --prefix none | grep -E '^(tokio|rapier3d|mlua|parry3d) ' ; then
    echo "gantry-scene must not depend on the crates listed above" >&2
    exit 1
fi
# The subsystems below the world (simUI's model, planning, IK) know no physics either.
for crate in gantry-ui gantry-planning gantry-ik; do
    if cargo tree -p "$crate" -e normal --prefix none | grep -E '^(tokio|rapier3d|mlua|parry3d) ' ; then
        echo "$crate must not depend on the crates listed above" >&2
        exit 1
    fi
done
for crate in gantry-world gantry-sim-core; do
    if cargo tree -p "$crate" -e normal --prefix none | grep -E '^(tokio|mlua) ' ; then
        echo "$crate must not depend on tokio or mlua" >&2
        exit 1
    fi
done
# The engine has no I/O: no sockets, no runtime, no transport crate.
if cargo tree -p gantry-engine -e normal --prefix none | grep -E '^(axum|zeromq|mio|gantry-server) ' ; then
    echo "gantry-engine must not depend on a transport, a runtime or the wire codecs" >&2
    exit 1
fi
# The recording format (issue 31) is data: no simulation, Lua, runtime or physics, so
# its reader and codecs are fuzzed on their own. The recorder sits on the engine (a
# Tap) and writes on a thread of its own: no transport.
# Rebuilding a recording's scene is the recorder's: the format does not load scenes.
if cargo tree -p gantry-mcap -e normal --prefix none | grep -E '^(tokio|mlua|rapier3d|parry3d|gantry-scene|gantry-world|gantry-sim-core|gantry-ros|gantry-lua|gantry-engine|gantry-server) ' ; then
    echo "gantry-mcap must not depend on the simulation, the scene loader, the Lua host, a runtime or physics" >&2
    exit 1
fi
if cargo tree -p gantry-record -e normal --prefix none | grep -E '^(axum|zeromq|gantry-server) ' ; then
    echo "gantry-record must not depend on a transport" >&2
    exit 1
fi
# ROS 2 (issue 29): the Lua host knows the network only as a trait; DDS lives in
# gantry-ros2, which is a transport beside the others, not under them.
if cargo tree -p gantry-lua -e normal --prefix none | grep -E '^(rustdds|gantry-ros2) ' ; then
    echo "gantry-lua must not depend on a DDS implementation" >&2
    exit 1
fi
if cargo tree -p gantry-ros2 -e normal --prefix none | grep -E '^(axum|zeromq|gantry-server) ' ; then
    echo "gantry-ros2 must not depend on the server's transports" >&2
    exit 1
fi
# ROS 2 over the world (issue 47): the sampler, the tf frames and the network trait
# that the recorder, the graph and the Lua host share sit below all three: no runtime,
# no Lua, no transport, no recording format. The graph takes them from there, not
# from the recorder.
if cargo tree -p gantry-ros -e normal --prefix none | grep -E '^(tokio|mio|mlua|rustdds|axum|zeromq|mcap|gantry-lua|gantry-engine|gantry-server|gantry-mcap|gantry-record|gantry-ros2) ' ; then
    echo "gantry-ros must not depend on a runtime, the Lua host, a transport or the recording" >&2
    exit 1
fi
if cargo tree -p gantry-ros2 -e normal --prefix none | grep -E '^gantry-record ' ; then
    echo "gantry-ros2 must not depend on the recorder (its messages and sampler are gantry-ros's)" >&2
    exit 1
fi
# The engine owns the simulation and drives the Lua host (issue 47): the observers
# (the recorder, the ROS 2 graph) see the simulation through the engine's Observer
# trait over &Sim and name no type of the Lua host, so neither depends on it directly.
for crate in gantry-record gantry-ros2; do
    if cargo tree -p "$crate" -e normal --prefix none --depth 1 | grep -E '^gantry-lua ' ; then
        echo "$crate must not depend on the Lua host (gantry-lua); observe through gantry_engine::Observer" >&2
        exit 1
    fi
done
# The tests' shared helpers (issue 47) sit on the scene model and the codecs only, so
# every crate from the world up takes them as a dev-dependency without a cycle.
if cargo tree -p gantry-test-support -e normal --prefix none | grep -E '^(rapier3d|mlua|tokio|gantry-world|gantry-sim-core|gantry-ros|gantry-lua|gantry-engine|gantry-record|gantry-ros2|gantry-server) ' ; then
    echo "gantry-test-support must depend only on gantry-scene and gantry-protocol among the workspace's crates" >&2
    exit 1
fi
# Inside the crates: no circle among files in any crate, and sim-core's and the Lua
# host's floors; the self-test first shows the checker still catches both.
python3 tools/layers.py --self-test
python3 tools/layers.py

stage "Rust tests (cargo test --workspace, ci profile; builds target/ci/gantry for the suites below)"
cargo test --workspace --profile ci
cargo build --profile ci --bin gantry
export GANTRY_BIN="$root/target/ci/gantry"

stage "fuzz smoke: every cargo-fuzz target for 6 s from its seeds (installs nightly and cargo-fuzz if missing)"
bash tools/fuzz-smoke.sh --seconds 6 --no-sanitizer

stage "Python suite: CoppeliaSim's ZMQ client against a real gantry; public robots against Pinocchio"
bash .ci/python-tests.sh

stage "soak: 200 text, 20 ZMQ and 4 viewer clients for 20 s, some killed mid-request; fds, memory, real-time factor"
bash tools/soak.sh --seconds 20

stage "browser test: the viewer page in headless chromium (Playwright) against a real gantry"
bash tools/browser-test.sh

stage "debugger: Microsoft's DAP test client (@vscode/debugadapter-testsupport) against gantry --debug"
bash tools/dap-tests.sh

echo
echo "all test suites passed"
