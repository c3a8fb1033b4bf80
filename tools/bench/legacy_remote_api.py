"""The legacy remote API's costs, with the real client (V-REP's remoteApi.so and vrep.py,
pypot's copy; see tests/python/test_legacy_remote_api.py): the round trip of a blocking
`simxGetObjectPosition`, and synchronous stepping (`simxSynchronousTrigger` + a blocking
read per step) against the headless step rate of the same scene.

    .venv/bin/python tools/bench/legacy_remote_api.py [--calls 2000] [--steps 500]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "python"))

from gantry_proc import GantryProcess  # noqa: E402
from test_legacy_remote_api import connect, legacy_port, load_bindings  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--calls", type=int, default=2000)
    ap.add_argument("--steps", type=int, default=500)
    args = ap.parse_args()
    vrep = load_bindings()
    with GantryProcess("assets/scenes/bubble_rob.toml", fast=False, extra=["--legacy-port", "0"]) as g:
        cid = connect(vrep, legacy_port(g))
        blocking = vrep.simx_opmode_blocking
        _, rob = vrep.simxGetObjectHandle(cid, "bubbleRob", blocking)
        lat = []
        for _ in range(args.calls):
            t = time.perf_counter()
            vrep.simxGetObjectPosition(cid, rob, -1, blocking)
            lat.append((time.perf_counter() - t) * 1e6)
        lat.sort()
        print(f"blocking simxGetObjectPosition: median {statistics.median(lat):.0f} us, "
              f"p99 {lat[int(0.99 * len(lat))]:.0f} us over {args.calls} calls")
        vrep.simxStopSimulation(cid, blocking)
        vrep.simxSynchronous(cid, True)
        vrep.simxStartSimulation(cid, blocking)
        t = time.perf_counter()
        for _ in range(args.steps):
            vrep.simxSynchronousTrigger(cid)
            vrep.simxGetObjectPosition(cid, rob, -1, blocking)
        dt = time.perf_counter() - t
        print(f"synchronous stepping (trigger + blocking read): {args.steps / dt:.0f} steps/s")
        vrep.simxSynchronous(cid, False)
        vrep.simxFinish(cid)


if __name__ == "__main__":
    main()
