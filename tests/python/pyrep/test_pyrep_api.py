"""What gantry's `pyrep` adds to PyRep or does differently, beyond PyRep's own suite
(which `tests/pyrep/run_suite.py` runs): several simulations at once, one per thread;
`headless=False` opening the browser viewer; PyRep's exceptions for bad input."""

import threading
import urllib.request

import numpy as np
import pytest

from conftest import TEST_SCENE, model_path


def test_one_simulation_per_thread_each_with_its_own_objects():
    from pyrep import PyRep
    from pyrep.objects.shape import Shape

    results = {}
    errors = []

    def run(name, steps):
        try:
            pr = PyRep()
            pr.launch(TEST_SCENE, headless=True)
            pr.start()
            cube = Shape("dynamic_cube")
            start = cube.get_position()
            for _ in range(steps):
                pr.step()
            results[name] = (start, cube.get_position(), pr.get_simulation_timestep())
            pr.stop()
            pr.shutdown()
        except Exception as e:  # reported by the main thread
            errors.append(e)

    threads = [threading.Thread(target=run, args=(n, s)) for n, s in (("a", 2), ("b", 20))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    (a0, a1, _), (b0, b1, _) = results["a"], results["b"]
    np.testing.assert_allclose(a0, b0)
    # The two simulations advanced independently: the cube fell further in the one
    # stepped ten times as often.
    assert a1[2] > b1[2]


def test_objects_need_a_launched_simulation_in_their_thread():
    from pyrep.errors import PyRepError
    from pyrep.objects.shape import Shape

    def in_a_fresh_thread():
        try:
            Shape("dynamic_cube")
        except PyRepError as e:
            caught.append(str(e))

    caught = []
    t = threading.Thread(target=in_a_fresh_thread)
    t.start()
    t.join()
    assert caught and "launch" in caught[0]


def test_headless_false_opens_the_browser_viewer():
    from pyrep import PyRep

    pr = PyRep()
    pr.launch(TEST_SCENE, headless=False)
    try:
        assert pr.viewer_address and pr.viewer_address.startswith("http://127.0.0.1:")
        with urllib.request.urlopen(pr.viewer_address + "/api/status", timeout=10) as r:
            assert r.status == 200
        pr.start()
        pr.step()
    finally:
        pr.stop()
        pr.shutdown()


def _write_png(path, width, height):
    """A grey RGB PNG, written by hand (no imaging library in the test venv)."""
    import struct
    import zlib

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    rows = b"".join(b"\x00" + b"\x80" * (3 * width) for _ in range(height))
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows))
                     + chunk(b"IEND", b""))


def test_bad_input_gets_pyreps_exceptions(tmp_path):
    import shutil

    from pyrep import PyRep
    from pyrep.errors import PyRepError, WrongObjectTypeError
    from pyrep.objects.joint import Joint
    from pyrep.objects.shape import Shape

    with pytest.raises(PyRepError, match="does not exist"):
        PyRep().launch(str(tmp_path / "nowhere.ttt"), headless=True)
    # The scene's folder is where the simulation may read: a copy of the test scene
    # beside the broken mesh.
    scene = tmp_path / "test_scene.ttt"
    shutil.copy(TEST_SCENE, scene)
    pr = PyRep()
    pr.launch(str(scene), headless=True)
    try:
        pr.start()
        with pytest.raises(PyRepError, match="does not exist"):
            pr.import_model(str(tmp_path / "nowhere.ttm"))
        with pytest.raises(WrongObjectTypeError):
            Joint("dynamic_cube")
        broken = tmp_path / "broken.obj"
        broken.write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")
        with pytest.raises(PyRepError) as e:
            Shape.import_mesh(str(broken))
        assert "7" in str(e.value) or "face" in str(e.value).lower(), e.value
        with pytest.raises(PyRepError):
            pr.create_texture(str(broken))
        # A texture of absurd size: refused with the limit.
        wide = tmp_path / "wide.png"
        _write_png(wide, 5000, 2)
        with pytest.raises(PyRepError, match="4096"):
            pr.create_texture(str(wide))
        # A path of one control point is that point everywhere.
        from pyrep.objects.cartesian_path import CartesianPath

        path = CartesianPath.create()
        path.insert_control_points([[0.1, 0.2, 0.3, 0.0, 0.0, 0.0]])
        position, _ = path.get_pose_on_path(0.5)
        assert np.allclose(position, [0.1, 0.2, 0.3])
        # An arm whose IK group lost its tip: IK says so; a new `Panda()` cannot find it.
        from pyrep.objects.dummy import Dummy
        from pyrep.robots.arms.panda import Panda

        arm = Panda()
        Dummy("Panda_tip").remove()
        with pytest.raises(PyRepError, match="tip"):
            arm.solve_ik_via_jacobian([0.3, 0.0, 0.5], [0.0, 0.0, 0.0])
        with pytest.raises(PyRepError, match="Panda_tip"):
            Panda()
        # The simulation is still up.
        pr.step()
        assert Shape("dynamic_cube").still_exists()
    finally:
        pr.stop()
        pr.shutdown()


def test_the_panda_model_imports_with_its_collection():
    from pyrep import PyRep
    from pyrep.backend import sim

    pr = PyRep()
    pr.launch("", headless=True)
    try:
        base = pr.import_model(model_path("Panda"))
        assert base.get_name() == "Panda"
        assert isinstance(sim.simGetCollectionHandle("Panda_arm"), int)
    finally:
        pr.shutdown()
