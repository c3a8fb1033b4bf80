"""Fixtures: a real gantry process driven by the real CoppeliaSim ZMQ remote API client.

``gantry(scene, fast=...)`` starts ``gantry run SCENE --zmq-port 0 --text-port 0``
(``--fast`` by default: stepping tests hold the simulation with ``setStepping`` anyway;
pass ``fast=False`` for a real-time paced run) and returns a handle whose ``client()``
makes a ``RemoteAPIClient(host='127.0.0.1', port=PORT)``. Every process is killed at
the end of its test, pass or fail; its stderr is printed when the test failed.

The binary is $GANTRY_BIN, else target/release/gantry, else target/debug/gantry.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

from gantry_proc import REPO, GantryProcess  # noqa: E402


@pytest.fixture
def gantry(request):
    started: list[GantryProcess] = []

    def start(scene: str | Path, *, fast: bool = True, extra: list[str] | None = None) -> GantryProcess:
        g = GantryProcess(scene, fast=fast, extra=extra)
        started.append(g)
        return g

    yield start
    failed = getattr(request.node, "rep_call", None) is not None and request.node.rep_call.failed
    for g in started:
        g.close()
        if failed:
            print(f"--- gantry stderr ({' '.join(g.cmd)}) ---\n{g.stderr()}", file=sys.stderr)


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item, call):
    rep = yield
    setattr(item, f"rep_{rep.when}", rep)
    return rep


@pytest.fixture
def client(gantry, request):
    """A client on the scene named by ``@pytest.mark.scene("assets/scenes/x.toml")``."""
    marker = request.node.get_closest_marker("scene")
    scene = marker.args[0] if marker else "assets/scenes/bubble_rob.toml"
    return gantry(scene).client()


def pytest_configure(config):
    config.addinivalue_line("markers", "scene(path): the scene the `client` fixture runs")


@pytest.fixture
def repo() -> Path:
    return REPO
