"""(3) BubbleRob driven remotely in stepping mode with setJointTargetVelocity and
readProximitySensor.

The scene's own controller script is removed (in a copy of the scene), so the remote
client is the only controller: it drives forward until the nose sensor sees something,
which in the walled arena it must.
"""

import math

import pytest

from gantry_proc import REPO

SCENE = REPO / "assets" / "scenes" / "bubble_rob.toml"


@pytest.fixture
def scene_without_script(tmp_path):
    lines = SCENE.read_text().splitlines()
    kept = [line for line in lines if not line.strip().startswith("script")]
    # The controller and the camera's edge-detection script both go: the remote client
    # is the only driver.
    assert len(kept) == len(lines) - 2, "the scene attaches the controller and the camera script"
    path = tmp_path / "bubble_rob_remote.toml"
    path.write_text("\n".join(kept) + "\n")
    return path


def test_rover_drives_forward_until_the_sensor_sees_an_obstacle(gantry, scene_without_script):
    client = gantry(scene_without_script).client()
    sim = client.require("sim")
    client.setStepping(True)
    # Start from the initial scene, as a user script would after setup.
    sim.stopSimulation()
    client.setStepping(True)
    sim.startSimulation()

    rob = sim.getObject("/bubbleRob")
    left = sim.getObject("/bubbleRob/leftMotor")
    right = sim.getObject("/bubbleRob/rightMotor")
    nose = sim.getObject("/bubbleRob/sensingNose")
    x0, y0, _ = sim.getObjectPosition(rob, sim.handle_world)

    speed = 5.0  # rad/s: 0.2 m/s on 0.04 m wheels
    sim.setJointTargetVelocity(left, speed)
    sim.setJointTargetVelocity(right, speed)
    assert sim.getJointTargetVelocity(left) == pytest.approx(speed)

    detected = None
    for k in range(1200):  # 60 simulated seconds at most
        client.step()
        reading = sim.readProximitySensor(nose)
        # Always 5 values: result, distance, point, object handle, normal.
        assert isinstance(reading, tuple) and len(reading) == 5, reading
        result, distance, point, obj, normal = reading
        assert isinstance(result, int) and len(point) == 3 and len(normal) == 3
        if k == 40:
            x, y, _ = sim.getObjectPosition(rob, sim.handle_world)
            assert x - x0 > 0.2, f"moved forward after 2 s: {x0:.3f} -> {x:.3f}"
            assert abs(y - y0) < 0.1
        if result > 0:
            detected = (distance, point, obj)
            break
    assert detected is not None, "the nose sensor never saw anything"
    distance, point, obj = detected
    assert 0 < distance <= 0.155 + 1e-6  # the cone reaches offset + range = 0.005 + 0.15 m
    assert math.dist(point, [0, 0, 0]) == pytest.approx(distance, abs=1e-6)  # point is in the sensor frame
    assert sim.getObjectAlias(obj) in ("obstacle", "wall")
    x, _, _ = sim.getObjectPosition(rob, sim.handle_world)
    assert x - x0 > 0.5

    # Remote control: back away, and the sensor clears.
    sim.setJointTargetVelocity(left, -speed)
    sim.setJointTargetVelocity(right, -speed)
    for _ in range(40):
        client.step()
    assert sim.readProximitySensor(nose)[0] == 0
