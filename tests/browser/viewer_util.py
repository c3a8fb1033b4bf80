"""Helpers shared by the viewer's browser test and benchmark.

* ``Gantry``: a real ``gantry`` process on the embedded showroom (no SCENE argument)
  with every listener on a free port (``--http-port 0 --text-port 0 --zmq-port 0``);
  the chosen addresses come from its ``listening KIND=ADDR`` lines on stderr.
* ``launch_chromium``: Debian's ``/usr/bin/chromium`` driven headless by Playwright,
  never a downloaded browser. ``--disable-gpu`` makes WebGL2 run on SwiftShader.
* ``text_packet``: one packet over the text channel, as the paper's client sends it.
* ``Replay``: ``gantry replay FILE`` with its viewer on a free port.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import socket
import subprocess
import sys
import threading
import time
import urllib.request
from collections import deque
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "python"))
from gantry_proc import ManagedProcess, gantry_bin  # noqa: E402  (one definition of "the binary under test")

LISTENING = re.compile(r"listening (text|zmq|http|dap)=([0-9.]+|\[[0-9a-fA-F:]+\]):(\d+)")
CHROMIUM = os.environ.get("CHROMIUM", "/usr/bin/chromium")
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


class Listening(ManagedProcess):
    """A gantry process that announces its listeners on stderr (``listening KIND=ADDR``):
    ``addr[kind]`` is ``(host, port)``, ``url`` its viewer page."""

    def _start(self, cmd: list[str], listeners: int, ready_timeout: float) -> None:
        """Starts ``cmd`` and waits until it announced ``listeners`` listeners."""
        self.cmd = cmd
        self.log: deque[str] = deque(maxlen=2000)
        self.addr: dict[str, tuple[str, int]] = {}
        self.proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                     stderr=subprocess.PIPE, text=True, errors="replace")
        ready = threading.Event()

        def drain():
            assert self.proc.stderr is not None
            for line in self.proc.stderr:
                self.log.append(line.rstrip("\n"))
                m = LISTENING.search(line)
                if m:
                    self.addr[m.group(1)] = (m.group(2).strip("[]"), int(m.group(3)))
                    if len(self.addr) == listeners:
                        ready.set()
            ready.set()  # stderr closed: the process ended

        threading.Thread(target=drain, daemon=True).start()
        ready.wait(ready_timeout)
        if len(self.addr) != listeners:
            self.close()
            raise RuntimeError(f"gantry did not report its listeners: {' '.join(cmd)}\n{self.stderr()}")

    @property
    def url(self) -> str:
        host, port = self.addr["http"]
        return f"http://{host}:{port}/"

    def status(self) -> dict:
        """``GET /api/status``: time, steps, state and viewers of a run; the replay
        clock (time, start, end, playing, speed, frame) of a replay."""
        with urllib.request.urlopen(self.url + "api/status", timeout=10) as r:
            return json.load(r)


class Gantry(Listening):
    """A running gantry serving the showroom; ``addr[kind]`` is ``(host, port)``."""

    def __init__(self, *, fast: bool = False, extra: list[str] | None = None, prefix: list[str] | None = None,
                 ready_timeout: float = 60.0):
        # `prefix` wraps the command, e.g. ["taskset", "-c", "0"] in the benchmark.
        cmd = [*(prefix or []), str(gantry_bin()), "run", "--http-port", "0", "--text-port", "0", "--zmq-port", "0"]
        if fast:
            cmd.append("--fast")
        cmd += extra or []
        # With --debug, the debugger's DAP listener is a fourth.
        self._start(cmd, 3 + any(a.startswith("--debug") for a in cmd), ready_timeout)

    def zmq_client(self):
        from coppeliasim_zmqremoteapi_client import RemoteAPIClient

        host, port = self.addr["zmq"]
        return RemoteAPIClient(host=host, port=port)



def launch_chromium(playwright):
    """Headless Debian chromium; Playwright gives each launch a fresh profile."""
    if not Path(CHROMIUM).exists():
        raise FileNotFoundError(f"{CHROMIUM} is missing: run tools/browser-test.sh (it installs chromium)")
    return playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)


@contextlib.contextmanager
def viewer_page(url: str, ready: str, timeout_ms: int = 30_000):
    """A headless Chromium page on ``url``, once the JavaScript condition ``ready``
    holds; on leaving, no JavaScript error may have happened on the page."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        browser = launch_chromium(p)
        pg = browser.new_page(viewport={"width": 1400, "height": 900})
        errors: list[str] = []
        pg.on("pageerror", lambda e: errors.append(str(e)))
        pg.goto(url)
        pg.wait_for_function(ready, timeout=timeout_ms)
        pg.errors = errors
        yield pg
        assert not errors, f"JavaScript errors on the page: {errors}"
        browser.close()


def text_packet(addr: tuple[str, int], packet: str, timeout: float = 5.0) -> str:
    """Sends one packet over the text channel and returns the reply line."""
    with socket.create_connection(addr, timeout=timeout) as s:
        s.sendall(packet.encode() + b"\n")
        buf = b""
        while not buf.endswith(b"\n"):
            chunk = s.recv(4096)
            if not chunk:
                break
            buf += chunk
    return buf.decode().strip()


def joints(addr: tuple[str, int]) -> list[float]:
    """The arm's joint angles (rad) from ``<JOINTS#>``."""
    reply = text_packet(addr, "<JOINTS#>")
    m = re.fullmatch(r"<JOINTS#(.*)>", reply)
    assert m, reply
    return [float(kv.split("=")[1]) for kv in m.group(1).split(",")]


def wait_for(predicate, timeout: float = 10.0, interval: float = 0.05, what: str = "condition"):
    """Polls ``predicate`` until it returns a truthy value, which is returned."""
    deadline = time.monotonic() + timeout
    last = None
    while time.monotonic() < deadline:
        last = predicate()
        if last:
            return last
        time.sleep(interval)
    raise AssertionError(f"timed out after {timeout} s waiting for {what} (last: {last!r})")


class Replay(Listening):
    """``gantry replay FILE --http-port 0``: the viewer over a recording; ``url`` is its page."""

    def __init__(self, recording: Path, ready_timeout: float = 60.0):
        self._start([str(gantry_bin()), "replay", str(recording), "--http-port", "0"], 1, ready_timeout)
