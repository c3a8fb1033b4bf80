"""Blocking calls from Python, as CoppeliaSim's own examples make them
(simpleMovement.py, sendMovementSequence-simMoveToConfig.py): ``sim.moveToConfig``,
``sim.moveToPose`` and ``sim.wait`` return once the motion or the time is done, with
the simulation stepping for them, over ZMQ and in-process."""

import math
import time

import pytest


@pytest.mark.scene("assets/scenes/fk_arm.toml")
def test_move_to_config_and_pose_block_until_done_in_stepping_mode(client):
    sim = client.require("sim")
    joints = [sim.getObject(f"/arm6/joint{i}") for i in range(1, 7)]
    target = sim.getObject("/target")
    # gantry runs its scene at once, and free (--fast, or in real time in process) until
    # setStepping holds it wherever it got to: stop it first, so that the run starts
    # at step 0 every time rather than at a step that depends on the wall clock.
    sim.stopSimulation()
    client.setStepping(True)
    sim.startSimulation()
    t0 = sim.getSimulationTime()
    assert t0 == 0.0

    goal = [0.5, -0.3, 0.4, 0.0, -math.pi / 2 + 0.2, 0.1]
    params = {
        "joints": joints,
        "targetPos": goal,
        "maxVel": [1.0] * 6,
        "maxAccel": [2.0] * 6,
        "maxJerk": [10.0] * 6,
    }
    result = sim.moveToConfig(params)
    reached = [sim.getJointPosition(j) for j in joints]
    assert reached == pytest.approx(goal, abs=1e-6)
    assert result["pos"] == pytest.approx(goal, abs=1e-6)
    t1 = sim.getSimulationTime()
    # 0.5 rad at 1 rad/s with the acceleration limit: well over half a second.
    assert t1 - t0 > 0.5, f"the motion took the steps it needed ({t1 - t0} s)"

    pose = sim.getObjectPose(target)
    goal_pose = list(pose)
    goal_pose[2] += 0.1
    sim.moveToPose({
        "object": target,
        "targetPose": goal_pose,
        "maxVel": [0.2] * 4,
        "maxAccel": [0.5] * 4,
        "maxJerk": [5.0] * 4,
    })
    assert sim.getObjectPose(target)[:3] == pytest.approx(goal_pose[:3], abs=1e-6)
    assert sim.getSimulationTime() - t1 > 0.3

    # sim.wait in simulation time, then in wall-clock time.
    t2 = sim.getSimulationTime()
    left = sim.wait(0.5)
    assert left <= 0
    assert sim.getSimulationTime() - t2 == pytest.approx(0.5, abs=0.051)
    start = time.monotonic()
    sim.wait(0.2, False)
    assert time.monotonic() - start >= 0.19

    # The client's own stepping goes on afterwards.
    t3 = sim.getSimulationTime()
    client.step()
    assert sim.getSimulationTime() == pytest.approx(t3 + 0.05, abs=1e-9)
    sim.stopSimulation()


@pytest.mark.scene("assets/scenes/fk_arm.toml")
def test_blocking_calls_are_refused_while_stopped_and_bad_arguments_are_named(client):
    sim = client.require("sim")
    sim.stopSimulation()  # gantry runs its scene at once
    with pytest.raises(Exception, match=r"simulation is stopped.*sim\.wait"):
        sim.wait(0.1)
    sim.startSimulation()
    with pytest.raises(Exception, match=r"moveToConfig"):
        sim.moveToConfig({"joints": [sim.getObject("/arm6/joint1")], "targetPos": [1, 2]})
    sim.stopSimulation()


@pytest.mark.scene("assets/scenes/fk_arm.toml")
def test_wait_takes_and_returns_the_same_whatever_step_it_starts_at(client):
    """Issue 47: ``sim.wait`` returned ``(t0 + dt) - t1`` of two simulation times, 0 or a
    few 1e-16 either side of it depending on the step it started at (+8.9e-16 once)."""
    sim = client.require("sim")
    sim.stopSimulation()  # from step 0, as in the test above
    client.setStepping(True)
    sim.startSimulation()
    dt = sim.getSimulationTimeStep()
    assert dt == 0.05
    for _ in range(25):
        # Each wait starts 11 steps after the last one, at steps 0 to 264, where the
        # old difference of times came out above, below and on zero.
        t = sim.getSimulationTime()
        assert sim.wait(0.5) == 0.0
        assert round((sim.getSimulationTime() - t) / dt) == 10
        client.step()
