#!/usr/bin/env bash
# gantry's benchmark against PyBullet and bare rapier (issue 8), in one run on one
# machine. Builds the release binary, runs `cargo bench --bench sim`, the PyBullet side,
# the public robots (mesh-collision arms from pybullet_data and example-robot-data, in
# gantry and PyBullet; issue 15), the ZMQ latency benchmark with the real Python client
# (and against the client's floor, tools/bench/zmq_floor.py), the vision sensors against
# PyBullet's TinyRenderer (tools/bench/vision.py) and the start-up probe, then prints the
# side-by-side report (also in target/bench/report.md) and draws docs/rovers.png. Takes about ten minutes; run it on
# a quiet machine.
#
#   bash tools/bench.sh            # GANTRY_BENCH_SECONDS=3 by default
#
# The public robots alone, with a given binary (the report's section 6):
#   GANTRY_BIN=target/release/gantry .venv/bin/python tools/bench/public_robots.py \
#       --repeat 3 > target/bench/public.json && .venv/bin/python tools/bench/report.py --public-only
# gantry against MuJoCo on the public arms alone (the report's section 9; the in-process
# package from tools/python-wheel.sh):
#   GANTRY_BIN=target/release/gantry .venv/bin/python tools/bench/mujoco_bench.py \
#       --repeat 3 > target/bench/mujoco.json && .venv/bin/python tools/bench/report.py --mujoco-only
# The vision section alone, with the installed wheel (source tools/python-wheel.sh first):
#   .venv/bin/python tools/bench/vision.py --json target/bench/vision.json && \
#       .venv/bin/python tools/bench/report.py --vision-only
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
source tools/python-venv.sh
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r tests/python/requirements.txt -r tools/bench/requirements.txt
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-deps -r tests/python/requirements-nodeps.txt
mkdir -p target/bench

echo "== release build"
cargo build --release --quiet
echo "== gantry: cargo bench --bench sim"
cargo bench --quiet --bench sim
echo "== vision sensors and laser scanners (cargo bench -p gantry-sim-core --bench vision / --bench scan; issue 30)"
cargo bench --quiet -p gantry-sim-core --bench vision
cargo bench --quiet -p gantry-sim-core --bench scan
echo "== the editor's edits: paste, undo, redo and a move with 5,000 objects (cargo bench -p gantry-engine --bench editing; issue 48)"
cargo bench --quiet -p gantry-engine --bench editing
echo "== PyBullet"
"$venv/bin/python" tools/bench/pybullet_bench.py --seconds "${GANTRY_BENCH_SECONDS:-3}" > target/bench/pybullet.json
echo "== public robots: mesh-collision arms in gantry and PyBullet"
"$venv/bin/python" tools/bench/public_robots.py --repeat 3 > target/bench/public.json
echo "== ZMQ latency (real Python client)"
"$venv/bin/python" tests/python/bench_zmq.py --runs 3 --json target/bench/zmq.json
echo "== ZMQ latency against the client's floor (a busy-polling pyzmq ROUTER echo server), interleaved"
GANTRY_BIN=target/release/gantry "$venv/bin/python" tools/bench/zmq_floor.py --rounds 5 --steps 2000 --json target/bench/zmq_floor.json
echo "== legacy remote API (V-REP's real remoteApi.so client): blocking call and synchronous stepping"
GANTRY_BIN=target/release/gantry "$venv/bin/python" tools/bench/legacy_remote_api.py
echo "== Python in-process: call latency and stepping against ZMQ and PyBullet; Ray batch speed-up"
source tools/python-wheel.sh
"$venv/bin/python" tools/bench/python_inproc.py --repeat 3 --json target/bench/python.json
# The batch benchmark exits 1 below its target speed-up; the report says so too.
"$venv/bin/python" tools/bench/ray_batch.py --json target/bench/ray.json || true
echo "== MuJoCo: the public arms in gantry (Lua loop, Python loop, advance(n)), MuJoCo (Python loop, rollout) and PyBullet, interleaved (issue 33)"
GANTRY_BIN=target/release/gantry "$venv/bin/python" tools/bench/mujoco_bench.py --repeat 3 > target/bench/mujoco.json
echo "== vector environments: 1 against 2 threads on BubbleRobAvoid and ArmReach, with the machine's ceiling"
"$venv/bin/python" tools/bench/vector_env.py --envs 4 16 32 64 128 --json target/bench/vector_env.json
echo "== vision: gantry's vision sensors against PyBullet's TinyRenderer, same scenes, interleaved (issue 30)"
"$venv/bin/python" tools/bench/vision.py --rounds 5 --json target/bench/vision.json
echo "== script debugger: step rate with and without --debug"
"$venv/bin/python" tools/bench/debugger.py --steps 10000 --repeat 3 --json target/bench/debugger.json
echo "== recording: the showroom's step rate with and without --record (issue 31)"
GANTRY_BIN=target/release/gantry "$venv/bin/python" tools/bench/record.py --json target/bench/record.json
echo "== replay: scrubbing a 10-minute showroom recording (issue 31)"
GANTRY_BIN=target/release/gantry "$venv/bin/python" tools/bench/replay.py --steps 12000 --seeks 200 --json target/bench/replay.json
echo "== ROS 2: --ros2's cost, a VGA camera on the graph, /cmd_vel latency; Cyclone DDS as the peer (issue 29)"
GANTRY_BIN=target/release/gantry "$venv/bin/python" tools/bench/ros2.py --json target/bench/ros2.json
echo "== start-up and memory"
# PyRep on gantry (issue 50): pr.step() on PyRep's Panda scene, and with RLBench's
# default observation; the pyrep package beside the wheel.
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-deps --force-reinstall ./python/gantry-pyrep
"$venv/bin/python" tools/bench/pyrep_bench.py --repeat 3 --json target/bench/pyrep.json
"$venv/bin/python" tools/bench/startup.py > target/bench/startup.json
echo
"$venv/bin/python" tools/bench/report.py
