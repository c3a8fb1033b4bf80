"""(1) CoppeliaSim's own simpleTest.py, adapted: connect, require sim, stepping, read
the time, step, get objects, stop."""

import pytest


def test_simple(gantry):
    # Real-time paced, as a desktop CoppeliaSim would run: stepping must still step on demand.
    g = gantry("assets/scenes/bubble_rob.toml", fast=False)
    client = g.client()
    sim = client.require("sim")
    assert sim.handle_world == -1  # constants come from zmqRemoteApi.info

    assert client.setStepping(True) == 0  # returns the previous stepping level
    sim.startSimulation()
    # 16 until the first step is done, 17 after (CoppeliaSim's advancing passes); a
    # gantry process has stepped before the client connects, an in-process one not yet.
    assert sim.getSimulationState() in (sim.simulation_advancing_firstafterstop, sim.simulation_advancing_running)
    dt = sim.getSimulationTimeStep()
    assert dt == pytest.approx(0.05)

    t = sim.getSimulationTime()
    for _ in range(10):
        client.step()  # sends sim.step [True], parks on _*wait*_
        t_next = sim.getSimulationTime()
        assert t_next == pytest.approx(t + dt, abs=1e-9)
        t = t_next
    sim.step()  # the newer spelling: sim.step() with no argument
    assert sim.getSimulationTime() == pytest.approx(t + dt, abs=1e-9)

    rob = sim.getObject("/bubbleRob")
    assert isinstance(rob, int)
    pos = sim.getObjectPosition(rob, sim.handle_world)
    assert isinstance(pos, list) and len(pos) == 3 and all(isinstance(x, float) for x in pos)
    assert sim.getObjectAlias(rob) == "bubbleRob"
    left = sim.getObject("/bubbleRob/leftMotor")
    assert sim.getObjectParent(left) == rob

    sim.stopSimulation()
    assert sim.getSimulationState() == sim.simulation_stopped
    assert sim.getSimulationTime() == 0.0  # the initial scene is back
    # Stop reset the stepping level.
    assert client.setStepping(False) == 0
