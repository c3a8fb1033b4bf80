"""What gantry in-process costs from Python (issue 18), in one run on one machine.

* Call latency of ``sim.getObjectPosition`` (median and p99, microseconds) three ways:
  in-process (``gantry.Client``), over the ZMQ remote API with CoppeliaSim's own client
  against ``gantry run --fast``, and PyBullet's ``getBasePositionAndOrientation`` in
  DIRECT mode (the in-process reference researchers know). Each sample times one call
  with ``perf_counter_ns``, so the clock's own cost (~0.1 us) is included everywhere.
* Step rate of bubble_rob: in-process ``client.advance(n)`` and a ``sim.step()`` loop
  against the headless binary (``gantry run --fast --steps N --no-listen``), which runs
  the same simulation with no client at all. Runs are interleaved, ``--repeat`` times;
  the figures are medians.

Targets: median < 2 us in-process; in-process stepping no more than 5 % below the
binary's rate.

    .venv/bin/python tools/bench/python_inproc.py [--calls 200000] [--steps 5000] [--repeat 3] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "python"))
from gantry_proc import GantryProcess, gantry_bin  # noqa: E402

import gantry  # noqa: E402

SCENE = REPO / "assets" / "scenes" / "bubble_rob.toml"
RATE = re.compile(r"steps_per_s=([0-9.]+)")
TARGET_MEDIAN_US = 2.0
TARGET_STEP_RATIO = 0.95


def percentile(sorted_values: list[float], p: float) -> float:
    k = min(len(sorted_values) - 1, max(0, round(p / 100 * (len(sorted_values) - 1))))
    return sorted_values[k]


def timed(call, calls: int) -> tuple[float, float]:
    for _ in range(min(calls, 2000)):  # warm-up
        call()
    clock = time.perf_counter_ns
    samples = []
    for _ in range(calls):
        t0 = clock()
        call()
        samples.append((clock() - t0) / 1000.0)
    samples.sort()
    return statistics.median(samples), percentile(samples, 99)


def inproc_latency(calls: int) -> tuple[float, float]:
    with gantry.Client(SCENE) as client:
        sim = client.require("sim")
        client.setStepping(True)  # a held simulation: only the call is measured
        h = sim.getObject("/bubbleRob")
        world = sim.handle_world
        return timed(lambda: sim.getObjectPosition(h, world), calls)


def zmq_latency(calls: int) -> tuple[float, float]:
    with GantryProcess(SCENE, fast=True) as g:
        sim = g.client().require("sim")
        h = sim.getObject("/bubbleRob")
        return timed(lambda: sim.getObjectPosition(h, -1), calls)


def pybullet_latency(calls: int) -> tuple[float, float]:
    import pybullet as pb
    import pybullet_data

    cid = pb.connect(pb.DIRECT)
    try:
        pb.setAdditionalSearchPath(pybullet_data.getDataPath(), physicsClientId=cid)
        body = pb.loadURDF("r2d2.urdf", [0, 0, 0.5], physicsClientId=cid)
        return timed(lambda: pb.getBasePositionAndOrientation(body, physicsClientId=cid), calls)
    finally:
        pb.disconnect(cid)


def binary_rate(steps: int) -> float:
    out = subprocess.run(
        [str(gantry_bin()), "run", str(SCENE), "--fast", "--steps", str(steps), "--no-listen"],
        capture_output=True, text=True, check=True, timeout=600,
    ).stdout
    m = RATE.search(out)
    if not m:
        raise RuntimeError(f"no steps_per_s in gantry's output: {out!r}")
    return float(m.group(1))


def inproc_rate(steps: int, loop: bool) -> float:
    with gantry.Client(SCENE, autostart=False, realtime=False) as client:
        sim = client.require("sim")
        t0 = time.perf_counter()
        if loop:
            client.setStepping(True)
            sim.startSimulation()
            for _ in range(steps):
                sim.step()
        else:
            client.advance(steps)
        wall = time.perf_counter() - t0
        assert abs(sim.getSimulationTime() - steps * sim.getSimulationTimeStep()) < 1e-6
    return steps / wall


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--calls", type=int, default=200_000)
    ap.add_argument("--zmq-calls", type=int, default=20_000)
    ap.add_argument("--steps", type=int, default=5000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", type=Path, help="also write the figures to this file")
    args = ap.parse_args()

    lat = {"inproc": [], "zmq": [], "pybullet": []}
    rates = {"binary": [], "advance": [], "step_loop": []}
    for run in range(1, args.repeat + 1):
        lat["inproc"].append(inproc_latency(args.calls))
        lat["pybullet"].append(pybullet_latency(args.calls))
        lat["zmq"].append(zmq_latency(args.zmq_calls))
        rates["binary"].append(binary_rate(args.steps))
        rates["advance"].append(inproc_rate(args.steps, loop=False))
        rates["step_loop"].append(inproc_rate(args.steps, loop=True))
        print(
            f"run {run}: getObjectPosition in-process {lat['inproc'][-1][0]:.2f} us "
            f"(p99 {lat['inproc'][-1][1]:.2f}), ZMQ {lat['zmq'][-1][0]:.1f} us (p99 {lat['zmq'][-1][1]:.1f}), "
            f"PyBullet getBasePositionAndOrientation {lat['pybullet'][-1][0]:.2f} us "
            f"(p99 {lat['pybullet'][-1][1]:.2f}); steps/s binary {rates['binary'][-1]:.0f}, "
            f"advance {rates['advance'][-1]:.0f}, sim.step loop {rates['step_loop'][-1]:.0f}",
            flush=True,
        )

    def med(pairs, i):
        return statistics.median(p[i] for p in pairs)

    figures = {
        "inproc_median_us": med(lat["inproc"], 0), "inproc_p99_us": med(lat["inproc"], 1),
        "zmq_median_us": med(lat["zmq"], 0), "zmq_p99_us": med(lat["zmq"], 1),
        "pybullet_median_us": med(lat["pybullet"], 0), "pybullet_p99_us": med(lat["pybullet"], 1),
        "binary_steps_per_s": statistics.median(rates["binary"]),
        "advance_steps_per_s": statistics.median(rates["advance"]),
        "step_loop_steps_per_s": statistics.median(rates["step_loop"]),
    }
    figures["advance_ratio"] = figures["advance_steps_per_s"] / figures["binary_steps_per_s"]
    figures["step_loop_ratio"] = figures["step_loop_steps_per_s"] / figures["binary_steps_per_s"]
    print(
        "python_inproc "
        + " ".join(f"{k}={v:.3f}" if isinstance(v, float) else f"{k}={v}" for k, v in figures.items())
    )
    ok = figures["inproc_median_us"] < TARGET_MEDIAN_US and min(
        figures["advance_ratio"], figures["step_loop_ratio"]) >= TARGET_STEP_RATIO
    print(f"targets: median < {TARGET_MEDIAN_US} us, in-process stepping >= {TARGET_STEP_RATIO:.0%} of the binary:",
          "met" if ok else "NOT met")
    if args.json:
        args.json.write_text(json.dumps(figures, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
