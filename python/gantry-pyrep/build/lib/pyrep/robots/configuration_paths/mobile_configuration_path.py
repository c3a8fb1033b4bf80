"""`MobileConfigurationPath`: a base's path as [x, y, yaw, step length] states,
followed by the base's own controller through its intermediate target."""

from __future__ import annotations

from typing import List, Optional

from pyrep.backend import sim
from pyrep.robots.configuration_paths.configuration_path import ConfigurationPath

# The intermediate target advances by at least this much path (m) at a time.
_LOOKAHEAD = 0.01


class MobileConfigurationPath(ConfigurationPath):
    def __init__(self, mobile, path_points: List[List[float]]):
        if len(path_points) == 0:
            raise ValueError("a path needs at least one state")
        self._mobile = mobile
        self._path_points = path_points
        self._drawing_handle: Optional[int] = None
        self._path_done = False
        self.i_path = -1
        self.inter_done = True
        self._num_joints = mobile.get_joint_count()
        self.set_to_start()
        if len(self._path_points) > 2:
            self._set_inter_target(0)

    def step(self) -> bool:
        raise NotImplementedError()

    def set_to_start(self) -> None:
        """Puts the base at the path's first state."""
        self._mobile.set_2d_pose(self._path_points[0][:3])
        self._path_done = False

    def set_to_end(self) -> None:
        """Puts the base at the path's last state."""
        self._mobile.set_2d_pose(self._path_points[-1][:3])

    def visualize(self) -> None:
        """Draws the base's path as lines (the base is put back)."""
        if len(self._path_points) <= 0:
            raise RuntimeError("Can't visualise a path with no points.")
        if self._drawing_handle is None:
            self._drawing_handle = sim.simAddDrawingObject(
                objectType=sim.sim_drawing_lines, size=3, duplicateTolerance=0, parentObjectHandle=-1,
                maxItemCount=99999, ambient_diffuse=[1, 0, 1])
        sim.simAddDrawingObjectItem(self._drawing_handle, None)
        saved = self._mobile.get_2d_pose()
        try:
            previous = None
            for state in self._path_points:
                self._mobile._place_2d(state[:3], reset_dynamics=False)
                point = list(self._mobile.get_position())
                if previous is not None:
                    sim.simAddDrawingObjectItem(self._drawing_handle, previous + point)
                previous = point
        finally:
            self._mobile.set_2d_pose(saved[:3])

    def clear_visualization(self) -> None:
        if self._drawing_handle is not None:
            sim.simAddDrawingObjectItem(self._drawing_handle, None)

    def _next_i_path(self) -> None:
        """Advances the index of the intermediate target by at least the look-ahead
        distance (or to the last state)."""
        travelled = 0.0
        while travelled < _LOOKAHEAD:
            self.i_path += 1
            if self.i_path >= len(self._path_points) - 1:
                self.i_path = len(self._path_points) - 1
                break
            travelled += self._path_points[self.i_path][-1]

    def _set_inter_target(self, i: int) -> None:
        x, y, yaw = self._path_points[i][:3]
        self._mobile.intermediate_target_base.set_position([x, y, self._mobile.target_z])
        self._mobile.intermediate_target_base.set_orientation([0.0, 0.0, yaw])
