#!/usr/bin/env bash
# Browser test of the viewer (issue 7): headless Debian chromium, driven by Playwright
# (Python), loads the page of a real gantry on the showroom and checks the 3D view,
# the joint, IK, custom-UI and control panels against the text and ZMQ APIs. Saves
# test-artifacts/viewer.png and copies it to docs/viewer.png (the README's picture).
#
#   bash tools/browser-test.sh             # builds target/release/gantry first
#   GANTRY_BIN=path/to/gantry bash tools/browser-test.sh   # uses that binary
#   bash tools/browser-test.sh --bench     # also runs tests/browser/bench_viewer.py
#
# Installs Debian's chromium when `chromium` is missing (apt-get; needs root) and
# creates or reuses the virtual environment .venv (as .ci/python-tests.sh does).
# Playwright never downloads a browser here. Other arguments go to pytest.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

bench=0
args=()
for a in "$@"; do
    if [[ "$a" == --bench ]]; then bench=1; else args+=("$a"); fi
done

if ! command -v chromium >/dev/null 2>&1; then
    echo "browser-test: installing Debian's chromium"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq chromium >/dev/null
fi
export CHROMIUM="$(command -v chromium)"
"$CHROMIUM" --version 2>/dev/null | grep -v '^\s*$' | head -1 || true

source "$root/tools/python-venv.sh"
# Playwright's own browser download is never used: tests pass executable_path.
export PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r tests/browser/requirements.txt

if [[ -z "${GANTRY_BIN:-}" ]]; then
    cargo build --release --bin gantry
    export GANTRY_BIN="$root/target/release/gantry"
fi
if [[ ! -x "$GANTRY_BIN" ]]; then
    echo "browser-test: GANTRY_BIN=$GANTRY_BIN is not an executable" >&2
    exit 1
fi
echo "browser-test: gantry at $GANTRY_BIN"

"$venv/bin/python" -m pytest tests/browser -q "${args[@]+"${args[@]}"}"
if [[ $bench == 1 ]]; then
    "$venv/bin/python" tests/browser/bench_viewer.py
fi
