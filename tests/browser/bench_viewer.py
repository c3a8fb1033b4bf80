"""Benchmark: simulation steps per second of the showroom run flat out (``gantry --fast``)
with 0 and with 4 viewers connected (issue 7; target: under 5 % slower).

    bash tools/browser-test.sh --bench          # or, with the venv ready:
    .venv/bin/python tests/browser/bench_viewer.py [--steps 3000] [--rounds 3] [--clients 4]

Each measurement replays the same run: stop (the initial scene comes back), start, and
time how long the simulation takes to reach ``--steps`` steps (``GET /api/status``
polled every 20 ms). The showroom's cost per step depends on where BubbleRob drives
(its vision sensor renders what it sees), so replaying the identical, deterministic run
compares like with like. Rounds alternate 0 and N viewers so drift hits both alike.

Three layouts, because on a small machine the browsers' software rendering (WebGL2 on
SwiftShader: no GPU) competes with the simulator for the same cores:
* ``raw``: N bare WebSocket clients that read and discard everything the viewer sends
  (scene, meshes, frames, panels, images): the server-side cost alone, as when the
  browsers run on other machines, the viewer's intended use;
* ``pinned``: N real headless chromium pages, gantry on core 0 and the browsers on the
  other cores (Linux ``taskset``);
* ``shared``: N real pages and gantry on every core: one small machine doing both,
  browser rendering included.
"""

from __future__ import annotations

import argparse
import base64
import os
import shutil
import socket
import statistics
import subprocess
import threading
import time

from playwright.sync_api import sync_playwright

from viewer_util import CHROMIUM, CHROMIUM_ARGS, Gantry, wait_for


class RawClient:
    """A WebSocket client that reads and discards: the server does all its work for it."""

    def __init__(self, host: str, port: int):
        self.sock = socket.create_connection((host, port))
        key = base64.b64encode(os.urandom(16)).decode()
        self.sock.sendall((f"GET /ws HTTP/1.1\r\nHost: {host}:{port}\r\nUpgrade: websocket\r\n"
                           f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n"
                           "Sec-WebSocket-Version: 13\r\n\r\n").encode())
        self.bytes = 0
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        try:
            while chunk := self.sock.recv(1 << 20):
                self.bytes += len(chunk)
        except OSError:
            pass

    def close(self):
        self.sock.close()


class Viewers:
    """Connects and disconnects N viewers of one kind."""

    def __init__(self, layout: str, g: Gantry, playwright, browser_cores: str | None):
        self.layout, self.g, self.pw, self.cores = layout, g, playwright, browser_cores
        self.open: list = []

    def connect(self, n: int) -> None:
        for _ in range(n):
            if self.layout == "raw":
                self.open.append(RawClient(*self.g.addr["http"]))
                continue
            b = self.pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
            if self.cores:
                pin_chromium(self.cores)  # pages opened later inherit the affinity
            pg = b.new_page(viewport={"width": 1280, "height": 800})
            pg.goto(self.g.url)
            pg.wait_for_function("window.gantry && gantry.framesRendered > 2", timeout=30_000)
            self.open.append(b)
        if self.cores:
            pin_chromium(self.cores)
        wait_for(lambda: self.g.status()["viewers"] == n, what=f"{n} viewers connected")

    def received(self) -> int:
        return sum(c.bytes for c in self.open) if self.layout == "raw" else 0

    def close(self) -> None:
        for v in self.open:
            v.close()
        self.open.clear()
        wait_for(lambda: self.g.status()["viewers"] == 0, what="viewers gone")


def pin_chromium(cores: str) -> None:
    # /usr/bin/chromium is a wrapper script; its processes are named chromium.
    for pid in subprocess.run(["pgrep", "chromium"], capture_output=True, text=True).stdout.split():
        subprocess.run(["taskset", "-a", "-p", "-c", cores, pid], capture_output=True)


def replay(g: Gantry, sim, steps: int) -> float:
    """Replays the run from its initial state to `steps` steps; returns steps/s."""
    sim.stopSimulation()
    wait_for(lambda: g.status()["state"] == 0, what="stopped")
    sim.startSimulation()
    t0 = time.monotonic()
    while True:
        s = g.status()["steps"]
        if s >= steps:
            return s / (time.monotonic() - t0)
        time.sleep(0.02)


def run_layout(layout: str, steps: int, rounds: int, clients: int) -> tuple[list[float], list[float]]:
    cores = os.cpu_count() or 1
    pin = layout == "pinned" and cores >= 2 and shutil.which("taskset")
    g = Gantry(fast=True, prefix=["taskset", "-c", "0"] if pin else None)
    zmq = g.zmq_client()
    sim = zmq.require("sim")
    idle, viewed = [], []
    try:
        with sync_playwright() as p:
            v = Viewers(layout, g, p, f"1-{cores - 1}" if pin else None)
            replay(g, sim, steps // 4)  # warm-up: caches, allocator, page cache
            for _ in range(rounds):
                idle.append(replay(g, sim, steps))
                v.connect(clients)
                before = v.received()
                t0 = time.monotonic()
                viewed.append(replay(g, sim, steps))
                mbps = (v.received() - before) / (time.monotonic() - t0) / 1e6 / clients
                v.close()
                extra = f" (each received {mbps:.2f} MB/s)" if layout == "raw" else ""
                print(f"  round: {idle[-1]:.0f} steps/s with 0, {viewed[-1]:.0f} with {clients}{extra}", flush=True)
    finally:
        g.close()
    return idle, viewed


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--steps", type=int, default=3000, help="steps per replayed run")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--clients", type=int, default=4)
    ap.add_argument("--layout", choices=["raw", "pinned", "shared", "all"], default="all")
    args = ap.parse_args()
    print(f"viewer benchmark: showroom, gantry --fast, {os.cpu_count()} cores, "
          f"{args.rounds} rounds of {args.steps}-step replays")
    for layout in ["raw", "pinned", "shared"] if args.layout == "all" else [args.layout]:
        print(f"{layout}:", flush=True)
        idle, viewed = run_layout(layout, args.steps, args.rounds, args.clients)
        a, b = statistics.mean(idle), statistics.mean(viewed)
        print(f"RESULT layout={layout} viewers=0 steps_per_s={a:.0f} viewers={args.clients} "
              f"steps_per_s={b:.0f} slowdown={100 * (a - b) / a:.1f}%", flush=True)


if __name__ == "__main__":
    main()
