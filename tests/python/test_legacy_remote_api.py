"""CoppeliaSim's legacy remote API (the ``simx*`` functions) against a real gantry,
driven by the real client: V-REP 3.3.2's ``remoteApi.so`` and ``vrep.py`` as pypot ships
them (installed with --no-deps by .ci/python-tests.sh, loaded here by path so that none of
pypot's own code runs). Nothing on the client side is gantry's.

Covers: connecting to ``gantry run --legacy-port 0``; object handles; blocking, streaming
and buffer reads; joint commands moving BubbleRob; signals (strings as bytes);
synchronous mode stepping exactly once per trigger; errors reported with the remote
error flag; and a scene script that starts its own server with ``simRemoteApi.start`` and
answers ``simxCallScriptFunction``, the server ending with the simulation.
"""

from __future__ import annotations

import importlib.util
import re
import socket
import sys
import sysconfig
import textwrap
import time
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

from gantry_proc import GantryProcess  # noqa: E402

LEGACY = re.compile(r"listening legacy=([0-9.]+):(\d+)")
BINDINGS = Path(sysconfig.get_paths()["purelib"]) / "pypot" / "vrep" / "remoteApiBindings"


@pytest.fixture(scope="module")
def vrep():
    """vrep.py with its remoteApi.so (see ``load_bindings``)."""
    module = load_bindings()
    yield module
    module.simxFinish(-1)


def load_bindings():
    """vrep.py with its remoteApi.so, imported as a package of its own."""
    init = BINDINGS / "__init__.py"
    assert init.exists(), f"pypot's legacy client is not installed at {BINDINGS} (run .ci/python-tests.sh)"
    spec = importlib.util.spec_from_file_location("legacy_bindings", init, submodule_search_locations=[str(BINDINGS)])
    pkg = importlib.util.module_from_spec(spec)
    sys.modules["legacy_bindings"] = pkg
    spec.loader.exec_module(pkg)
    return importlib.import_module("legacy_bindings.vrep")


def legacy_port(proc: GantryProcess) -> int:
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        for line in list(proc.log):
            m = LEGACY.search(line)
            if m:
                return int(m.group(2))
        time.sleep(0.05)
    raise AssertionError("gantry did not report its legacy port\n" + proc.stderr())


def connect(vrep, port: int, timeout_ms: int = 5000) -> int:
    client = vrep.simxStart("127.0.0.1", port, True, True, timeout_ms, 5)
    assert client >= 0, f"simxStart to port {port} failed"
    return client


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_bubble_rob_is_driven_and_read_by_the_legacy_client(vrep):
    with GantryProcess("assets/scenes/bubble_rob.toml", fast=False, extra=["--legacy-port", "0"]) as g:
        cid = connect(vrep, legacy_port(g))
        try:
            blocking = vrep.simx_opmode_blocking
            rc, rob = vrep.simxGetObjectHandle(cid, "bubbleRob", blocking)
            assert rc == vrep.simx_return_ok and rob >= 0
            rc, left = vrep.simxGetObjectHandle(cid, "leftMotor", blocking)
            assert rc == vrep.simx_return_ok and left >= 0 and left != rob
            # A name that does not exist: the remote error flag, not a crash or a hang.
            rc, _ = vrep.simxGetObjectHandle(cid, "noSuchObject", blocking)
            assert rc & vrep.simx_return_remote_error_flag
            rc, errors = vrep.simxGetLastErrors(cid, blocking)
            assert rc == vrep.simx_return_ok and any("noSuchObject" in e for e in errors), errors

            # Streaming: the first buffer read may have nothing yet; later ones do.
            rc, start = vrep.simxGetObjectPosition(cid, rob, -1, vrep.simx_opmode_streaming)
            assert rc in (vrep.simx_return_ok, vrep.simx_return_novalue_flag)
            time.sleep(0.3)
            rc, start = vrep.simxGetObjectPosition(cid, rob, -1, vrep.simx_opmode_buffer)
            assert rc == vrep.simx_return_ok and len(start) == 3
            rc, blocking_pos = vrep.simxGetObjectPosition(cid, rob, -1, blocking)
            assert rc == vrep.simx_return_ok
            assert blocking_pos[2] == pytest.approx(start[2], abs=0.02)

            # The scene's script drives the wheels; the streamed position follows the rover.
            time.sleep(1.5)
            rc, later = vrep.simxGetObjectPosition(cid, rob, -1, vrep.simx_opmode_buffer)
            assert rc == vrep.simx_return_ok
            moved = ((later[0] - start[0]) ** 2 + (later[1] - start[1]) ** 2) ** 0.5
            assert moved > 0.05, f"BubbleRob did not move: {start} -> {later}"
            assert vrep.simxGetLastCmdTime(cid) > 0  # simulation time of the last reply, ms

            rc = vrep.simxSetJointTargetVelocity(cid, left, 1.25, blocking)
            assert rc == vrep.simx_return_ok

            # Signals: a script-side value and a binary string round-trip.
            assert vrep.simxSetIntegerSignal(cid, "legacyInt", 42, blocking) == vrep.simx_return_ok
            rc, value = vrep.simxGetIntegerSignal(cid, "legacyInt", blocking)
            assert (rc, value) == (vrep.simx_return_ok, 42)
            payload = bytes([0, 1, 2, 255, 0, 7])
            assert vrep.simxSetStringSignal(cid, "legacyBytes", payload, blocking) == vrep.simx_return_ok
            rc, got = vrep.simxGetStringSignal(cid, "legacyBytes", blocking)
            assert rc == vrep.simx_return_ok and bytes(got) == payload
            rc, _ = vrep.simxGetFloatSignal(cid, "neverSet", blocking)
            assert rc & vrep.simx_return_remote_error_flag

            rc, ping = vrep.simxGetPingTime(cid)
            assert rc == vrep.simx_return_ok and ping < 1000
            rc, objects = vrep.simxGetObjects(cid, vrep.sim_handle_all, blocking)
            assert rc == vrep.simx_return_ok and rob in objects and left in objects
        finally:
            vrep.simxFinish(cid)


def test_synchronous_mode_steps_once_per_trigger(vrep):
    with GantryProcess("assets/scenes/bubble_rob.toml", fast=False, extra=["--legacy-port", "0"]) as g:
        cid = connect(vrep, legacy_port(g))
        try:
            blocking = vrep.simx_opmode_blocking
            assert vrep.simxStopSimulation(cid, blocking) == vrep.simx_return_ok
            assert vrep.simxSynchronous(cid, True) == vrep.simx_return_ok
            assert vrep.simxStartSimulation(cid, blocking) == vrep.simx_return_ok
            rc, rob = vrep.simxGetObjectHandle(cid, "bubbleRob", blocking)
            assert rc == vrep.simx_return_ok
            vrep.simxGetObjectPosition(cid, rob, -1, blocking)
            t0 = vrep.simxGetLastCmdTime(cid)
            # Held: half a second of wall time and no step is taken.
            time.sleep(0.5)
            vrep.simxGetObjectPosition(cid, rob, -1, blocking)
            assert vrep.simxGetLastCmdTime(cid) == t0
            for k in range(1, 11):
                assert vrep.simxSynchronousTrigger(cid) == vrep.simx_return_ok
                vrep.simxGetObjectPosition(cid, rob, -1, blocking)
                assert vrep.simxGetLastCmdTime(cid) == t0 + 50 * k  # dt = 50 ms
            assert vrep.simxSynchronous(cid, False) == vrep.simx_return_ok
            assert vrep.simxStopSimulation(cid, blocking) == vrep.simx_return_ok
        finally:
            vrep.simxFinish(cid)


SCRIPTED_SERVER = """
[simulation]
dt = 0.05

[[object]]
name = "remoteApiCommandServer"
alias = "remoteApiCommandServer"
kind = "dummy"
script = "server.lua"
"""

SERVER_LUA = """
function sysCall_init()
    sim = require('sim')
    started = simRemoteApi.start({port})
    sim.setInt32Signal('started', started)
end

function createDummy_function(inInts, inFloats, inStrings, inBuffer)
    local h = sim.createDummy(0.05)
    sim.setObjectAlias(h, inStrings[1])
    sim.setObjectPosition(h, -1, inFloats)
    return {{h, #inBuffer}}, {{inFloats[1] * 2}}, {{'made ' .. inStrings[1]}}, inBuffer .. '!'
end
"""


def test_a_script_starts_a_server_that_ends_with_the_simulation(vrep, tmp_path):
    port = free_port()
    (tmp_path / "scene.toml").write_text(textwrap.dedent(SCRIPTED_SERVER))
    (tmp_path / "server.lua").write_text(SERVER_LUA.format(port=port))
    with GantryProcess(tmp_path / "scene.toml", fast=False) as g:
        # The client gives up at once if the port refuses it (doNotReconnect): wait for
        # the script's sysCall_init to have started the server.
        deadline = time.monotonic() + 30
        while f"legacy remote API listening on 127.0.0.1:{port}" not in g.stderr():
            assert time.monotonic() < deadline, g.stderr()
            time.sleep(0.05)
        cid = connect(vrep, port)
        try:
            blocking = vrep.simx_opmode_blocking
            rc, started = vrep.simxGetIntegerSignal(cid, "started", blocking)
            assert (rc, started) == (vrep.simx_return_ok, 1)
            rc, ints, floats, strings, buf = vrep.simxCallScriptFunction(
                cid, "remoteApiCommandServer", vrep.sim_scripttype_childscript, "createDummy_function",
                [], [0.5, 0.25, 0.125], ["marker"], bytearray(b"abc"), blocking)
            assert rc == vrep.simx_return_ok, g.stderr()
            handle, buffer_len = ints
            assert buffer_len == 3
            assert floats == [pytest.approx(1.0)]
            assert strings == ["made marker"]
            assert bytes(buf) == b"abc!"
            rc, found = vrep.simxGetObjectHandle(cid, "marker", blocking)
            assert (rc, found) == (vrep.simx_return_ok, handle)
            rc, pos = vrep.simxGetObjectPosition(cid, handle, -1, blocking)
            assert rc == vrep.simx_return_ok and pos == pytest.approx([0.5, 0.25, 0.125], abs=1e-6)
            # A function the script lacks: the remote error flag and the reason.
            rc, *_ = vrep.simxCallScriptFunction(
                cid, "remoteApiCommandServer", vrep.sim_scripttype_childscript, "missing",
                [], [], [], bytearray(), blocking)
            assert rc & vrep.simx_return_remote_error_flag
            # Stopping the simulation ends the script's server, as in CoppeliaSim.
            vrep.simxStopSimulation(cid, vrep.simx_opmode_oneshot)
            deadline = time.monotonic() + 10
            while vrep.simxGetConnectionId(cid) != -1 and time.monotonic() < deadline:
                time.sleep(0.05)
            assert vrep.simxGetConnectionId(cid) == -1, "the script's server outlived the simulation"
        finally:
            vrep.simxFinish(cid)
        with socket.socket() as s:
            assert s.connect_ex(("127.0.0.1", port)) != 0, "the port still accepts connections"
        assert "legacy remote API on port" in g.stderr()
