"""(4) Errors reach the client as CoppeliaSim's do, and never hurt the server."""

import pytest


@pytest.mark.scene("assets/scenes/fk_arm.toml")
def test_unknown_object(client):
    sim = client.require("sim")
    with pytest.raises(Exception) as e:
        sim.getObject("/doesNotExist")
    assert type(e.value) is Exception
    text = str(e.value)
    assert "object does not exist" in text
    assert "(in function 'sim.getObject')" in text


@pytest.mark.scene("assets/scenes/fk_arm.toml")
def test_unknown_function(client):
    sim = client.require("sim")
    # Not in zmqRemoteApi.info: the client refuses before sending anything.
    with pytest.raises(AttributeError):
        sim.bogus(1)
    # Sent anyway: the server's own answer.
    with pytest.raises(Exception, match=r"^No such function: sim\.bogus$"):
        client.call("sim.bogus", [1, None])
    with pytest.raises(Exception, match="not available"):
        client.require("simNotAModule")


@pytest.mark.scene("assets/scenes/fk_arm.toml")
def test_wrong_argument_types(client):
    sim = client.require("sim")
    j = sim.getObject("/arm6/joint1")
    cases = [
        (lambda: sim.getObjectPosition("joint1", -1), "argument 1", "sim.getObjectPosition"),
        (lambda: sim.setJointPosition(j, "fast"), "argument 2", "sim.setJointPosition"),
        (lambda: sim.setObjectPosition(j, [1, 2], -1), "", "sim.setObjectPosition"),
        (lambda: sim.getObject(42), "argument 1", "sim.getObject"),
        (lambda: sim.setStepping("yes"), "argument 1", "sim.setStepping"),
    ]
    for call, what, func in cases:
        with pytest.raises(Exception) as e:
            call()
        assert what in str(e.value) and f"(in function '{func}')" in str(e.value), str(e.value)
    # Still served after all of that, and still running: before or after its first step,
    # depending on how soon the loaded machine let the simulation take it.
    assert sim.getJointPosition(j) == pytest.approx(0.0)
    assert sim.getSimulationState() in (sim.simulation_advancing_firstafterstop, sim.simulation_advancing_running)
