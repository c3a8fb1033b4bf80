#!/usr/bin/env bash
# Python suite: the real CoppeliaSim ZMQ client (coppeliasim-zmqremoteapi-client==2.0.4
# from PyPI) drives a real gantry process (issue 6), and the same tests run a second
# time in-process against the `gantry` package (issue 18), whose wheel this script
# builds with maturin and installs, with its Gymnasium and Ray suites.
#
#   bash .ci/python-tests.sh            # builds target/release/gantry and the wheel first
#   GANTRY_BIN=path/to/gantry bash .ci/python-tests.sh   # uses that binary (the wheel is still built)
#
# Creates (or reuses) the virtual environment .venv at the repository root. Extra
# arguments go to pytest, e.g. `bash .ci/python-tests.sh -k fk`.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

source "$root/tools/python-venv.sh"

"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r tests/python/requirements.txt
# The legacy remote API's real client (V-REP's remoteApi.so and vrep.py), as pypot ships
# it; without pypot's own dependencies (OpenCV, SciPy...), which the tests never import.
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-deps -r tests/python/requirements-nodeps.txt

if [[ -z "${GANTRY_BIN:-}" ]]; then
    cargo build --release --bin gantry
    export GANTRY_BIN="$root/target/release/gantry"
fi
if [[ ! -x "$GANTRY_BIN" ]]; then
    echo "python-tests: GANTRY_BIN=$GANTRY_BIN is not an executable" >&2
    exit 1
fi
echo "python-tests: gantry at $GANTRY_BIN"

source "$root/tools/python-wheel.sh"

# PyRep's API on gantry (issue 50): a pure-Python package beside the wheel.
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-deps \
    --force-reinstall "$root/python/gantry-pyrep"

status=0
"$venv/bin/python" -m pytest tests/python -q --ignore=tests/python/pyrep "$@" || status=$?
# The `pyrep` package's own tests, in a process of their own: it is a distribution of
# its own, and its simulations (one per thread) should not share a process with the
# suite above's subprocess tests.
"$venv/bin/python" -m pytest tests/python/pyrep -q || status=$?
# PyRep's own unit tests, unchanged, from ../shared/pyrep/tests: the acceptance suite
# of the `pyrep` package, with the issue's bar (tests/pyrep/run_suite.py).
"$venv/bin/python" tests/pyrep/run_suite.py || status=$?
exit $status
