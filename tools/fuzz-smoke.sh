#!/usr/bin/env bash
# Runs every cargo-fuzz target in fuzz/ for a short, bounded time and fails on any
# crash, panic, timeout or out-of-memory. Part of tools/test-all.sh.
#
#   bash tools/fuzz-smoke.sh                  # every target, 15 s each
#   bash tools/fuzz-smoke.sh --seconds 300    # longer (the fuzz/README.md figures)
#   bash tools/fuzz-smoke.sh scene urdf       # only these targets
#   bash tools/fuzz-smoke.sh --no-sanitizer   # without AddressSanitizer (the test
#                                             # command's smoke run: the targets are safe
#                                             # Rust, and ASan doubles the build and run)
#
# Installs what it needs when missing, and nothing when it is there: a nightly
# toolchain (rustup, minimal profile) and cargo-fuzz (cargo install --locked). Each
# target starts from its committed seeds (fuzz/seeds/TARGET) plus the corpus earlier runs
# grew (fuzz/corpus/TARGET, git-ignored) and uses fuzz/TARGET.dict when there is one.
# libFuzzer's output goes to fuzz/target/smoke-logs/TARGET.log; a crash leaves its input
# in fuzz/artifacts/TARGET/ and prints how to reproduce it.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

seconds=15
sanitizer=address
targets=()
while (($#)); do
    case "$1" in
        --seconds) seconds="$2"; shift 2 ;;
        --seconds=*) seconds="${1#*=}"; shift ;;
        --no-sanitizer) sanitizer=none; shift ;;
        -h|--help) sed -n '2,19p' "${BASH_SOURCE[0]}"; exit 0 ;;
        *) targets+=("$1"); shift ;;
    esac
done

if ! rustup run nightly rustc --version >/dev/null 2>&1; then
    echo "fuzz-smoke: installing the nightly toolchain (rustup, minimal profile)"
    rustup toolchain install nightly --profile minimal >/dev/null
fi
if ! cargo fuzz --version >/dev/null 2>&1; then
    echo "fuzz-smoke: installing cargo-fuzz"
    cargo install cargo-fuzz --locked --quiet
fi

cd "$root/fuzz"
if ((${#targets[@]} == 0)); then
    mapfile -t targets < <(cargo +nightly fuzz list)
fi
echo "fuzz-smoke: building ${targets[*]} ($(rustup run nightly rustc --version))"
# One build for every target; `fuzz run` below reuses it (same flags: release, debug
# assertions and overflow checks on, the sanitizer chosen above).
logs="$root/fuzz/target/smoke-logs"
mkdir -p "$logs"
cargo +nightly fuzz build --sanitizer "$sanitizer" >"$logs/build.log" 2>&1 || { tail -60 "$logs/build.log" >&2; exit 1; }
failed=()
printf '%-12s %12s %8s %8s  %s\n' target executions exec/s corpus result
for t in "${targets[@]}"; do
    mkdir -p "corpus/$t"
    dirs=("corpus/$t")
    [[ -d "seeds/$t" ]] && dirs+=("seeds/$t")
    opts=("-max_total_time=$seconds" -timeout=20 -rss_limit_mb=2048 -print_final_stats=1)
    [[ -f "$t.dict" ]] && opts+=("-dict=$t.dict")
    log="$logs/$t.log"
    if nice cargo +nightly fuzz run --sanitizer "$sanitizer" "$t" "${dirs[@]}" -- "${opts[@]}" >"$log" 2>&1; then
        result=ok
    else
        result=FAILED
        failed+=("$t")
    fi
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
    corpus=$(find "corpus/$t" -type f | wc -l)
    printf '%-12s %12s %8s %8s  %s\n' "$t" "${runs:-?}" "${speed:-?}" "$corpus" "$result"
    if [[ $result == FAILED ]]; then
        grep -E -A 30 '^(==[0-9]+==ERROR|thread .* panicked|ERROR: libFuzzer)' "$log" | head -60 >&2 \
            || tail -40 "$log" >&2
        echo "fuzz-smoke: $t failed; full log $log; reproduce with" >&2
        echo "  cd fuzz && cargo +nightly fuzz run $t artifacts/$t/<file>" >&2
    fi
done
if ((${#failed[@]})); then
    echo "fuzz-smoke: FAILED: ${failed[*]}" >&2
    exit 1
fi
echo "fuzz-smoke: ${#targets[@]} targets, ${seconds} s each, sanitizer $sanitizer, no crash"
