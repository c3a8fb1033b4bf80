"""Fixtures of the `pyrep` robot tests: a launched PyRep on PyRep's test scene or on
an empty scene, torn down after each test."""

import os

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.abspath(os.path.join(HERE, "..", "..", ".."))

# The shared test material beside the repository (PyRep's assets, public models).
SHARED = os.environ.get("GANTRY_SHARED", os.path.join(REPO, "..", "shared"))
TEST_SCENE = os.path.join(SHARED, "pyrep", "tests", "assets", "test_scene.ttt")
MODELS = os.path.join(SHARED, "coppelia-files")


def model_path(name: str) -> str:
    """A robot model PyRep ships: `PyRep__<name>.ttm`."""
    return os.path.join(MODELS, "PyRep__%s.ttm" % name)


def _launch(scene):
    if scene and not os.path.isfile(scene):
        pytest.fail(f"missing test asset {scene} (set GANTRY_SHARED to the folder holding pyrep/ and coppelia-files/)")
    from pyrep import PyRep

    pr = PyRep()
    pr.launch(scene, headless=True)
    pr.step()
    pr.start()
    return pr


@pytest.fixture
def pr_scene():
    """PyRep's test_scene.ttt, started."""
    pr = _launch(TEST_SCENE)
    yield pr
    pr.stop()
    pr.shutdown()


@pytest.fixture
def pr_empty():
    """An empty scene, started."""
    pr = _launch("")
    yield pr
    pr.stop()
    pr.shutdown()
