#!/usr/bin/env bash
# End-to-end tests of the Debug Adapter Protocol server (`gantry run SCENE --debug`) with
# Microsoft's own DAP test client (@vscode/debugadapter-testsupport), on node's built-in
# test runner. Each test starts its own gantry with --debug=0 and every port free.
#
#   bash tools/dap-tests.sh                                  # builds target/release/gantry first
#   GANTRY_BIN=path/to/gantry bash tools/dap-tests.sh        # uses that binary
#   bash tools/dap-tests.sh --test-name-pattern='hot reload' # other arguments go to node --test
#   bash tools/dap-tests.sh tests/dap/protocol.test.mjs      # only these files
#
# Needs node (20 or later) and npm. Installs the packages pinned by
# tests/dap/package-lock.json into tests/dap/node_modules (npm ci; skipped when that lock
# file has not changed since the last install).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
    echo "dap-tests: installing Debian's nodejs and npm"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq nodejs npm >/dev/null
fi
node_major="$(node -p 'process.versions.node.split(".")[0]')"
if (( node_major < 20 )); then
    echo "dap-tests: node $(node --version) is too old; the suite needs node 20 or later" >&2
    exit 1
fi

# npm ci, unless node_modules was installed from this very package-lock.json.
lock_sum="$(sha256sum tests/dap/package-lock.json | cut -d' ' -f1)"
stamp=tests/dap/node_modules/.gantry-lock-sha256
if [[ -f "$stamp" && "$(cat "$stamp")" == "$lock_sum" ]]; then
    echo "dap-tests: tests/dap/node_modules is up to date"
else
    (cd tests/dap && npm ci --no-audit --no-fund)
    echo "$lock_sum" > "$stamp"
fi

if [[ -z "${GANTRY_BIN:-}" ]]; then
    cargo build --release --bin gantry
    export GANTRY_BIN="$root/target/release/gantry"
fi
if [[ ! -x "$GANTRY_BIN" ]]; then
    echo "dap-tests: GANTRY_BIN=$GANTRY_BIN is not an executable" >&2
    exit 1
fi
echo "dap-tests: gantry at $GANTRY_BIN"

# Options go to node --test; file arguments replace the default list of test files.
# (Options that take a value may be written --opt=value or --opt value.)
opts=()
files=()
takes_value='^--(test-name-pattern|test-skip-pattern|test-reporter|test-reporter-destination|test-concurrency|test-timeout|test-shard)$'
while (( $# )); do
    case "$1" in
        -*)
            opts+=("$1")
            if [[ "$1" =~ $takes_value && $# -ge 2 ]]; then
                opts+=("$2")
                shift
            fi
            ;;
        *) files+=("$1") ;;
    esac
    shift
done
if (( ${#files[@]} == 0 )); then
    files=(tests/dap/*.test.mjs)
fi

node --test "${opts[@]+"${opts[@]}"}" "${files[@]}"
