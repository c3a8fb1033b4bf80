#!/usr/bin/env python3
"""ZMQ call latency against the client's floor (issue 32, item 5).

Measures `sim.getObjectPosition` through CoppeliaSim's own Python client
(coppeliasim-zmqremoteapi-client 2.0.4) against:
  * the floor: a tiny pyzmq ROUTER server that busy-polls with NOBLOCK and answers
    every call from memory with a valid `{"ret": [...]}` CBOR reply. It never sleeps,
    so it adds no thread wake-up of its own: what is left is the client, libzmq and
    the loopback, i.e. the least any server can achieve with this client here;
  * one or more gantry binaries (e.g. before and after a change), each with the
    simulation free-running at full speed (`--fast`, the bench's headline case) and
    in real time (idle between 50 ms steps).

Every round measures every target once, in an order that rotates from round to
round, so that drifts of the machine (other builds, CPU frequency) spread over all
targets alike. One process at a time: the echo server's busy poll and a `--fast`
simulation each keep a core busy. The report pools each target's samples over the
rounds (median and p99) and gives the spread of the per-round medians.

Target: gantry's median at most 15 us above the floor's.

With --steps N, each round also times N `client.step()` calls per binary on an empty
scene in stepping mode (two round trips per step, `sim.step` and `_*executed*_`, and
nothing to simulate: the protocol's own cost).

Usage (from the repository root):
    .venv/bin/python tools/bench/zmq_floor.py [--calls 5000] [--rounds 5] \\
        [--bin after=target/release/gantry --bin before=/tmp/gantry-before] [--json out.json]
Without --bin, the binary is $GANTRY_BIN, else target/release/gantry.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import socket
import statistics
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "python"))

from gantry_proc import GantryProcess, gantry_bin  # noqa: E402

SCENE = "assets/scenes/bubble_rob.toml"
EMPTY_SCENE = "assets/scenes/bench/empty.toml"
TARGET_ABOVE_FLOOR_US = 15.0
POSITION = [0.5, -0.25, 1.0]


def echo_server(port: int) -> None:
    """A ROUTER socket answering REQ clients from memory, busy-polling with NOBLOCK.

    `zmqRemoteApi.info` gets an INFO map with the one function the benchmark calls;
    every other request gets `{"ret": [[x, y, z]]}`. The request is decoded, as any
    server must, to tell the two apart."""
    import cbor2
    import zmq

    sock = zmq.Context().socket(zmq.ROUTER)
    sock.bind(f"tcp://127.0.0.1:{port}")
    ret = cbor2.dumps({"ret": [POSITION]})
    info = cbor2.dumps({"ret": [{"getObjectPosition": {"func": {}}, "getObjectsInTree": {"func": {}},
                                 "handle_world": {"const": -1}, "handle_scene": {"const": -12},
                                 "handle_all": {"const": -2}}]})
    while True:
        try:
            *envelope, payload = sock.recv_multipart(zmq.NOBLOCK)
        except zmq.Again:
            continue
        req = cbor2.loads(payload)
        sock.send_multipart([*envelope, info if req.get("func") == "zmqRemoteApi.info" else ret])


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def call_loop(sim, handle: int, calls: int) -> list[float]:
    """`calls` timed calls of sim.getObjectPosition(handle, -1), in microseconds, after
    500 untimed ones (connection, caches, CPU frequency)."""
    for _ in range(500):
        sim.getObjectPosition(handle, -1)
    clock = time.perf_counter_ns
    samples = []
    for _ in range(calls):
        t0 = clock()
        sim.getObjectPosition(handle, -1)
        samples.append((clock() - t0) / 1000.0)
    return samples


def measure_floor(calls: int) -> list[float]:
    from coppeliasim_zmqremoteapi_client import RemoteAPIClient

    port = free_port()
    proc = multiprocessing.Process(target=echo_server, args=(port,), daemon=True)
    proc.start()
    try:
        sim = RemoteAPIClient(host="127.0.0.1", port=port).require("sim")
        return call_loop(sim, 1, calls)
    finally:
        proc.kill()
        proc.join()


def measure_gantry(binary: Path, fast: bool, calls: int) -> list[float]:
    old = os.environ.get("GANTRY_BIN")
    os.environ["GANTRY_BIN"] = str(binary)
    try:
        with GantryProcess(SCENE, fast=fast) as g:
            sim = g.client().require("sim")
            handle = sim.getObjectsInTree(sim.handle_scene, sim.handle_all, 0)[-1]
            return call_loop(sim, handle, calls)
    finally:
        if old is None:
            del os.environ["GANTRY_BIN"]
        else:
            os.environ["GANTRY_BIN"] = old


def measure_steps(binary: Path, steps: int) -> float:
    """client.step() calls per second on the empty scene, after 100 untimed ones."""
    os.environ["GANTRY_BIN"] = str(binary)
    with GantryProcess(EMPTY_SCENE, fast=True) as g:
        client = g.client()
        client.require("sim")
        client.setStepping(True)
        for _ in range(100):
            client.step()
        t0 = time.perf_counter()
        for _ in range(steps):
            client.step()
        return steps / (time.perf_counter() - t0)


def percentile(sorted_values: list[float], p: float) -> float:
    k = min(len(sorted_values) - 1, max(0, round(p / 100 * (len(sorted_values) - 1))))
    return sorted_values[k]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--calls", type=int, default=5000, help="timed calls per target and round")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--bin", action="append", default=[], metavar="NAME=PATH",
                    help="a gantry binary to measure (repeatable); default $GANTRY_BIN or target/release/gantry")
    ap.add_argument("--steps", type=int, default=0,
                    help="also time this many client.step() calls per binary and round (empty scene)")
    ap.add_argument("--json", type=Path, help="also write the figures to this file")
    args = ap.parse_args()

    binaries = []
    for spec in args.bin:
        name, _, path = spec.partition("=")
        binaries.append((name, Path(path).resolve()))
    if not binaries:
        binaries.append(("gantry", gantry_bin().resolve()))
    for name, path in binaries:
        if not path.exists():
            ap.error(f"--bin {name}: {path} does not exist")

    targets = [("floor (pyzmq ROUTER echo, busy-polling)", None, None)]
    for name, path in binaries:
        targets.append((f"{name}, --fast (free-running)", path, True))
        targets.append((f"{name}, real time (idle between steps)", path, False))
    samples: dict[str, list[float]] = {t[0]: [] for t in targets}
    medians: dict[str, list[float]] = {t[0]: [] for t in targets}
    rates: dict[str, list[float]] = {name: [] for name, _ in binaries}

    for r in range(args.rounds):
        order = targets[r % len(targets):] + targets[:r % len(targets)]
        line = []
        for label, path, fast in order:
            s = measure_floor(args.calls) if path is None else measure_gantry(path, fast, args.calls)
            samples[label] += s
            medians[label].append(statistics.median(s))
            line.append(f"{label.split(',')[0].split(' ')[0]}{'' if path is None else ('/fast' if fast else '/rt')} "
                        f"{medians[label][-1]:.1f}")
        if args.steps:
            for name, path in binaries[r % len(binaries):] + binaries[:r % len(binaries)]:
                rates[name].append(measure_steps(path, args.steps))
            line.append("steps/s " + ", ".join(f"{name} {rates[name][-1]:.0f}" for name, _ in binaries))
        print(f"round {r + 1}: medians (us): " + ", ".join(line), flush=True)

    floor_label = targets[0][0]
    floor_med = statistics.median(samples[floor_label])
    print()
    print(f"sim.getObjectPosition through coppeliasim-zmqremoteapi-client, {args.rounds} rounds x "
          f"{args.calls} calls per target, interleaved")
    print(f"| target | median (us) | p99 (us) | per-round medians (us) | median above floor (us) |")
    print(f"|---|---|---|---|---|")
    report = {"calls": args.calls, "rounds": args.rounds, "target_above_floor_us": TARGET_ABOVE_FLOOR_US,
              "targets": {}}
    ok = True
    for label, path, fast in targets:
        s = sorted(samples[label])
        med, p99 = statistics.median(s), percentile(s, 99)
        above = med - floor_med
        rounds = ", ".join(f"{m:.0f}" for m in medians[label])
        print(f"| {label} | {med:.1f} | {p99:.1f} | {rounds} | {'-' if path is None else f'{above:+.1f}'} |")
        report["targets"][label] = {"median_us": med, "p99_us": p99, "round_medians_us": medians[label],
                                    "above_floor_us": above, "binary": str(path) if path else None}
        if path is not None and path == binaries[-1][1]:
            ok &= above <= TARGET_ABOVE_FLOOR_US
    for name, _ in binaries:
        if rates[name]:
            print(f"{name}: client.step() on an empty scene, median of rounds "
                  f"{statistics.median(rates[name]):.0f} steps/s ({', '.join(f'{x:.0f}' for x in rates[name])})")
            report.setdefault("empty_steps_per_s", {})[name] = rates[name]
    print(f"target: {binaries[-1][0]} at most {TARGET_ABOVE_FLOOR_US:.0f} us above the floor (both modes):",
          "met" if ok else "NOT met")
    if args.json:
        args.json.write_text(json.dumps(report, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
