"""Soak test (issue 9): a real-time gantry under many clients of every kind at once.

Starts ``gantry run SCENE`` (default: the showroom, in real time, every listener on a
free port) and, for a bounded time, drives it with

* 200 persistent text clients (asyncio): each pipelines bursts of ``<FK#...>`` packets
  whose joint values are unique to the client and the packet, and checks that every
  echo comes back, in order, unchanged;
* 20 ZMQ remote API clients (the real ``coppeliasim_zmqremoteapi_client``, one thread
  each): ``sim.getObjectPosition`` of the static ``/target`` dummy must return its
  scene position and ``sim.getSimulationTime`` must never go back;
* 4 viewer WebSockets reading the pose stream: frames must keep coming, well formed
  (finite positions, unit quaternions), with the simulation time never going back;

while it disturbs the server: text clients that send half a packet (or a whole one)
and vanish, some with a TCP reset; two text clients that send without ever reading a
reply; viewer pages that close right after the scene description; and ZMQ clients in
their own process, killed with SIGKILL in the middle of their calls. None of that may disturb the persistent clients.

Meanwhile it samples the server's open file descriptors (``/proc/PID/fd``) and
resident memory (``VmRSS``), and one more ZMQ client samples the simulation time. It
fails when:

* any persistent client saw an error (lost, reordered or altered reply, exception,
  time-out, stalled stream);
* the real-time factor after warm-up (simulation time over wall time) is below 0.9;
* after warm-up, the descriptors grew by more than the churn in flight, or the memory by
  more than 20 % + 24 MiB; or once every client has left, the descriptors are not back
  to within 8 of the count before the first client came;
* gantry does not exit with status 0 on SIGTERM at the end.

It prints a summary table either way. Run it through ``tools/soak.sh`` (which sets up
the virtual environment and builds the binary), e.g. ``bash tools/soak.sh --seconds 20``.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import math
import os
import random
import re
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from gantry_proc import REPO, ManagedProcess, gantry_bin  # noqa: E402

LISTENING = re.compile(r"listening (text|zmq|http)=([0-9.]+|\[[0-9a-fA-F:]+\]):(\d+)")
# The static IK target dummy of the showroom and fk_arm scenes, world frame, metres.
TARGET_PATH = "/target"
MSG_FRAME = 1
MIB = 1024 * 1024


class SoakGantry(ManagedProcess):
    """gantry with every listener on a free port; stdout kept for the summary line."""

    def __init__(self, scene: Path, ready_timeout: float = 60.0):
        cmd = [str(gantry_bin()), "run", str(scene), "--text-port", "0", "--zmq-port", "0",
               "--http-port", "0"]
        self.cmd = cmd
        self.log: deque[str] = deque(maxlen=5000)
        self.stdout_lines: list[str] = []
        self.proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, text=True, errors="replace")
        self.addrs: dict[str, tuple[str, int]] = {}
        ready = threading.Event()

        def drain_err():
            for line in self.proc.stderr:
                self.log.append(line.rstrip("\n"))
                m = LISTENING.search(line)
                if m:
                    self.addrs[m.group(1)] = (m.group(2).strip("[]"), int(m.group(3)))
                    if len(self.addrs) == 3:
                        ready.set()
            ready.set()

        def drain_out():
            for line in self.proc.stdout:
                self.stdout_lines.append(line.rstrip("\n"))

        threading.Thread(target=drain_err, daemon=True).start()
        threading.Thread(target=drain_out, daemon=True).start()
        ready.wait(ready_timeout)
        if len(self.addrs) != 3:
            self.close()
            raise RuntimeError(f"gantry did not report its three ports: {' '.join(cmd)}\n{self.stderr()}")

    @property
    def pid(self) -> int:
        return self.proc.pid


@dataclass
class Channel:
    """Counters of one kind of client; updated from threads and the event loop."""

    requests: int = 0
    errors: list[str] = field(default_factory=list)
    latencies: list[float] = field(default_factory=list)
    lock: threading.Lock = field(default_factory=threading.Lock)

    def ok(self, n: int, latency: float | None = None) -> None:
        with self.lock:
            self.requests += n
            if latency is not None and len(self.latencies) < 2_000_000:
                self.latencies.append(latency)

    def error(self, text: str) -> None:
        with self.lock:
            self.errors.append(text)

    def percentile(self, q: float) -> float:
        if not self.latencies:
            return float("nan")
        s = sorted(self.latencies)
        return s[min(len(s) - 1, int(q * len(s)))]


@dataclass
class Stats:
    text: Channel = field(default_factory=Channel)
    zmq: Channel = field(default_factory=Channel)
    viewer: Channel = field(default_factory=Channel)
    churn_text: int = 0
    churn_viewer: int = 0
    stalled_sent: int = 0
    zmq_killed: int = 0
    zmq_victim_calls: int = 0
    infra_errors: list[str] = field(default_factory=list)
    # (wall s, simulation time s) from the monitor client.
    sim_samples: list[tuple[float, float]] = field(default_factory=list)
    # (wall s, open fds, RSS bytes) of the server.
    proc_samples: list[tuple[float, int, int]] = field(default_factory=list)


# --------------------------------------------------------------------------- text

def fk_packet(cid: int, seq: int) -> str:
    # J1 is unique to the client, J2 to the packet: any reply delivered to the wrong
    # client, dropped, duplicated or reordered differs from what was expected.
    return f"<FK#J1={cid * 0.001:.3f},J2={seq * 1e-6:.6f},J3=0,J4=0,J5=-1.57,J6=0>"


async def text_client(cid: int, addr, stop_at: float, rate: float, ch: Channel) -> None:
    window = 4
    try:
        reader, writer = await asyncio.wait_for(asyncio.open_connection(*addr), 10)
    except (OSError, asyncio.TimeoutError) as e:
        ch.error(f"text client {cid}: cannot connect: {e!r}")
        return
    seq = 0
    try:
        await asyncio.sleep(random.uniform(0, window / rate))
        while time.monotonic() < stop_at:
            sent = [fk_packet(cid, seq + i) for i in range(window)]
            seq += window
            t0 = time.perf_counter()
            writer.write(("\n".join(sent) + "\n").encode())
            await writer.drain()
            for p in sent:
                line = await asyncio.wait_for(reader.readline(), 10)
                if not line:
                    ch.error(f"text client {cid}: connection closed by the server")
                    return
                got = line.decode(errors="replace").rstrip("\r\n")
                if got != p:
                    ch.error(f"text client {cid}: sent {p}, got {got}")
                    return
            dt = time.perf_counter() - t0
            ch.ok(window, dt)
            await asyncio.sleep(max(0.0, window / rate - dt) * random.uniform(0.5, 1.5))
    except asyncio.TimeoutError:
        ch.error(f"text client {cid}: no reply within 10 s")
    except OSError as e:
        ch.error(f"text client {cid}: {e!r}")
    finally:
        writer.close()


async def text_churn(addr, stop_at: float, stats: Stats) -> None:
    """Clients that vanish mid-request: half a packet, or a whole one, then a close
    (FIN) or a reset (RST), without reading the reply."""
    n = 0
    while time.monotonic() < stop_at:
        n += 1
        try:
            reader, writer = await asyncio.wait_for(asyncio.open_connection(*addr), 10)
            kind = n % 4
            if kind in (0, 1):
                writer.write(b"<FK#J1=0.12,J2=0.3")       # half a packet
            else:
                writer.write((fk_packet(999, n) + "\n").encode())  # a whole one, reply unread
            await writer.drain()
            if kind % 2 == 0:
                sock = writer.get_extra_info("socket")
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
                writer.transport.abort()                   # RST
            else:
                writer.close()                             # FIN
            stats.churn_text += 1
        except (OSError, asyncio.TimeoutError) as e:
            stats.infra_errors.append(f"text churn: {e!r}")
        await asyncio.sleep(random.uniform(0.02, 0.08))


async def text_stalled(sid: int, addr, stop_at: float, stats: Stats) -> None:
    """A client that keeps sending and never reads: the server must push back (stop
    reading) rather than queue replies without bound. Reset at the end."""
    try:
        reader, writer = await asyncio.wait_for(asyncio.open_connection(*addr), 10)
    except (OSError, asyncio.TimeoutError) as e:
        stats.infra_errors.append(f"stalled reader {sid}: cannot connect: {e!r}")
        return
    burst = "".join(fk_packet(500 + sid, i) + "\n" for i in range(64)).encode()
    try:
        while time.monotonic() < stop_at:
            writer.write(burst)
            try:
                await asyncio.wait_for(writer.drain(), max(0.01, stop_at - time.monotonic()))
            except asyncio.TimeoutError:
                break  # the server stopped reading: what it should do
            stats.stalled_sent += 64
            await asyncio.sleep(0.01)
    except OSError:
        pass  # closed by the server (e.g. a write time-out): acceptable too
    finally:
        writer.transport.abort()


# ------------------------------------------------------------------------- viewer

def check_frame(data: bytes) -> str | None:
    """None when the pose frame is well formed, else what is wrong."""
    if len(data) < 16:
        return f"short frame ({len(data)} bytes)"
    kind, poses, _drawings, _zero = struct.unpack_from("<4I", data, 0)
    if kind != MSG_FRAME:
        return None
    if len(data) < 16 + 32 * poses:
        return f"frame of {poses} poses in {len(data)} bytes"
    for i in range(poses):
        _idx, x, y, z, qx, qy, qz, qw = struct.unpack_from("<I7f", data, 16 + 32 * i)
        if not all(math.isfinite(v) for v in (x, y, z, qx, qy, qz, qw)):
            return "non-finite pose"
        n = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
        if abs(n - 1.0) > 1e-3:
            return f"quaternion of norm {n}"
    return None


async def viewer(vid: int, uri: str, stop_at: float, ch: Channel) -> None:
    from websockets.asyncio.client import connect

    frames = 0
    last_time = -1.0
    last_frame = time.monotonic()
    try:
        async with connect(uri, max_size=None, open_timeout=10, ping_interval=None,
                           close_timeout=2) as ws:
            while time.monotonic() < stop_at:
                msg = await asyncio.wait_for(ws.recv(), 5)
                now = time.monotonic()
                if isinstance(msg, bytes):
                    if len(msg) >= 4 and struct.unpack_from("<I", msg)[0] == MSG_FRAME:
                        problem = check_frame(msg)
                        if problem:
                            ch.error(f"viewer {vid}: {problem}")
                            return
                        gap = now - last_frame
                        last_frame = now
                        frames += 1
                        ch.ok(1, gap)
                    continue
                m = json.loads(msg)
                if m.get("t") == "tick":
                    t = float(m["time"])
                    if t < last_time:
                        ch.error(f"viewer {vid}: simulation time went back from {last_time} to {t}")
                        return
                    last_time = t
                if now - last_frame > 3.0:
                    ch.error(f"viewer {vid}: no pose frame for {now - last_frame:.1f} s")
                    return
    except asyncio.TimeoutError:
        ch.error(f"viewer {vid}: no message for 5 s (after {frames} frames)")
    except Exception as e:  # noqa: BLE001 - any failure of a persistent client counts
        ch.error(f"viewer {vid}: {e!r}")


async def viewer_churn(uri: str, stop_at: float, stats: Stats) -> None:
    """Pages that leave right after the scene description (or before it)."""
    from websockets.asyncio.client import connect

    n = 0
    while time.monotonic() < stop_at:
        n += 1
        try:
            ws = await connect(uri, max_size=None, open_timeout=10, ping_interval=None, close_timeout=1)
            if n % 2:
                await asyncio.wait_for(ws.recv(), 5)
                await ws.close()
            else:
                ws.transport.abort()
            stats.churn_viewer += 1
        except Exception as e:  # noqa: BLE001
            stats.infra_errors.append(f"viewer churn: {e!r}")
        await asyncio.sleep(random.uniform(0.3, 0.7))


# ---------------------------------------------------------------------------- zmq

@dataclass
class Deadline:
    """When the load ends; known only once every ZMQ client has set up."""

    stop_at: float


def zmq_worker(wid: int, host: str, port: int, deadline: Deadline, rate: float, ch: Channel,
               started: threading.Barrier) -> None:
    from coppeliasim_zmqremoteapi_client import RemoteAPIClient

    client = RemoteAPIClient(host=host, port=port)
    try:
        try:
            sim = client.require("sim")
            target = sim.getObject(TARGET_PATH)
            expected = sim.getObjectPosition(target, sim.handle_world)
        except Exception as e:  # noqa: BLE001
            ch.error(f"zmq client {wid}: set-up failed: {e!r}")
            started.abort()
            return
        try:
            started.wait(60)
        except threading.BrokenBarrierError:
            return
        last_t = -1.0
        while time.monotonic() < deadline.stop_at:
            t0 = time.perf_counter()
            pos = sim.getObjectPosition(target, sim.handle_world)
            if len(pos) != 3 or any(abs(a - b) > 1e-9 for a, b in zip(pos, expected)):
                ch.error(f"zmq client {wid}: /target at {pos}, expected {expected}")
                return
            t = sim.getSimulationTime()
            if t < last_t:
                ch.error(f"zmq client {wid}: simulation time went back from {last_t} to {t}")
                return
            last_t = t
            dt = time.perf_counter() - t0
            ch.ok(2, dt / 2)
            time.sleep(max(0.0, 2 / rate - dt) * random.uniform(0.5, 1.5))
    except Exception as e:  # noqa: BLE001 - any failure of a persistent client counts
        ch.error(f"zmq client {wid}: {e!r}")
    finally:
        client.socket.close(linger=0)
        client.context.term()


def zmq_monitor(host: str, port: int, stop_at: float, stats: Stats) -> None:
    """Samples the simulation time twice a second, for the real-time factor."""
    from coppeliasim_zmqremoteapi_client import RemoteAPIClient

    client = RemoteAPIClient(host=host, port=port)
    try:
        sim = client.require("sim")
        while time.monotonic() < stop_at:
            t0 = time.monotonic()
            t = sim.getSimulationTime()
            t1 = time.monotonic()
            stats.sim_samples.append(((t0 + t1) / 2, t))
            time.sleep(0.5)
    except Exception as e:  # noqa: BLE001
        stats.zmq.error(f"zmq monitor: {e!r}")
    finally:
        client.socket.close(linger=0)
        client.context.term()


def zmq_killer(host: str, port: int, stop_at: float, stats: Stats) -> None:
    """Every 1.5-3 s: a ZMQ client in its own process, SIGKILLed while it calls."""
    while time.monotonic() < stop_at - 2:
        victim = subprocess.Popen([sys.executable, __file__, "--zmq-victim", f"{host}:{port}"],
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            line = ""
            ready = threading.Event()

            def read_ready():
                nonlocal line
                line = victim.stdout.readline()
                ready.set()

            threading.Thread(target=read_ready, daemon=True).start()
            if not ready.wait(30) or not line.startswith("ready"):
                stats.infra_errors.append(f"zmq victim did not start: {line!r} {victim.stderr.read() if victim.poll() is not None else ''}")
            else:
                time.sleep(random.uniform(0.05, 0.4))
                victim.send_signal(signal.SIGKILL)
                stats.zmq_killed += 1
        finally:
            if victim.poll() is None:
                victim.kill()
            victim.wait(10)
        time.sleep(random.uniform(1.5, 3.0))


def zmq_victim(addr: str) -> None:
    """Child-process mode: call as fast as possible until killed."""
    from coppeliasim_zmqremoteapi_client import RemoteAPIClient

    host, port = addr.rsplit(":", 1)
    client = RemoteAPIClient(host=host, port=int(port))
    sim = client.require("sim")
    target = sim.getObject(TARGET_PATH)
    sim.getObjectPosition(target, sim.handle_world)
    print("ready", flush=True)
    while True:
        sim.getObjectPosition(target, sim.handle_world)
        sim.getSimulationTime()


# ----------------------------------------------------------------------- sampling

def fd_count(pid: int) -> int:
    try:
        return len(os.listdir(f"/proc/{pid}/fd"))
    except OSError:
        return -1


def rss_bytes(pid: int) -> int:
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return -1


def sampler(pid: int, stop: threading.Event, stats: Stats) -> None:
    while not stop.is_set():
        stats.proc_samples.append((time.monotonic(), fd_count(pid), rss_bytes(pid)))
        stop.wait(0.5)


def sample_at(samples, t: float):
    """The first sample at or after t (the last one if none)."""
    for s in samples:
        if s[0] >= t:
            return s
    return samples[-1]


def rtf_between(samples, t0: float, t1: float) -> float:
    pts = [s for s in samples if t0 <= s[0] <= t1]
    if len(pts) < 2:
        return float("nan")
    (w0, s0), (w1, s1) = pts[0], pts[-1]
    return (s1 - s0) / (w1 - w0) if w1 > w0 else float("nan")


# --------------------------------------------------------------------------- main

async def run_async_clients(addrs, args, stop_at: float, stats: Stats) -> None:
    text_addr = addrs["text"]
    host, hport = addrs["http"]
    uri = f"ws://{host}:{hport}/ws"
    tasks = [asyncio.create_task(text_client(i, text_addr, stop_at, args.text_rate, stats.text))
             for i in range(args.text_clients)]
    tasks += [asyncio.create_task(viewer(i, uri, stop_at, stats.viewer)) for i in range(args.viewers)]
    tasks.append(asyncio.create_task(text_churn(text_addr, stop_at, stats)))
    tasks += [asyncio.create_task(text_stalled(i, text_addr, stop_at, stats)) for i in range(2)]
    tasks.append(asyncio.create_task(viewer_churn(uri, stop_at, stats)))
    done, pending = await asyncio.wait(tasks, timeout=stop_at - time.monotonic() + 20)
    for t in pending:
        t.cancel()
    if pending:
        stats.infra_errors.append(f"{len(pending)} async clients did not finish in time")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=60.0, help="load duration (default 60)")
    ap.add_argument("--scene", default="assets/scenes/showroom.toml")
    ap.add_argument("--text-clients", type=int, default=200)
    ap.add_argument("--zmq-clients", type=int, default=20)
    ap.add_argument("--viewers", type=int, default=4)
    ap.add_argument("--text-rate", type=float, default=10.0, help="packets/s per text client")
    ap.add_argument("--zmq-rate", type=float, default=50.0, help="calls/s per ZMQ client")
    ap.add_argument("--min-rtf", type=float, default=0.9)
    ap.add_argument("--zmq-victim", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.zmq_victim:
        zmq_victim(args.zmq_victim)
        return 0

    scene = Path(args.scene)
    if not scene.is_absolute():
        scene = REPO / scene
    g = SoakGantry(scene)
    stats = Stats()
    failures: list[str] = []
    exit_code = None
    try:
        pid = g.pid
        time.sleep(1.0)  # let the first steps and the listeners settle
        baseline = (fd_count(pid), rss_bytes(pid))
        stop_sampling = threading.Event()
        threading.Thread(target=sampler, args=(pid, stop_sampling, stats), daemon=True).start()
        zhost, zport = g.addrs["zmq"]

        # ZMQ clients connect first (require() fetches the API description), then
        # everything runs for the same bounded time.
        barrier = threading.Barrier(args.zmq_clients + 1)
        deadline = Deadline(time.monotonic() + 3600)
        threads = []
        for i in range(args.zmq_clients):
            th = threading.Thread(target=zmq_worker, name=f"zmq-{i}",
                                  args=(i, zhost, zport, deadline, args.zmq_rate, stats.zmq, barrier),
                                  daemon=True)
            th.start()
            threads.append(th)
        try:
            barrier.wait(60)
        except threading.BrokenBarrierError:
            failures.append("ZMQ clients could not all set up")
        t_start = time.monotonic()
        stop_at = t_start + args.seconds
        deadline.stop_at = stop_at
        warm_at = t_start + min(10.0, max(3.0, args.seconds / 4))
        monitor = threading.Thread(target=zmq_monitor, args=(zhost, zport, stop_at, stats), daemon=True)
        monitor.start()
        killer = threading.Thread(target=zmq_killer, args=(zhost, zport, stop_at, stats), daemon=True)
        killer.start()

        asyncio.run(run_async_clients(g.addrs, args, stop_at, stats))

        for th in threads + [monitor, killer]:
            th.join(max(0.0, stop_at + 20 - time.monotonic()))
            if th.is_alive():
                failures.append(f"a ZMQ client thread ({th.name}) hung past the end")
        t_end = time.monotonic()
        # The last sample under full load, before the clients start leaving.
        loaded = [s for s in stats.proc_samples if s[0] <= stop_at - 0.25][-1]
        warm = sample_at(stats.proc_samples, warm_at)
        peak_fds = max(s[1] for s in stats.proc_samples)
        peak_rss = max(s[2] for s in stats.proc_samples)
        # Every client has left: the server must be back to its own descriptors.
        time.sleep(2.0)
        after = (fd_count(pid), rss_bytes(pid))
        stop_sampling.set()
        rtf = rtf_between(stats.sim_samples, warm_at, t_end)
        rtf_all = rtf_between(stats.sim_samples, t_start, t_end)

        # Clean stop under SIGTERM.
        g.proc.send_signal(signal.SIGTERM)
        try:
            exit_code = g.proc.wait(20)
        except subprocess.TimeoutExpired:
            exit_code = None
        time.sleep(0.2)
        summary_line = next((l for l in reversed(g.stdout_lines) if l.startswith("steps=")), "")

        # ---- verdicts
        for name, ch in (("text", stats.text), ("zmq", stats.zmq), ("viewer", stats.viewer)):
            if ch.errors:
                failures.append(f"{name}: {len(ch.errors)} errors, first: {ch.errors[:3]}")
        expected_text = args.text_clients * args.text_rate * args.seconds * 0.5
        if stats.text.requests < expected_text:
            failures.append(f"text: only {stats.text.requests} replies (expected at least {expected_text:.0f})")
        if args.zmq_clients and stats.zmq.requests < args.zmq_clients * 10:
            failures.append(f"zmq: only {stats.zmq.requests} calls")
        if args.viewers and stats.viewer.requests < args.viewers * args.seconds * 2:
            failures.append(f"viewer: only {stats.viewer.requests} pose frames")
        if stats.zmq_killed == 0 and args.seconds >= 8:
            failures.append("no ZMQ client was killed (the killer did not run)")
        if stats.infra_errors:
            failures.append(f"soak harness: {len(stats.infra_errors)} errors, first: {stats.infra_errors[:3]}")
        if not (rtf >= args.min_rtf):
            failures.append(f"real-time factor after warm-up {rtf:.3f} < {args.min_rtf}")
        churn_in_flight = 16
        if loaded[1] > warm[1] + churn_in_flight:
            failures.append(f"fds grew from {warm[1]} (after warm-up) to {loaded[1]} under the same load")
        if after[0] > baseline[0] + 8:
            failures.append(f"fds {after[0]} after every client left, {baseline[0]} before any came")
        rss_limit = warm[2] * 1.2 + 24 * MIB
        if loaded[2] > rss_limit:
            failures.append(f"RSS grew from {warm[2] / MIB:.1f} MiB (after warm-up) to {loaded[2] / MIB:.1f} MiB")
        if exit_code != 0:
            failures.append(f"gantry exit status {exit_code} after SIGTERM (expected 0)")

        # ---- report
        print()
        print(f"soak: {scene.relative_to(REPO) if scene.is_relative_to(REPO) else scene}, "
              f"{args.seconds:.0f} s of load, real time; gantry pid {pid}")
        print(f"{'channel':<10} {'clients':>8} {'requests':>10} {'req/s':>8} {'errors':>7} "
              f"{'p50 ms':>8} {'p99 ms':>8} {'max ms':>8}")
        for name, ch, n, unit in (("text", stats.text, args.text_clients, "burst of 4"),
                                  ("zmq", stats.zmq, args.zmq_clients, "call"),
                                  ("viewer", stats.viewer, args.viewers, "frame gap")):
            lat = ch.latencies
            print(f"{name:<10} {n:>8} {ch.requests:>10} {ch.requests / args.seconds:>8.0f} "
                  f"{len(ch.errors):>7} {ch.percentile(0.5) * 1e3:>8.2f} {ch.percentile(0.99) * 1e3:>8.2f} "
                  f"{(max(lat) if lat else float('nan')) * 1e3:>8.1f}   ({unit})")
        print(f"disturbances: {stats.churn_text} text clients vanished mid-request, "
              f"{stats.zmq_killed} ZMQ client processes SIGKILLed mid-call, "
              f"{stats.churn_viewer} viewer pages left early, 2 text clients sent "
              f"{stats.stalled_sent} packets without reading a reply")
        print(f"{'server':<10} {'before':>10} {'warm':>10} {'peak':>10} {'end':>10} {'after':>10}")
        print(f"{'fds':<10} {baseline[0]:>10} {warm[1]:>10} {peak_fds:>10} {loaded[1]:>10} {after[0]:>10}")
        print(f"{'RSS MiB':<10} {baseline[1] / MIB:>10.1f} {warm[2] / MIB:>10.1f} {peak_rss / MIB:>10.1f} "
              f"{loaded[2] / MIB:>10.1f} {after[1] / MIB:>10.1f}")
        print(f"real-time factor: {rtf:.3f} after warm-up, {rtf_all:.3f} overall (min {args.min_rtf}); "
              f"gantry's own line: {summary_line or '(none)'}")
        print(f"exit status after SIGTERM: {exit_code}")
        if failures:
            print("\nsoak FAILED:")
            for f in failures:
                print(f"  - {f}")
            print("\n--- gantry stderr (last lines) ---")
            print("\n".join(list(g.log)[-40:]))
            return 1
        print("soak passed")
        return 0
    finally:
        g.close()


if __name__ == "__main__":
    sys.exit(main())
