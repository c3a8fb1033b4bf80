#!/usr/bin/env python3
"""Start-up time and peak memory of gantry on the embedded `showroom` scene (issue 8).

* start-up: wall time from spawning `gantry run --steps 1 --fast` to its exit, i.e.
  process start, scene load, physics and Lua set-up, listeners bound, the first step,
  and a clean shutdown (median of --runs runs);
* peak memory: the largest resident set (ru_maxrss from wait4) of a run of 2,000 steps
  with every listener open (text, ZMQ, HTTP), the arm's and the rover's scripts and the
  rover's vision sensor running.

Prints JSON. GANTRY_BIN selects the binary (default target/release/gantry).
    python3 tools/bench/startup.py [--runs 10]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LISTEN = ["--text-port", "0", "--zmq-port", "0", "--http-port", "0"]


def run(args: list[str]) -> tuple[float, int]:
    """(wall seconds, peak RSS in KiB) of one gantry run."""
    binary = os.environ.get("GANTRY_BIN", str(ROOT / "target/release/gantry"))
    t0 = time.perf_counter()
    proc = subprocess.Popen([binary, "run", *args], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise SystemExit(f"gantry run {' '.join(args)} exited with {proc.returncode}")
    return wall, usage.ru_maxrss


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=10)
    args = ap.parse_args()
    run(["--steps", "1", "--fast", *LISTEN])  # warm the page cache
    first_step = [run(["--steps", "1", "--fast", *LISTEN])[0] for _ in range(args.runs)]
    _, peak_kib = run(["--steps", "2000", "--fast", *LISTEN])
    print(json.dumps({
        "scene": "showroom (embedded)",
        "start_to_first_step_ms": statistics.median(first_step) * 1000,
        "start_to_first_step_max_ms": max(first_step) * 1000,
        "peak_rss_mib": peak_kib / 1024,
    }, indent=2))


if __name__ == "__main__":
    main()
