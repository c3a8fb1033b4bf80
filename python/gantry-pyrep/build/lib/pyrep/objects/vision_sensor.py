"""`VisionSensor`: RGB, depth and point clouds rendered headless by gantry.

Images come as numpy arrays with the first row at the top: RGB float32 in [0, 1]
(height x width x 3), depth float32 (height x width), normalised between the clipping
planes or in metres. The sensor looks along its +z axis, its y axis up in the image.
"""

from __future__ import annotations

import math
from typing import List, Optional, Sequence, Union

import numpy as np

from pyrep.backend import sim
from pyrep.const import ObjectType, PerspectiveMode, RenderMode
from pyrep.objects.object import Object, object_type_to_class


class VisionSensor(Object):
    def __init__(self, name_or_handle: Union[str, int]):
        super().__init__(name_or_handle)
        self.resolution = sim.simGetVisionSensorResolution(self._handle)

    @staticmethod
    def create(resolution: List[int], explicit_handling: bool = False, perspective_mode: bool = True,
               show_volume_not_detecting: bool = True, show_volume_detecting: bool = True, passive: bool = False,
               use_local_lights: bool = False, show_fog: bool = True, near_clipping_plane: float = 1e-2,
               far_clipping_plane: float = 10.0, view_angle: float = 60.0, ortho_size: float = 1.0,
               sensor_size: Optional[Sequence[float]] = None, render_mode: RenderMode = RenderMode.OPENGL3,
               position=None, orientation=None) -> "VisionSensor":
        """A new vision sensor (`view_angle` in degrees, distances in metres)."""
        flags = [(explicit_handling, 1), (perspective_mode, 2), (not show_volume_not_detecting, 4),
                 (not show_volume_detecting, 8), (passive, 16), (use_local_lights, 32), (not show_fog, 64)]
        options = 0
        for on, bit in flags:
            if on:
                options |= bit
        size = [0.01, 0.01, 0.03] if sensor_size is None else list(sensor_size)
        floats = [near_clipping_plane, far_clipping_plane,
                  math.radians(view_angle) if perspective_mode else ortho_size,
                  size[0], size[1], size[2], 0.0, 0.0, 0.0, 0.0, 0.0]
        vs = VisionSensor(sim.simCreateVisionSensor(options, [resolution[0], resolution[1], 0, 0], floats, None))
        vs.set_render_mode(render_mode)
        if position is not None:
            vs.set_position(position)
        if orientation is not None:
            vs.set_orientation(orientation)
        return vs

    def _get_requested_type(self) -> ObjectType:
        return ObjectType.VISION_SENSOR

    def handle_explicitly(self) -> None:
        """Renders now (the sensor must be explicitly handled)."""
        if not self.get_explicit_handling():
            raise RuntimeError(
                "The explicit_handling is disabled. Call set_explicit_handling(value=1) to enable explicit_handling first."
            )
        sim.simHandleVisionSensor(self._handle)

    # --- images -------------------------------------------------------------------

    def capture_rgb(self) -> np.ndarray:
        """The last rendered image (blank before the first rendering)."""
        return sim.simGetVisionSensorImage(self._handle, self.resolution)

    def capture_depth(self, in_meters: bool = False) -> np.ndarray:
        return sim.simGetVisionSensorDepthBuffer(self._handle, self.resolution, in_meters)

    def capture_pointcloud(self) -> np.ndarray:
        """Each pixel's point in the world frame (height x width x 3, metres)."""
        return self.pointcloud_from_depth(self.capture_depth(in_meters=True))

    def pointcloud_from_depth(self, depth: np.ndarray) -> np.ndarray:
        return VisionSensor.pointcloud_from_depth_and_camera_params(
            depth, self.get_matrix(), self.get_intrinsic_matrix())

    @staticmethod
    def pointcloud_from_depth_and_camera_params(depth: np.ndarray, extrinsics: np.ndarray,
                                                intrinsics: np.ndarray) -> np.ndarray:
        """Unprojects a depth image (metres along the view axis) with the camera's
        intrinsic matrix (`get_intrinsic_matrix`, whose negative focal lengths map
        image right and down to the sensor's -x and -y) and places the points with
        the sensor's 4 x 4 world matrix."""
        height, width = depth.shape
        u, v = np.meshgrid(np.arange(width, dtype=np.float64), np.arange(height, dtype=np.float64))
        fx, fy = intrinsics[0, 0], intrinsics[1, 1]
        cx, cy = intrinsics[0, 2], intrinsics[1, 2]
        z = depth.astype(np.float64)
        local = np.stack([(u - cx) * z / fx, (v - cy) * z / fy, z, np.ones_like(z)], axis=-1)
        world = local.reshape(-1, 4) @ np.asarray(extrinsics, dtype=np.float64).T
        return world[:, :3].reshape(height, width, 3)

    def get_intrinsic_matrix(self) -> np.ndarray:
        """The pinhole matrix of the sensor's perspective projection, in pixels."""
        res = np.array(self.get_resolution(), dtype=np.float64)
        angle = math.radians(self.get_perspective_angle())
        # CoppeliaSim's perspective angle spans the longer side of the image.
        ratio = res[0] / res[1]
        ax = ay = angle
        if ratio > 1:
            ay = 2 * math.atan(math.tan(angle / 2) / ratio)
        elif ratio < 1:
            ax = 2 * math.atan(math.tan(angle / 2) * ratio)
        fx = -res[0] / (2 * math.tan(ax / 2))
        fy = -res[1] / (2 * math.tan(ay / 2))
        return np.array([[fx, 0.0, res[0] / 2], [0.0, fy, res[1] / 2], [0.0, 0.0, 1.0]])

    # --- parameters ---------------------------------------------------------------

    def _int(self, param: int) -> int:
        return sim.simGetObjectInt32Parameter(self._handle, param)

    def _set_int(self, param: int, value: int) -> None:
        sim.simSetObjectInt32Parameter(self._handle, param, int(value))

    def _float(self, param: int) -> float:
        return sim.simGetObjectFloatParameter(self._handle, param)

    def _set_float(self, param: int, value: float) -> None:
        sim.simSetObjectFloatParameter(self._handle, param, float(value))

    def get_resolution(self) -> List[int]:
        return sim.simGetVisionSensorResolution(self._handle)

    def set_resolution(self, resolution: List[int]) -> None:
        self._set_int(sim.sim_visionintparam_resolution_x, resolution[0])
        self._set_int(sim.sim_visionintparam_resolution_y, resolution[1])
        self.resolution = list(resolution)

    def get_perspective_mode(self) -> PerspectiveMode:
        return PerspectiveMode(self._int(sim.sim_visionintparam_perspective_operation))

    def set_perspective_mode(self, perspective_mode: PerspectiveMode) -> None:
        self._set_int(sim.sim_visionintparam_perspective_operation, perspective_mode.value)

    def get_render_mode(self) -> RenderMode:
        return RenderMode(self._int(sim.sim_visionintparam_render_mode))

    def set_render_mode(self, render_mode: RenderMode) -> None:
        self._set_int(sim.sim_visionintparam_render_mode, render_mode.value)

    def get_windowed_size(self) -> Sequence[int]:
        return (self._int(sim.sim_visionintparam_windowed_size_x), self._int(sim.sim_visionintparam_windowed_size_y))

    def set_windowed_size(self, resolution: Sequence[int] = (0, 0)) -> None:
        self._set_int(sim.sim_visionintparam_windowed_size_x, resolution[0])
        self._set_int(sim.sim_visionintparam_windowed_size_y, resolution[1])

    def get_perspective_angle(self) -> float:
        """Degrees."""
        return math.degrees(self._float(sim.sim_visionfloatparam_perspective_angle))

    def set_perspective_angle(self, angle: float) -> None:
        """Degrees."""
        self._set_float(sim.sim_visionfloatparam_perspective_angle, math.radians(angle))

    def get_orthographic_size(self) -> float:
        return self._float(sim.sim_visionfloatparam_ortho_size)

    def set_orthographic_size(self, ortho_size: float) -> None:
        self._set_float(sim.sim_visionfloatparam_ortho_size, ortho_size)

    def get_near_clipping_plane(self) -> float:
        return self._float(sim.sim_visionfloatparam_near_clipping)

    def set_near_clipping_plane(self, near_clipping: float) -> None:
        self._set_float(sim.sim_visionfloatparam_near_clipping, near_clipping)

    def get_far_clipping_plane(self) -> float:
        return self._float(sim.sim_visionfloatparam_far_clipping)

    def set_far_clipping_plane(self, far_clipping: float) -> None:
        self._set_float(sim.sim_visionfloatparam_far_clipping, far_clipping)

    def set_entity_to_render(self, entity_to_render: int) -> None:
        """The object or collection the sensor sees (-1: everything)."""
        self._set_int(sim.sim_visionintparam_entity_to_render, entity_to_render)

    def get_entity_to_render(self) -> int:
        return self._int(sim.sim_visionintparam_entity_to_render)


object_type_to_class[ObjectType.VISION_SENSOR] = VisionSensor
