#!/usr/bin/env bash
# Soak test (issue 9): a real-time gantry on the showroom under 200 text clients, 20
# ZMQ remote API clients and 4 viewer WebSockets at once, with clients killed mid-request,
# watching the server's file descriptors, memory and real-time factor
# (tests/python/soak.py says exactly what it checks). Prints a summary table; exits
# non-zero on any failed check.
#
#   bash tools/soak.sh                 # 60 s of load; builds target/release/gantry first
#   bash tools/soak.sh --seconds 20    # what tools/test-all.sh runs
#   GANTRY_BIN=path/to/gantry bash tools/soak.sh   # uses that binary, no build
#
# Other arguments go to soak.py (--text-clients N, --zmq-clients N, --viewers N, ...).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

source "$root/tools/python-venv.sh"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    -r tests/python/requirements.txt "websockets==15.0.1"

if [[ -z "${GANTRY_BIN:-}" ]]; then
    cargo build --release --bin gantry
    export GANTRY_BIN="$root/target/release/gantry"
fi
if [[ ! -x "$GANTRY_BIN" ]]; then
    echo "soak: GANTRY_BIN=$GANTRY_BIN is not an executable" >&2
    exit 1
fi
# 200 clients plus the server's own descriptors, ZMQ contexts and child processes.
ulimit -n 4096 2>/dev/null || true
exec "$venv/bin/python" tests/python/soak.py "$@"
