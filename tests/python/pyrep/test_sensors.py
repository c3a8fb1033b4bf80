"""PyRep's composite sensors on gantry (accelerometer, gyroscope, spherical vision
sensor), on PyRep's test scene."""

import numpy as np
import pytest

from pyrep.sensors.accelerometer import Accelerometer
from pyrep.sensors.gyroscope import Gyroscope
from pyrep.sensors.spherical_vision_sensor import SphericalVisionSensor


def test_accelerometer_at_rest_reads_gravity(pr_scene):
    sensor = Accelerometer("accelerometer")
    for _ in range(10):
        pr_scene.step()
    reading = sensor.read()
    assert len(reading) == 3
    assert abs(np.linalg.norm(reading) - 9.81) < 0.2


def test_gyroscope_reads_turn_rate(pr_scene):
    sensor = Gyroscope("gyroscope")
    for _ in range(5):
        pr_scene.step()
    assert np.allclose(sensor.read(), [0.0, 0.0, 0.0], atol=1e-3)
    # No time passed: zeros.
    assert sensor.read() == [0.0, 0.0, 0.0]
    sensor.set_orientation(sensor.get_orientation() + np.array([0.0, 0.0, 0.1]))
    pr_scene.step()
    rate = sensor.read()
    dt = pr_scene.get_simulation_timestep()
    assert np.allclose(rate, [0.0, 0.0, 0.1 / dt], atol=0.05)


def test_missing_sensor_parts_are_errors(pr_scene):
    with pytest.raises(RuntimeError):
        Accelerometer("gyroscope")  # has no gyroscope_mass


def test_spherical_panorama_matches_its_faces(pr_scene):
    for _ in range(3):
        pr_scene.step()
    sensor = SphericalVisionSensor("sphericalVisionRGBAndDepth")
    sensor.handle_explicitly()
    width, height = sensor.get_resolution()
    rgb = sensor.capture_rgb()
    depth = sensor.capture_depth(in_meters=True)
    normalised = sensor.capture_depth()
    assert rgb.shape == (height, width, 3) and depth.shape == (height, width)
    front, top, back = sensor._six_sensors[0], sensor._six_sensors[1], sensor._six_sensors[2]
    n = front.get_resolution()[0]
    # The centre looks where `front` looks, the top row where `top` looks, the left
    # and right edges where `back` looks.
    assert np.allclose(rgb[height // 2, width // 2], front.capture_rgb()[n // 2, n // 2], atol=0.02)
    left, right = sensor._six_sensors[4], sensor._six_sensors[5]
    assert np.allclose(rgb[height // 2, 3 * width // 4], right.capture_rgb()[n // 2, n // 2], atol=0.02)
    assert np.allclose(rgb[height // 2, width // 4], left.capture_rgb()[n // 2, n // 2], atol=0.02)
    # The panorama's depth is kept in 8 bits between the clipping planes, as
    # CoppeliaSim keeps it: one grey level of tolerance.
    near, far = sensor.get_near_clipping_plane(), sensor.get_far_clipping_plane()
    level = (far - near) / 255
    assert np.allclose(depth[height // 2, width // 2], front.capture_depth(True)[n // 2, n // 2], atol=level)
    top_depth = top.capture_depth(True)[n // 2, n // 2]
    assert np.allclose(depth[0, :], top_depth, rtol=0.1, atol=level)
    assert np.allclose(depth[height // 2, 0], back.capture_depth(True)[n // 2, n // 2], atol=level)
    # Radial depth: never shorter than the face's axial depth.
    assert depth.min() >= near * 0.99
    assert np.allclose(normalised, (depth - near) / (far - near), atol=1e-5)


def test_spherical_resolution(pr_scene):
    sensor = SphericalVisionSensor("sphericalVisionRGBAndDepth")
    sensor.set_resolution([128, 64])
    assert sensor.get_resolution() == [128, 64]
    assert sensor._six_sensors[0].get_resolution() == [32, 32]
    assert sensor.capture_rgb().shape == (64, 128, 3)
    assert sensor.capture_depth().shape == (64, 128)
    with pytest.raises(ValueError):
        sensor.set_resolution([100, 64])
    with pytest.raises(ValueError):
        sensor.set_resolution([130, 65])
