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

python="${PYTHON:-python3}"
venv="$root/.venv"

if [[ ! -x "$venv/bin/python" ]]; then
    echo "python-tests: creating $venv"
    if ! "$python" -m venv "$venv" 2>/dev/null; then
        # Debian splits venv (ensurepip) into python3-venv; fall back to virtualenv.
        rm -rf "$venv"
        echo "python-tests: '$python -m venv' is unavailable; using virtualenv"
        "$python" -m pip install --quiet --user virtualenv \
            || "$python" -m pip install --quiet --user --break-system-packages virtualenv
        "$python" -m virtualenv --quiet "$venv"
    fi
fi

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
