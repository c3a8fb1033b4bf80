"""Start a real gantry process for the ZMQ remote API tests and benchmark.

`GantryProcess` runs ``gantry run SCENE --zmq-port 0 --text-port 0 ...``, reads the
port it chose from the ``listening zmq=127.0.0.1:PORT`` line on stderr, keeps draining
stderr (so the pipe never fills up and the log is available when a test fails), and
always terminates the process on ``close()``.
"""

from __future__ import annotations

import os
import re
import subprocess
import threading
import time
from collections import deque
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
LISTENING = re.compile(r"listening zmq=([0-9.]+|\[[0-9a-fA-F:]+\]):(\d+)")


def gantry_bin() -> Path:
    """The binary under test: $GANTRY_BIN, else target/release, else target/debug."""
    env = os.environ.get("GANTRY_BIN")
    if env:
        return Path(env)
    for profile in ("release", "debug"):
        p = REPO / "target" / profile / "gantry"
        if p.exists():
            return p
    raise FileNotFoundError(
        "no gantry binary: run `cargo build --release` or set GANTRY_BIN"
    )


class ManagedProcess:
    """A child process with its stderr lines in ``self.log``, stopped on exit.

    Subclasses set ``self.proc`` (a ``subprocess.Popen``) and ``self.log``.
    """

    proc: subprocess.Popen
    log: deque

    def stderr(self) -> str:
        return "\n".join(self.log)

    def close(self) -> None:
        """Terminates the process (SIGTERM, then SIGKILL after 5 s)."""
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(5)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class GantryProcess(ManagedProcess):
    """A running gantry serving the ZMQ remote API, its text channel and its viewer on
    free ports."""

    def __init__(self, scene: str | Path, *, fast: bool = True, extra: list[str] | None = None,
                 ready_timeout: float = 60.0):
        scene = Path(scene)
        if not scene.is_absolute():
            scene = REPO / scene
        cmd = [str(gantry_bin()), "run", str(scene), "--zmq-port", "0", "--text-port", "0"]
        if fast:
            cmd.append("--fast")
        extra = extra or []
        # The viewer on a free port too, unless the test chose one: never the default
        # 8080, which a developer's own gantry or a second process of the test may hold.
        if "--http-port" not in extra:
            cmd += ["--http-port", "0"]
        cmd += extra
        self.cmd = cmd
        self.log: deque[str] = deque(maxlen=2000)
        self.proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                     stderr=subprocess.PIPE, text=True, errors="replace")
        found = threading.Event()
        self.host = "127.0.0.1"
        self.port = 0

        def drain():
            assert self.proc.stderr is not None
            for line in self.proc.stderr:
                self.log.append(line.rstrip("\n"))
                m = LISTENING.search(line)
                if m and not found.is_set():
                    self.host = m.group(1).strip("[]")
                    self.port = int(m.group(2))
                    found.set()
            found.set()  # stderr closed: the process ended

        threading.Thread(target=drain, daemon=True).start()
        deadline = time.monotonic() + ready_timeout
        while not found.wait(0.05):
            if time.monotonic() > deadline:
                break
        if not self.port:
            self.close()
            raise RuntimeError(f"gantry did not report its ZMQ port: {' '.join(cmd)}\n" + self.stderr())

    def client(self):
        """A new RemoteAPIClient connected to this gantry."""
        from coppeliasim_zmqremoteapi_client import RemoteAPIClient

        return RemoteAPIClient(host=self.host, port=self.port)
