"""How fast `gantry replay` scrubs (issue 31: to any time of a 10-minute recording in
under 100 ms).

Records the bundled showroom for `--steps` steps (12000 at its 50 ms step: 10 simulated
minutes) with `gantry run --record FILE --fast --no-listen`, starts `gantry replay FILE
--http-port 0`, connects to the viewer's WebSocket as a page does and seeks to
`--seeks` random times (a fixed seed), one after another. Per seek it measures:

- server: what the simulation thread spent setting every pose and building the frame
  (the replay's `apply_ms`, reported in the seek's reply);
- reply: from sending the seek to its reply (the player, the simulation thread and
  the WebSocket; the new frame is published before the reply goes out);
- frame: from sending the seek to the arrival of the frame's tick with the new time
  (what a page waits for before it draws).

It also gives the time `gantry replay` takes to open the file (read, decompress,
index) and serve the page. Prints a JSON summary (median and max of each, ms).

    GANTRY_BIN=target/release/gantry .venv/bin/python tools/bench/replay.py [--steps 12000] [--seeks 200]
"""

from __future__ import annotations

import argparse
import base64
import json
import os
import random
import re
import socket
import statistics
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "python"))
from gantry_proc import gantry_bin  # noqa: E402

LISTENING = re.compile(r"listening http=([0-9.]+):(\d+)")
# Target of issue 31.
TARGET_MS = 100.0


class WebSocket:
    """The smallest RFC 6455 client for this benchmark: text out (masked), every frame in."""

    def __init__(self, host: str, port: int):
        self.sock = socket.create_connection((host, port), timeout=30)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        key = base64.b64encode(os.urandom(16)).decode()
        self.sock.sendall((f"GET /ws HTTP/1.1\r\nHost: {host}:{port}\r\nUpgrade: websocket\r\n"
                           f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n"
                           f"Sec-WebSocket-Version: 13\r\nOrigin: http://{host}:{port}\r\n\r\n").encode())
        head = b""
        while b"\r\n\r\n" not in head:
            chunk = self.sock.recv(4096)
            if not chunk:
                raise RuntimeError("the viewer closed the connection during the handshake")
            head += chunk
        status = head.split(b"\r\n", 1)[0]
        if b" 101 " not in status:
            raise RuntimeError(f"WebSocket refused: {status!r}")
        self.buf = head.split(b"\r\n\r\n", 1)[1]

    def _read(self, n: int) -> bytes:
        while len(self.buf) < n:
            chunk = self.sock.recv(1 << 16)
            if not chunk:
                raise RuntimeError("the viewer closed the connection")
            self.buf += chunk
        out, self.buf = self.buf[:n], self.buf[n:]
        return out

    def recv(self) -> tuple[int, bytes]:
        """The next message: (opcode, payload); 1 is text, 2 binary."""
        b0, b1 = self._read(2)
        n = b1 & 0x7F
        if n == 126:
            n = struct.unpack(">H", self._read(2))[0]
        elif n == 127:
            n = struct.unpack(">Q", self._read(8))[0]
        return b0 & 0x0F, self._read(n)

    def send_text(self, text: str) -> None:
        data = text.encode()
        mask = os.urandom(4)
        n = len(data)
        head = bytes([0x81]) + (bytes([0x80 | n]) if n < 126 else bytes([0x80 | 126]) + struct.pack(">H", n))
        self.sock.sendall(head + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(data)))


def summary(values: list[float]) -> dict:
    return {"median_ms": round(statistics.median(values), 3), "max_ms": round(max(values), 3)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=12000, help="steps recorded (12000: 10 minutes)")
    ap.add_argument("--seeks", type=int, default=200)
    ap.add_argument("--json", type=Path, help="also write the summary here")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        rec = Path(tmp) / "showroom.mcap"
        subprocess.run([str(gantry_bin()), "run", "--record", str(rec), "--steps", str(args.steps), "--fast",
                        "--no-listen"], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        started = time.perf_counter()
        proc = subprocess.Popen([str(gantry_bin()), "replay", str(rec), "--http-port", "0"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        try:
            assert proc.stderr is not None
            for line in proc.stderr:
                m = LISTENING.search(line)
                if m:
                    break
            else:
                raise RuntimeError("gantry replay did not report its viewer")
            open_s = time.perf_counter() - started
            ws = WebSocket(m.group(1), int(m.group(2)))
            start = end = None
            while end is None:
                op, data = ws.recv()
                if op == 1:
                    msg = json.loads(data)
                    if msg.get("t") == "replay":
                        start, end = msg["start"], msg["end"]
            rng = random.Random(31)
            server, reply, frame = [], [], []
            for i in range(args.seeks):
                t = round(rng.uniform(start, end), 3)
                sent = time.perf_counter()
                ws.send_text(json.dumps({"id": i + 1, "op": "replay", "action": "seek", "time": t}))
                got_reply = got_frame = None
                while got_reply is None or got_frame is None:
                    op, data = ws.recv()
                    if op != 1:
                        continue
                    msg = json.loads(data)
                    if msg.get("t") == "reply" and msg.get("id") == i + 1:
                        if not msg["ok"]:
                            raise RuntimeError(msg["text"])
                        got_reply = time.perf_counter()
                        server.append(json.loads(msg["text"])["apply_ms"])
                    elif msg.get("t") == "tick" and abs(msg.get("time", -1) - t) < 1e-6:
                        got_frame = time.perf_counter()
                reply.append((got_reply - sent) * 1e3)
                frame.append((got_frame - sent) * 1e3)
        finally:
            proc.terminate()
            proc.wait(10)
        out = {
            "steps": args.steps,
            "recorded_s": round(end - start, 3),
            "file_bytes": rec.stat().st_size,
            "open_and_serve_s": round(open_s, 3),
            "seeks": args.seeks,
            "server": summary(server),
            "reply": summary(reply),
            "frame": summary(frame),
            "target_ms": TARGET_MS,
        }
    print(json.dumps(out, indent=2))
    if args.json:
        args.json.write_text(json.dumps(out, indent=2))
    if out["frame"]["max_ms"] > TARGET_MS:
        print(f"scrubbing is over the {TARGET_MS} ms target", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
