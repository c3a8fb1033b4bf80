"""Issue 31: `gantry verify run.mcap` re-simulates a recorded run with its recorded
inputs and reports "identical", for runs driven the ways researchers drive gantry:

- the showroom on its own (`gantry run --record ... --steps N`);
- bubble_rob driven by CoppeliaSim's own ZMQ client: stepping, reads, and pushes of the
  rover at chosen steps, then running free;
- the FK arm driven over the text channel with the paper's `<FK#...>` packets, while
  the simulation runs free (packets land at whatever step they arrive);
- the in-process Python client, `gantry.Client(scene, record=path)`.

Each recording's `/gantry/input` channel is read back with the `mcap` reader to check
that the inputs the client sent are the ones recorded. The test that one changed input
makes `verify` report the step where the runs part is in crates/record/tests/verify.rs.
"""

from __future__ import annotations

import re
import socket
import subprocess
import time

from mcap.reader import make_reader

from gantry_proc import GantryProcess, gantry_bin


def verify(path):
    return subprocess.run([str(gantry_bin()), "verify", str(path)], capture_output=True, text=True, timeout=600)


def assert_identical(path):
    r = verify(path)
    assert r.returncode == 0, f"exit {r.returncode}\n{r.stdout}\n{r.stderr}"
    assert "identical" in r.stdout, r.stdout


def inputs(path):
    """(kind, name) of every recorded input, in order."""
    out = []
    with open(path, "rb") as f:
        for _, channel, message in make_reader(f).iter_messages(topics=["/gantry/input"]):
            assert channel.message_encoding == "cdr"
            out.append(message.data)
    return [decode_input(d) for d in out]


def decode_input(data: bytes):
    """kind and name of a gantry_msgs/msg/Input (CDR: uint64 step, uint32 boundary,
    string kind, string name, ...), decoded here by hand: the reader is independent."""
    body = data[4:]
    at = 12  # step (8) + boundary (4)

    def string(at):
        at = (at + 3) // 4 * 4
        n = int.from_bytes(body[at:at + 4], "little")
        return body[at + 4:at + 4 + n - 1].decode(), at + 4 + n

    kind, at = string(at)
    name, _ = string(at)
    return kind, name


def test_the_showroom_re_runs_identically(tmp_path):
    path = tmp_path / "showroom.mcap"
    run = subprocess.run([str(gantry_bin()), "run", "--record", str(path), "--steps", "150", "--fast", "--no-listen"],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert_identical(path)
    assert ("control", "start") in inputs(path), "the run's autostart is its first input"


def test_bubble_rob_driven_by_the_zmq_client_re_runs_identically(tmp_path):
    path = tmp_path / "zmq.mcap"
    # Real time, not --fast: free running as fast as possible would outrun the writer
    # (a recording that dropped snapshots cannot be verified, by design).
    g = GantryProcess("assets/scenes/bubble_rob.toml", fast=False, extra=["--record", str(path), "--http-port", "0"])
    try:
        client = g.client()
        sim = client.require("sim")
        client.setStepping(True)
        rover = sim.getObject("/bubbleRob")
        for k in range(60):
            if k % 20 == 10:
                x, y, z = sim.getObjectPosition(rover, sim.handle_world)
                sim.setObjectPosition(rover, sim.handle_world, [x + 0.02, y, z])
            client.step()
        # Then free running for a while, with reads arriving at whatever step.
        client.setStepping(False)
        deadline = time.monotonic() + 0.3
        while time.monotonic() < deadline:
            sim.getObjectPosition(rover, sim.handle_world)
    finally:
        g.close()
    assert g.proc.returncode == 0, g.stderr()
    recorded = inputs(path)
    assert recorded.count(("call", "sim.setObjectPosition")) == 3, recorded[:20]
    assert_identical(path)


def test_text_channel_packets_re_run_identically(tmp_path):
    path = tmp_path / "text.mcap"
    g = GantryProcess("assets/scenes/fk_arm.toml", fast=False, extra=["--record", str(path), "--http-port", "0"])
    try:
        addr = None
        deadline = time.monotonic() + 30
        while addr is None and time.monotonic() < deadline:
            for line in list(g.log):
                m = re.search(r"listening text=([0-9.]+):(\d+)", line)
                if m:
                    addr = (m.group(1), int(m.group(2)))
            time.sleep(0.02)
        assert addr, g.stderr()
        with socket.create_connection(addr, timeout=10) as s:
            f = s.makefile("rwb")
            for j in range(8):
                packet = f"<FK#J1={0.1 * j:.2f},J2=0.2,J3=-0.3,J4=0,J5={0.05 * j:.2f},J6=0>"
                f.write(packet.encode() + b"\n")
                f.flush()
                reply = f.readline()
                assert reply.startswith(b"<FK#"), reply
                time.sleep(0.02)
    finally:
        g.close()
    assert g.proc.returncode == 0, g.stderr()
    assert inputs(path).count(("packet", "")) == 8
    assert_identical(path)


def test_the_in_process_client_records_a_run_that_re_runs_identically(tmp_path):
    import gantry  # built and installed by .ci/python-tests.sh

    path = tmp_path / "inproc.mcap"
    client = gantry.Client("bubble_rob", realtime=False, record=path)
    sim = client.require("sim")
    rover = sim.getObject("/bubbleRob")
    client.advance(20)
    x, y, z = sim.getObjectPosition(rover, sim.handle_world)
    sim.setObjectPosition(rover, sim.handle_world, [x, y + 0.03, z])
    client.advance(30)
    client.close()
    assert ("call", "sim.setObjectPosition") in inputs(path)
    assert_identical(path)


def test_verify_refuses_what_is_not_a_gantry_recording(tmp_path):
    foreign = tmp_path / "foreign.mcap"
    foreign.write_bytes(b'{"this is": "json"}')
    r = verify(foreign)
    assert r.returncode == 1 and "not a readable MCAP file" in r.stderr, r.stderr
    missing = verify(tmp_path / "missing.mcap")
    assert missing.returncode == 1 and "cannot read" in missing.stderr, missing.stderr
