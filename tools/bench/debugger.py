"""What the script debugger costs (issue 17): BubbleRob's headless step rate without
--debug, with --debug and no client, with a DAP client attached and no breakpoint, and
with a breakpoint armed on a line that never runs (the speed slider's callback, which
only a viewer calls), so that every line goes through the hook's breakpoint test.

Each configuration runs `gantry run bubble_rob.toml --fast --steps N --no-listen`
(plus --debug=0), interleaved, `--repeat` times; the figure is the median of the
steps/s the binary reports. The client attaches within milliseconds of the start, a
negligible share of a run of several seconds.

    .venv/bin/python tools/bench/debugger.py [--steps 20000] [--repeat 3] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import re
import socket
import statistics
import subprocess
import sys
import threading
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "python"))
from gantry_proc import gantry_bin  # noqa: E402

SCENE = REPO / "assets" / "scenes" / "bubble_rob.toml"
SCRIPT = REPO / "scripts" / "bubble_rob.lua"
RATE = re.compile(r"steps_per_s=([0-9.]+)")
DAP = re.compile(r"listening dap=([0-9.]+):(\d+)")


def request(sock: socket.socket, seq: int, command: str, arguments: dict) -> None:
    body = json.dumps({"seq": seq, "type": "request", "command": command, "arguments": arguments})
    sock.sendall(f"Content-Length: {len(body)}\r\n\r\n{body}".encode())


def run(steps: int, mode: str) -> float:
    cmd = [str(gantry_bin()), "run", str(SCENE), "--fast", "--steps", str(steps), "--no-listen"]
    if mode != "plain":
        cmd.append("--debug=0")
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    client = None
    if mode in ("client", "armed"):
        assert proc.stderr is not None
        for line in proc.stderr:
            m = DAP.search(line)
            if m:
                client = socket.create_connection((m.group(1), int(m.group(2))))
                request(client, 1, "initialize", {"adapterID": "gantry"})
                request(client, 2, "attach", {})
                if mode == "armed":
                    never = next(n for n, l in enumerate(SCRIPT.read_text().splitlines(), 1)
                                 if l.strip().startswith("speed=minMaxSpeed[1]+"))
                    request(client, 3, "setBreakpoints",
                            {"source": {"path": str(SCRIPT)}, "breakpoints": [{"line": never}]})
                request(client, 4, "configurationDone", {})
                # Keep reading so the adapter never blocks on a full socket.
                threading.Thread(target=lambda c=client: [None for _ in iter(lambda: c.recv(65536), b"")],
                                 daemon=True).start()
                break
    out, err = proc.communicate(timeout=600)
    if client is not None:
        client.close()
    m = RATE.search(out)
    if proc.returncode != 0 or not m:
        raise RuntimeError(f"{' '.join(cmd)} failed ({proc.returncode}):\n{out}\n{err}")
    return float(m.group(1))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    modes = {
        "plain": "without --debug",
        "debug": "--debug, no client",
        "client": "--debug, client attached, no breakpoint",
        "armed": "--debug, client, a breakpoint never reached",
    }
    rates: dict[str, list[float]] = {m: [] for m in modes}
    for _ in range(args.repeat):
        for m in modes:
            rates[m].append(run(args.steps, m))
    base = statistics.median(rates["plain"])
    result = {}
    print(f"BubbleRob, {args.steps} steps --fast, median of {args.repeat}")
    print(f"{'configuration':48} {'steps/s':>9} {'vs plain':>9}")
    for m, label in modes.items():
        med = statistics.median(rates[m])
        result[m] = {"label": label, "steps_per_s": med, "runs": rates[m], "ratio": med / base}
        print(f"{label:48} {med:9.0f} {100 * med / base:8.1f}%")
    if args.json:
        args.json.write_text(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
