"""`NonHolonomicBase`: a differential-drive base (two driven wheels), steered by a
PID controller on its heading to the intermediate target."""

from __future__ import annotations

import math
from typing import List

from pyrep.const import ConfigurationPathAlgorithms as Algos
from pyrep.errors import ConfigurationPathError
from pyrep.robots.configuration_paths.nonholonomic_configuration_path import NonHolonomicConfigurationPath
from pyrep.robots.mobiles.mobile_base import MobileBase


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


class NonHolonomicBase(MobileBase):
    def __init__(self, count: int, num_wheels: int, name: str):
        super().__init__(count, num_wheels, name)
        self.cummulative_error = 0.0
        self.prev_error = 0.0
        self.Kp = 1.0
        self.Ki = 0.01
        self.Kd = 0.1
        self.desired_velocity = 0.05

    def get_base_velocities(self) -> List[float]:
        """[linear (m/s), angular (rad/s)] velocity of the base from its wheels'
        speeds (left wheel first)."""
        left, right = self.get_joint_velocities()[:2]
        linear = (left + right) * self.wheel_radius / 2.0
        angular = self.wheel_radius * (right - left) / self.wheel_distance
        return [linear, angular]

    def get_linear_path(self, position: List[float], angle=0) -> NonHolonomicConfigurationPath:
        """A straight path to [x, y], yaw `angle` (ConfigurationPathError if the base
        would collide on it)."""
        start = self.get_position()
        start_yaw = self.get_orientation()[2]
        for target in (self.target_base, self.intermediate_target_base):
            target.set_position([position[0], position[1], self.target_z])
            target.set_orientation([0.0, 0.0, angle])
        path = [[start[0], start[1], start_yaw], [position[0], position[1], angle]]
        if self._check_collision_linear_path(path):
            raise ConfigurationPathError("Could not create path. An object was detected on the linear path.")
        return NonHolonomicConfigurationPath(self, path)

    def get_nonlinear_path(self, position: List[float], angle=0, boundaries=2, path_pts=600, ignore_collisions=False,
                           algorithm=Algos.RRTConnect) -> NonHolonomicConfigurationPath:
        path = self._get_nonlinear_path_points(position, angle, boundaries, path_pts, ignore_collisions, algorithm)
        return NonHolonomicConfigurationPath(self, path)

    def get_base_actuation(self):
        """([left, right] wheel speeds, whether the target is reached (within
        10 cm))."""
        dx, dy, _ = self.intermediate_target_base.get_position(relative_to=self)
        fx, fy, _ = self.target_base.get_position(relative_to=self)
        if math.hypot(fx, fy) < 0.1:
            return [0.0, 0.0], True
        error = _wrap(math.atan2(dy, dx))
        integral = self.cummulative_error + error
        derivative = error - self.prev_error
        turn = _wrap(self.Kp * error + self.Ki * integral + self.Kd * derivative)
        self.cummulative_error = integral
        self.prev_error = error
        right = (2.0 * self.desired_velocity + turn * self.wheel_distance) / (2.0 * self.wheel_radius)
        left = (2.0 * self.desired_velocity - turn * self.wheel_distance) / (2.0 * self.wheel_radius)
        return [left, right], False
