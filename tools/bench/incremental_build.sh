#!/usr/bin/env bash
# Incremental build of the gantry binary after touching one file (issue 32, item 6):
# the wall time of `cargo build --profile ci --bin gantry` once a file in each floor of
# the simulation has changed. Cargo rebuilds the touched crate and every crate above
# it, so the figure shows what the crate boundaries save: a change to the registry
# (crates/sim-core/src/api) no longer recompiles the world and the scene model.
#
#     bash tools/bench/incremental_build.sh [--rounds N] [FILE ...]
#
# Without FILEs it touches one file of the registry, the world and the scene model.
# Each FILE is touched and rebuilt N times (default 3); the median is reported. Run it
# on a quiet machine: the figures are wall times.
set -euo pipefail
cd "$(dirname "$0")/../.."

rounds=3
files=()
while [ $# -gt 0 ]; do
    case "$1" in
        --rounds) rounds=$2; shift 2 ;;
        *) files+=("$1"); shift ;;
    esac
done
if [ ${#files[@]} -eq 0 ]; then
    files=(crates/sim-core/src/api/signals.rs crates/world/src/world/query.rs crates/scene/src/scene/load.rs)
fi

build() { cargo build --profile ci --bin gantry --quiet; }
build
echo "| touched file | rebuild, median of $rounds (s) | each (s) |"
echo "|---|---|---|"
for f in "${files[@]}"; do
    [ -f "$f" ] || { echo "no such file: $f" >&2; exit 2; }
    times=()
    for _ in $(seq "$rounds"); do
        touch "$f"
        t0=$EPOCHREALTIME
        build
        t1=$EPOCHREALTIME
        times+=("$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }')")
    done
    median=$(printf '%s\n' "${times[@]}" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
    printf '| `%s` | %.1f | %s |\n' "$f" "$median" "$(printf '%.1f ' "${times[@]}")"
done
