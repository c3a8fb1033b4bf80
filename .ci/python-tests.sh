#!/usr/bin/env bash
# Python suite of the ZMQ remote API (issue 6): the real CoppeliaSim client
# (coppeliasim-zmqremoteapi-client==2.0.4 from PyPI) drives a real gantry process.
#
#   bash .ci/python-tests.sh            # builds target/release/gantry first
#   GANTRY_BIN=path/to/gantry bash .ci/python-tests.sh   # uses that binary, no build
#
# Creates (or reuses) the virtual environment .venv at the repository root. Extra
# arguments go to pytest, e.g. `bash .ci/python-tests.sh -k fk`.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

source "$root/tools/python-venv.sh"

"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r tests/python/requirements.txt

if [[ -z "${GANTRY_BIN:-}" ]]; then
    cargo build --release --bin gantry
    export GANTRY_BIN="$root/target/release/gantry"
fi
if [[ ! -x "$GANTRY_BIN" ]]; then
    echo "python-tests: GANTRY_BIN=$GANTRY_BIN is not an executable" >&2
    exit 1
fi
echo "python-tests: gantry at $GANTRY_BIN"

exec "$venv/bin/python" -m pytest tests/python -q "$@"
