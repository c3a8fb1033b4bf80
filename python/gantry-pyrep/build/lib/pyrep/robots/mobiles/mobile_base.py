"""`MobileBase`: a wheeled base on the floor, posed by (x, y, yaw), with planning.

A base named `Name` has the wheel joints `Name_m_joint1..N`, the wheel shapes
`Name_wheel1..N`, the dummies `Name_target_base` (the goal) and
`Name_intermediate_target_base` (the next point its controller steers to), and the
collection `Name_base` for collision checks.
"""

from __future__ import annotations

import math
from typing import List, Sequence, Union

import numpy as np

from pyrep.backend import sim
from pyrep.const import ConfigurationPathAlgorithms as Algos
from pyrep.errors import ConfigurationPathError
from pyrep.objects.dummy import Dummy
from pyrep.objects.shape import Shape
from pyrep.robots import planning
from pyrep.robots.robot_component import RobotComponent, copy_suffix


class MobileBase(RobotComponent):
    def __init__(self, count: int, num_wheels: int, name: str):
        joint_names = ["%s_m_joint%d" % (name, i + 1) for i in range(num_wheels)]
        super().__init__(count, name, joint_names)
        self.num_wheels = num_wheels
        suffix = copy_suffix(count)
        self.wheels = [Shape("%s_wheel%d%s" % (name, i + 1, suffix)) for i in range(num_wheels)]
        self.intermediate_target_base = Dummy("%s_intermediate_target_base%s" % (name, suffix))
        self.target_base = Dummy("%s_target_base%s" % (name, suffix))
        self._collision_collection = sim.simGetCollectionHandle("%s_base%s" % (name, suffix))
        self.z_pos = self.get_position()[2]
        self.target_z = self.target_base.get_position()[2]
        self.wheel_radius = self.wheels[0].get_bounding_box()[5]
        self.wheel_distance = float(np.linalg.norm(self.wheels[0].get_position() - self.wheels[1].get_position()))
        # The targets hang from the base in the model file; they must stay put.
        self.intermediate_target_base.set_parent(None)
        self.target_base.set_parent(None)

    def get_2d_pose(self) -> np.ndarray:
        """[x, y, yaw] in the world."""
        return np.r_[self.get_position()[:2], self.get_orientation()[2:]]

    def set_2d_pose(self, pose: Union[List[float], np.ndarray]) -> None:
        """Places the base at [x, y, yaw], on its own height, level."""
        if len(pose) != 3:
            raise ValueError(f"a 2D pose is [x, y, yaw], not {list(pose)}")
        self._place_2d(pose, reset_dynamics=True)

    def _place_2d(self, pose, reset_dynamics: bool) -> None:
        x, y, yaw = pose
        self.set_position([x, y, self.z_pos], reset_dynamics=reset_dynamics)
        self.set_orientation([0.0, 0.0, yaw], reset_dynamics=reset_dynamics)

    def assess_collision(self) -> bool:
        """Whether the base collides with anything."""
        return sim.simCheckCollision(self._collision_collection, sim.sim_handle_all) == 1

    def set_cartesian_position(self, position: Sequence[float]) -> None:
        """Drives by a step of [dx, dy, dyaw] (over a 0.05 s step); holonomic bases
        only."""
        velocity = [position[0] / (0.05 * self.wheel_radius / 2), position[1] / (0.05 * self.wheel_radius / 2),
                    position[2]]
        self.set_base_angular_velocites(velocity)

    def set_base_angular_velocites(self, velocity: List[float]) -> None:
        raise NotImplementedError()

    def get_base_actuation(self):
        raise NotImplementedError()

    def _get_nonlinear_path_points(self, position: List[float], angle=0, boundaries=2, path_pts=600,
                                   ignore_collisions=False, algorithm=Algos.RRTConnect) -> List[List[float]]:
        """Plans to [x, y] with yaw `angle`: the states as [x, y, yaw, distance from
        the previous state]."""
        self.target_base.set_position([position[0], position[1], self.target_z])
        self.target_base.set_orientation([0.0, 0.0, angle])
        flat = planning.nonlinear_path_mobile(self.get_handle(), self.target_base.get_handle(),
                                              None if ignore_collisions else self._collision_collection,
                                              boundaries, path_pts, algorithm)
        if not flat:
            raise ConfigurationPathError("Could not create path.")
        path: List[List[float]] = []
        for i in range(len(flat) // 3):
            state = list(flat[3 * i:3 * i + 3])
            step = 0.0 if not path else math.hypot(state[0] - path[-1][0], state[1] - path[-1][1])
            path.append(state + [step])
        return path

    def _check_collision_linear_path(self, path) -> bool:
        """Whether the base collides anywhere on the straight line from path[0] to
        path[1] (50 poses checked; the base is left at the last one checked, its
        dynamics reset there: the poses between are only placed)."""
        (x0, y0, yaw0), (x1, y1, yaw1) = path[0][:3], path[1][:3]
        pose = list(path[0][:3])
        try:
            for k in range(1, 51):
                t = k / 50.0
                pose = [x0 + t * (x1 - x0), y0 + t * (y1 - y0), yaw0 if k < 47 else yaw1]
                self._place_2d(pose, reset_dynamics=False)
                if self.assess_collision():
                    return True
            return False
        finally:
            self._place_2d(pose, reset_dynamics=True)

    def copy(self) -> RobotComponent:
        self.intermediate_target_base.set_parent(self)
        self.target_base.set_parent(self)
        try:
            return super().copy()
        finally:
            self.intermediate_target_base.set_parent(None)
            self.target_base.set_parent(None)
