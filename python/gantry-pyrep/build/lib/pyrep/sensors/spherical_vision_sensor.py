"""`SphericalVisionSensor`: a 360 x 180 degree camera made of six 90-degree vision
sensors on the faces of a cube.

The model `name` holds the six sensors `name_front`, `name_top`, `name_back`,
`name_bottom`, `name_left`, `name_right` and two output sensors `name_sensorRGB` and
`name_sensorDepth` whose resolution (width = 2 x height) is the panorama's. The
panorama is assembled by gantry's `simVision.handleSpherical`, as CoppeliaSim's vision
plugin does it: equirectangular, its centre column looking where `front` looks; depth
is the distance along each ray, normalised between the faces' clipping planes, written
as grey into `name_sensorDepth`. The model's own script assembles it every step.
"""

from __future__ import annotations

import math
from typing import List, Sequence

import numpy as np

from pyrep.backend import session, sim
from pyrep.const import ObjectType, RenderMode
from pyrep.objects.object import Object
from pyrep.objects.vision_sensor import VisionSensor

_FACES = ["front", "top", "back", "bottom", "left", "right"]


class SphericalVisionSensor(Object):
    def __init__(self, name):
        super().__init__(name)
        base = self.get_name()
        self._sensor_depth = VisionSensor("%s_sensorDepth" % base)
        self._sensor_rgb = VisionSensor("%s_sensorRGB" % base)
        self._six_sensors = [VisionSensor("%s_%s" % (base, face)) for face in _FACES]
        self._front = self._six_sensors[0]
        self._six_sensor_handles = [s.get_handle() for s in self._six_sensors]
        for sensor in [self._sensor_depth, self._sensor_rgb] + self._six_sensors:
            sensor.set_explicit_handling(1)
        self._near_clipping_plane = self.get_near_clipping_plane()
        self._far_clipping_plane = self.get_far_clipping_plane()
        self._clipping_plane_diff = self._far_clipping_plane - self._near_clipping_plane

    def _get_requested_type(self) -> ObjectType:
        return ObjectType(sim.simGetObjectType(self.get_handle()))

    def handle_explicitly(self) -> None:
        """Renders the six sensors now and assembles the panorama."""
        session.call(
            "simVision.handleSpherical",
            self._sensor_rgb.get_handle(),
            self._six_sensor_handles,
            2 * math.pi,
            math.pi,
            self._sensor_depth.get_handle(),
        )

    def capture_rgb(self) -> np.ndarray:
        """The last panorama as float RGB in [0, 1], shape (height, width, 3)."""
        return self._sensor_rgb.capture_rgb()

    def capture_depth(self, in_meters: bool = False) -> np.ndarray:
        """The last panorama's depth along each ray, shape (height, width): metres, or
        normalised between the near and far clipping planes (8 bits, as CoppeliaSim
        keeps it)."""
        depth = self._sensor_depth.capture_rgb()[:, :, 0]
        if in_meters:
            return (self._near_clipping_plane + depth * self._clipping_plane_diff).astype(np.float32)
        return depth.astype(np.float32)

    def get_resolution(self) -> List[int]:
        return self._sensor_depth.get_resolution()

    def set_resolution(self, resolution: List[int]) -> None:
        """[width, height] of the panorama: width twice the height, height even (each
        face gets height/2 squared)."""
        if len(resolution) != 2 or resolution[0] != 2 * resolution[1]:
            raise ValueError("Spherical vision sensors must have an X resolution 2x the Y resolution")
        if resolution[1] % 2 != 0:
            raise ValueError("Spherical vision sensors must have an even Y resolution")
        face = [resolution[1] // 2, resolution[1] // 2]
        for sensor in self._six_sensors:
            sensor.set_resolution(face)
        self._sensor_depth.set_resolution(list(resolution))
        self._sensor_rgb.set_resolution(list(resolution))

    def get_render_mode(self) -> RenderMode:
        return self._sensor_depth.get_render_mode()

    def set_render_mode(self, render_mode: RenderMode) -> None:
        for sensor in [self._sensor_depth, self._sensor_rgb] + self._six_sensors:
            sensor.set_render_mode(render_mode)

    def get_windowed_size(self) -> Sequence[int]:
        return self._sensor_depth.get_windowed_size()

    def set_windowed_size(self, resolution: Sequence[int] = (0, 0)) -> None:
        self._sensor_depth.set_windowed_size(resolution)
        self._sensor_rgb.set_windowed_size(resolution)

    def get_near_clipping_plane(self) -> float:
        """Metres (the six sensors')."""
        return self._front.get_near_clipping_plane()

    def set_near_clipping_plane(self, near_clipping: float) -> None:
        self._near_clipping_plane = near_clipping
        self._clipping_plane_diff = self._far_clipping_plane - near_clipping
        for sensor in self._six_sensors:
            sensor.set_near_clipping_plane(near_clipping)

    def get_far_clipping_plane(self) -> float:
        """Metres (the six sensors')."""
        return self._front.get_far_clipping_plane()

    def set_far_clipping_plane(self, far_clipping: float) -> None:
        self._far_clipping_plane = far_clipping
        self._clipping_plane_diff = far_clipping - self._near_clipping_plane
        for sensor in self._six_sensors:
            sensor.set_far_clipping_plane(far_clipping)

    def set_entity_to_render(self, entity_to_render: int) -> None:
        """The object or collection the panorama shows (-1: everything)."""
        for sensor in [self._sensor_depth, self._sensor_rgb] + self._six_sensors:
            sensor.set_entity_to_render(entity_to_render)

    def get_entity_to_render(self) -> int:
        return self._sensor_depth.get_entity_to_render()
