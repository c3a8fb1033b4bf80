"""What the in-process package (``gantry.Client``, built from python/) offers beyond the
remote-API tests it also runs (see conftest.py): numpy images, bundled scenes, the
context manager, several simulations in threads with the GIL released during steps,
a served simulation that a ZMQ client and the viewer can join, and clear errors."""

from __future__ import annotations

import json
import threading
import urllib.request

import numpy as np
import pytest
from coppeliasim_zmqremoteapi_client import RemoteAPIClient

import gantry
from gantry_proc import REPO

BUBBLE_ROB = REPO / "assets" / "scenes" / "bubble_rob.toml"


def test_images_are_numpy_arrays_over_the_same_pixels():
    with gantry.Client(BUBBLE_ROB) as client:
        sim = client.require("sim")
        client.setStepping(True)
        sensor = sim.getObject("/visionSensor")
        for _ in range(3):
            sim.step()
        img = client.image(sensor)
        raw, (w, h) = sim.getVisionSensorImg(sensor)
        assert img.shape == (h, w, 3) and img.dtype == np.uint8
        # Not a copy: a view over the buffer the simulator filled.
        assert not img.flags["OWNDATA"] and img.base is not None
        # C-contiguous, rows in place rather than a reversed view: torch.from_numpy
        # refuses negative strides, and np.ascontiguousarray would copy again.
        assert img.flags["C_CONTIGUOUS"] and img.strides[0] > 0
        # Row 0 is the top: the bytes (bottom row first, CoppeliaSim's order) flipped.
        bottom_first = np.frombuffer(raw, np.uint8).reshape(h, w, 3)
        assert np.array_equal(img, bottom_first[::-1])
        assert np.array_equal(client.image(sensor, top_first=False), bottom_first)
        assert client.image(sensor, options=1).shape == (h, w, 1)
        # The floor and obstacles are in view: not a blank image.
        assert img.std() > 1.0

        depth = client.depth(sensor, metres=True)
        assert depth.shape == (h, w) and depth.dtype == np.float32
        assert depth.flags["C_CONTIGUOUS"] and client.depth(sensor, top_first=False).flags["C_CONTIGUOUS"]
        raw_depth, _ = sim.getVisionSensorDepth(sensor, 1)
        assert np.array_equal(depth, np.frombuffer(raw_depth, "<f4").reshape(h, w)[::-1])
        near, far = 0.01, 1.0  # the scene's clipping planes
        assert near <= depth.min() and depth.max() <= far + 1e-6

        # The segmentation mask: handles of shapes, -1 where nothing is seen, from the
        # same render as the image (the first call renders again, with a mask).
        mask = client.mask(sensor)
        assert mask.shape == (h, w) and mask.dtype == np.int32 and mask.flags["C_CONTIGUOUS"]
        raw_mask, _ = sim.getVisionSensorMask(sensor)
        assert np.array_equal(mask, np.frombuffer(raw_mask, "<i4").reshape(h, w)[::-1])
        seen = {int(v) for v in np.unique(mask)} - {-1}
        assert seen and all(sim.getObjectType(s) == sim.object_shape_type for s in seen)
        # Nothing seen exactly where the depth reaches the far plane, and black there.
        img, depth = client.image(sensor), client.depth(sensor)
        assert np.array_equal(mask == -1, depth >= 1.0)
        assert (img[mask == -1] == 0).all()
        # PyRep's and RLBench's way: a colour-coded sensor shows handles as colours.
        sim.setObjectInt32Param(sensor, sim.visionintparam_render_mode, sim.rendermode_colorcoded)
        sim.handleVisionSensor(sensor)
        coded = client.image(sensor).astype(np.int64)
        decoded = coded[..., 0] + 256 * coded[..., 1] + 65536 * coded[..., 2]
        assert np.array_equal(np.where(decoded == 0xFFFFFF, -1, decoded), client.mask(sensor))


def test_bundled_scene_without_scripts_and_step_control():
    assert set(gantry.bundled_scenes()) >= {"showroom", "bubble_rob", "fk_arm"}
    # scripts=False: nothing drives the rover, so it stays where it is.
    with gantry.Client("bubble_rob", scripts=False, realtime=False) as client:
        sim = client.require("sim")
        rob = sim.getObject("/bubbleRob")
        x0 = sim.getObjectPosition(rob, sim.handle_world)[0]
        assert client.advance(40) == 40
        assert sim.getSimulationTime() == pytest.approx(2.0)
        assert sim.getObjectPosition(rob, sim.handle_world)[0] == pytest.approx(x0, abs=1e-3)
        # Without stepping and without real time, time passes only on demand.
        t = sim.getSimulationTime()
        assert sim.getSimulationTime() == t
        sim.step()
        assert sim.getSimulationTime() == pytest.approx(t + 0.05)
    # With its controller, the rover drives off.
    with gantry.Client("bubble_rob", realtime=False) as client:
        sim = client.require("sim")
        rob = sim.getObject("/bubbleRob")
        x0 = sim.getObjectPosition(rob, sim.handle_world)[0]
        client.advance(40)
        assert sim.getObjectPosition(rob, sim.handle_world)[0] > x0 + 0.2


def test_free_running_client_sees_time_pass_in_real_time():
    import time

    with gantry.Client(BUBBLE_ROB) as client:
        sim = client.require("sim")
        start = time.monotonic()
        t0 = sim.getSimulationTime()
        while sim.getSimulationTime() < t0 + 0.5:
            assert time.monotonic() - start < 30, "simulation time does not advance"
            time.sleep(0.01)
        # Not faster than the wall clock (the first step is due at once).
        assert time.monotonic() - start >= 0.5 - 0.05 - 0.02


def test_free_running_time_counts_from_the_start_and_step_takes_one_step():
    import time

    with gantry.Client(BUBBLE_ROB) as client:
        sim = client.require("sim")
        # The wall time between the start and the first call counts.
        time.sleep(0.5)
        assert sim.getSimulationTime() >= 0.4
        # Free running, sim.step() waits for the next due step: ten of them advance
        # about ten steps, not twenty.
        t0, w0 = sim.getSimulationTime(), time.monotonic()
        for _ in range(10):
            sim.step()
        dt_sim, dt_wall = sim.getSimulationTime() - t0, time.monotonic() - w0
        assert dt_wall >= 0.45 - 0.06, dt_wall
        assert dt_sim <= dt_wall + 0.1 + 1e-9, (dt_sim, dt_wall)


def test_calls_while_stopped_keep_the_stepping_level():
    """As test_public_robots does it: stop, setStepping, set the scene up with calls
    (script functions and locks included), start: the simulation waits for sim.step()."""
    import time

    with gantry.Client(BUBBLE_ROB) as client:
        sim = client.require("sim")
        sim.stopSimulation()
        assert client.setStepping(True) == 0
        rob = sim.getObject("/bubbleRob")
        assert sim.getScript(sim.scripttype_childscript, rob) == rob
        sim.acquireLock()
        sim.releaseLock()
        sim.startSimulation()
        time.sleep(0.3)
        assert sim.getSimulationTime() == 0.0, "held by the stepping level"
        for _ in range(4):
            sim.step()
        assert sim.getSimulationTime() == pytest.approx(0.2)
        assert client.setStepping(False) == 1


def _sim_threads() -> int:
    """gantry simulation threads of this process (Linux thread names)."""
    import glob

    names = []
    for comm in glob.glob("/proc/self/task/*/comm"):
        try:
            with open(comm) as f:
                names.append(f.read().strip())
        except OSError:
            pass
    return names.count("gantry-sim")


def test_an_unclosed_served_client_ends_its_simulation_when_collected():
    import gc

    import time

    def settles(want: int) -> bool:
        # A thread takes its name once it runs: poll briefly.
        deadline = time.monotonic() + 10
        while _sim_threads() != want and time.monotonic() < deadline:
            time.sleep(0.01)
        return _sim_threads() == want

    before = _sim_threads()
    client = gantry.Client(BUBBLE_ROB, zmq_port=0, realtime=False)
    assert settles(before + 1)
    del client
    gc.collect()
    assert settles(before), "the simulation thread outlived its client"


def test_closed_client_and_context_manager():
    client = gantry.Client(BUBBLE_ROB)
    sim = client.require("sim")
    with client:
        assert sim.getObject("/bubbleRob") >= 0
    with pytest.raises(RuntimeError, match="closed"):
        sim.getObject("/bubbleRob")


def test_simulations_in_threads_are_independent_and_release_the_gil():
    results: dict[int, list[float]] = {}
    errors: list[BaseException] = []
    ticks = []
    stepping = threading.Event()

    def run(speed_index: int):
        try:
            with gantry.Client("bubble_rob", realtime=False) as client:
                sim = client.require("sim")
                rob = sim.getObject("/bubbleRob")
                stepping.set()
                client.advance(600)
                results[speed_index] = sim.getObjectPosition(rob, sim.handle_world)
        except BaseException as e:  # reported to the main thread below
            errors.append(e)

    threads = [threading.Thread(target=run, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    stepping.wait(30)
    # While the simulations step, this thread keeps running Python: a step that held
    # the GIL would freeze it for the whole advance().
    while any(t.is_alive() for t in threads):
        ticks.append(1)
        threading.Event().wait(0.001)
    for t in threads:
        t.join()
    assert not errors, errors
    # Same scene, same inputs: identical results in both threads.
    assert results[0] == results[1]
    assert len(ticks) > 20, f"the main thread ran only {len(ticks)} times while the simulations stepped"


def test_a_client_belongs_to_its_thread():
    client = gantry.Client(BUBBLE_ROB)
    sim = client.require("sim")
    caught: list[BaseException] = []

    def other():
        # An ordinary exception, not the extension's panic (a BaseException).
        for call in (lambda: sim.getObject("/bubbleRob"), lambda: client.advance(1)):
            try:
                call()
            except Exception as e:
                caught.append(e)

    t = threading.Thread(target=other)
    t.start()
    t.join()
    assert len(caught) == 2, caught
    for e in caught:
        assert isinstance(e, RuntimeError) and "belongs to the thread that created it" in str(e), e
    assert sim.getObject("/bubbleRob") >= 0  # still fine in its own thread
    client.close()


def test_served_simulation_is_joined_by_zmq_and_the_viewer():
    with gantry.Client(BUBBLE_ROB, zmq_port=0, http_port=0) as client:
        assert not client.in_process
        addrs = client.addresses
        assert set(addrs) == {"zmq", "http"}
        sim = client.require("sim")
        client.setStepping(True)
        t0 = sim.getSimulationTime()
        for _ in range(5):
            sim.step()
        assert sim.getSimulationTime() == pytest.approx(t0 + 0.25)

        # A CoppeliaSim client joins the same simulation and sees the same world.
        host, port = addrs["zmq"].rsplit(":", 1)
        remote = RemoteAPIClient(host=host, port=int(port))
        rsim = remote.require("sim")
        rob = sim.getObject("/bubbleRob")
        assert rsim.getObjectPosition(rob, -1) == sim.getObjectPosition(rob, -1)
        assert rsim.getSimulationTime() == pytest.approx(t0 + 0.25)

        with urllib.request.urlopen(f"http://{addrs['http']}/api/status", timeout=10) as r:
            status = json.load(r)
        assert status["time"] == pytest.approx(t0 + 0.25), status
        client.setStepping(False)
    with pytest.raises(RuntimeError, match="closed"):
        sim.getSimulationTime()


@pytest.mark.parametrize(
    "kwargs, error, match",
    [
        ({"scene": "no-such-scene.toml"}, ValueError, "no-such-scene.toml"),
        ({"scene": "unknown_bundle"}, ValueError, "unknown_bundle"),
        ({"scene": "bubble_rob", "dt": 0.0}, ValueError, "time step"),
        ({"scene": "bubble_rob", "substeps": 0}, ValueError, "substeps"),
        ({"scene": "bubble_rob", "zmq_port": 0, "bind": "not-an-ip"}, ValueError, "IP address"),
        ({"scene": "bubble_rob", "http_port": 0, "token": "has space"}, ValueError, "token"),
    ],
)
def test_bad_construction_is_a_clear_error(kwargs, error, match):
    scene = kwargs.pop("scene")
    with pytest.raises(error, match=match):
        gantry.Client(scene, **kwargs)


def test_bad_arguments_are_clear_errors_and_harmless():
    with gantry.Client(BUBBLE_ROB) as client:
        sim = client.require("sim")
        with pytest.raises(Exception, match="illegal argument: cannot pass a object"):
            sim.getObject(object())
        cyclic: list = []
        cyclic.append(cyclic)
        with pytest.raises(Exception, match="nested deeper"):
            sim.packTable(cyclic)
        with pytest.raises(Exception, match="64-bit range"):
            sim.getObjectAlias(2**70)
        with pytest.raises(Exception, match=r"^No such function: simIK\.nothing$"):
            client.call("simIK.nothing", [])
        # numpy arguments are accepted as the remote client accepts them.
        rob = sim.getObject("/bubbleRob")
        sim.setObjectPosition(rob, np.array([0.5, 0.25, 0.12]), sim.handle_world)
        assert sim.getObjectPosition(rob, np.int64(-1)) == pytest.approx([0.5, 0.25, 0.12])
        # Stepping while holding the lock would wait for ever against a server: an error.
        client.setStepping(True)
        sim.acquireLock()
        with pytest.raises(Exception, match=r"holds sim.acquireLock.*\(in function 'sim.step'\)"):
            sim.step()
        sim.releaseLock()
        t = sim.getSimulationTime()
        sim.step()
        assert sim.getSimulationTime() == pytest.approx(t + 0.05)
        # The other modules are there with their constants.
        simIK = client.require("simIK")
        assert isinstance(simIK.constraint_pose, int)
        assert "getObjectPosition" in dir(sim)
