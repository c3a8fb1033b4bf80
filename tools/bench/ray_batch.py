#!/usr/bin/env python3
"""gantry.batch on Ray against the same runs one after another: the wall time of a
batch of BubbleRob runs (one wheel speed each, --sim-seconds of simulated time,
about 3 s of wall time per run at the default) on a local Ray with --cpus CPUs,
against gantry.batch.run_local in this process.

Ray is started once and its workers are warmed up (one short task per CPU, each
seen to run in its own worker process) before anything is timed, so that the figure
is the batch's and not Ray's start-up or the workers' first import of gantry. Each
repeat times the serial batch, then the Ray batch; the figures are the medians. The
two batches must give identical results (the simulation is deterministic), or the
script fails.

Prints one machine-readable line, then exits 1 if the speed-up is below
--min-speedup:

    ray_batch runs=8 cpus=2 sim_s=450 repeat=3 serial_s=24.1 ray_s=12.6 speedup=1.91

    .venv/bin/python tools/bench/ray_batch.py [--runs 8] [--sim-seconds 450] [--repeat 3]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path
from typing import Any

import ray

import gantry
import gantry.batch

SCENE = "bubble_rob"  # the bundled scene: the same on every machine


def bubble_rob(client: gantry.Client, sim: Any, slider: float, seconds: float) -> dict:
    """Sets the controller's speed slider (0..10: 50..300 deg/s at the wheels) and
    runs `seconds` of simulated time as fast as possible."""
    rover = sim.getObject("/bubbleRob")
    script = sim.getScript(sim.scripttype_childscript, rover)
    sim.callScriptFunction("speedChange_callback", script, 0, 1, slider)
    client.advance(round(seconds / sim.getSimulationTimeStep()))
    return {
        "sim_time": sim.getSimulationTime(),
        "pose": sim.getObjectPose(rover, sim.handle_world),
    }


def worker_pid(client: gantry.Client, sim: Any) -> dict:
    # Long enough that the scheduler cannot hand both warm-up tasks to one worker.
    time.sleep(0.5)
    return {"pid": os.getpid()}


def results(batch: gantry.batch.BatchResult) -> list[dict]:
    if not batch.ok:
        sys.exit(f"ray_batch: a run failed:\n{batch.failures[0]['error']}")
    return [{k: v for k, v in row.items() if k != "wall_s"} for row in batch.rows]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=8)
    ap.add_argument("--sim-seconds", type=float, default=450.0, help="simulated seconds per run")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--cpus", type=int, default=2, help="the local Ray's num_cpus")
    ap.add_argument("--min-speedup", type=float, default=1.7)
    ap.add_argument("--json", type=Path, help="also write the figures to this file")
    args = ap.parse_args()

    ray.init(num_cpus=args.cpus, include_dashboard=False, logging_level="warning")
    warm = gantry.batch.run(worker_pid, [{}] * args.cpus, scene=SCENE, progress=False)
    workers = {row["pid"] for row in results(warm)}
    print(f"# warm-up: {len(workers)} Ray worker processes ready (of {args.cpus} CPUs), not timed",
          file=sys.stderr)

    sliders = [10 * i / max(1, args.runs - 1) for i in range(args.runs)]
    runs = gantry.batch.grid(slider=sliders, seconds=[args.sim_seconds])
    serial_s: list[float] = []
    ray_s: list[float] = []
    run_wall_s: list[float] = []
    for _ in range(args.repeat):
        serial = gantry.batch.run_local(bubble_rob, runs, scene=SCENE, progress=False)
        parallel = gantry.batch.run(bubble_rob, runs, scene=SCENE, progress=False)
        if results(parallel) != results(serial):
            sys.exit("ray_batch: the Ray batch's results differ from the serial batch's")
        serial_s.append(serial.wall_s)
        ray_s.append(parallel.wall_s)
        run_wall_s += [row["wall_s"] for row in serial]
    ray.shutdown()

    serial_med, ray_med = statistics.median(serial_s), statistics.median(ray_s)
    speedup = serial_med / ray_med
    print(f"# per run: {statistics.median(run_wall_s):.2f} s wall (median, serial); "
          f"serial batches {[round(s, 2) for s in serial_s]} s, Ray batches {[round(s, 2) for s in ray_s]} s",
          file=sys.stderr)
    print(f"ray_batch runs={args.runs} cpus={args.cpus} sim_s={args.sim_seconds:g} repeat={args.repeat} "
          f"serial_s={serial_med:.2f} ray_s={ray_med:.2f} speedup={speedup:.2f}")
    if args.json:
        args.json.write_text(json.dumps({
            "runs": args.runs, "cpus": args.cpus, "sim_seconds": args.sim_seconds,
            "run_wall_s": statistics.median(run_wall_s), "serial_s": serial_med, "ray_s": ray_med,
            "speedup": speedup, "min_speedup": args.min_speedup,
        }, indent=2))
    if speedup < args.min_speedup:
        print(f"ray_batch: speed-up {speedup:.2f} is below --min-speedup {args.min_speedup}", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
