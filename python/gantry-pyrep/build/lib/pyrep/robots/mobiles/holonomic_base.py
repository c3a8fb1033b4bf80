"""`HolonomicBase`: an omnidirectional base (mecanum wheels), steered by a
proportional controller towards its intermediate target."""

from __future__ import annotations

import math
from typing import List

from pyrep.const import ConfigurationPathAlgorithms as Algos
from pyrep.errors import ConfigurationPathError
from pyrep.objects.joint import Joint
from pyrep.robots import planning
from pyrep.robots.configuration_paths.holonomic_configuration_path import HolonomicConfigurationPath
from pyrep.robots.mobiles.mobile_base import MobileBase
from pyrep.robots.robot_component import copy_suffix


def _limit(value: float, bound: float) -> float:
    return max(-bound, min(bound, value))


class HolonomicBase(MobileBase):
    """`distance_from_target`: how far before the target the base stops;
    `max_velocity`, `max_velocity_rotation`: bounds of the controller's forward/side
    and turning wheel speeds; `max_acceleration`: the largest change per step, as a
    fraction of those bounds."""

    def __init__(self, count: int, num_wheels: int, distance_from_target: float, name: str, max_velocity: float = 4,
                 max_velocity_rotation: float = 6, max_acceleration: float = 0.035):
        super().__init__(count, num_wheels, name)
        suffix = copy_suffix(count)
        self.paramP = 20
        self.paramO = 10
        self.previous_forw_back_vel = 0.0
        self.previous_left_right_vel = 0.0
        self.previous_rot_vel = 0.0
        self.accelF = max_acceleration
        self.maxV = max_velocity
        self.max_v_rot = max_velocity_rotation
        self.dist1 = distance_from_target
        self.joints_slipping = [Joint("%s_slipping_m_joint%d%s" % (name, i + 1, suffix)) for i in range(num_wheels)]

    def set_base_angular_velocites(self, velocity: List[float]) -> None:
        """[forward/backward, left/right, rotation] wheel speeds (rad/s) mixed onto
        the four wheels."""
        forward, side, turn = velocity
        self.set_joint_target_velocities([-forward - side - turn, -forward + side - turn,
                                          -forward - side + turn, -forward + side + turn])

    def _facing(self, target) -> List[float]:
        return planning.box_adjusted_matrix_and_facing_angle(self.get_handle(), target.get_handle())

    def get_linear_path(self, position: List[float], angle=0) -> HolonomicConfigurationPath:
        """A straight path to [x, y] (raises ConfigurationPathError if the base would
        collide on it); the base stops `distance_from_target` before it, facing it."""
        start = self.get_position()
        start_yaw = self.get_orientation()[2]
        self.target_base.set_position([position[0], position[1], self.target_z])
        self.target_base.set_orientation([0.0, 0.0, angle])
        values = self._facing(self.target_base)
        m, angle = values[:12], values[12]
        self.intermediate_target_base.set_position(
            [m[3] - m[0] * self.dist1, m[7] - m[4] * self.dist1, self.target_z])
        self.intermediate_target_base.set_orientation([0.0, 0.0, angle])
        self.target_base.set_orientation([0.0, 0.0, angle])
        path = [[start[0], start[1], start_yaw], [position[0], position[1], angle]]
        if self._check_collision_linear_path(path):
            raise ConfigurationPathError("Could not create path. An object was detected on the linear path.")
        return HolonomicConfigurationPath(self, path)

    def get_nonlinear_path(self, position: List[float], angle=0, boundaries=2, path_pts=600, ignore_collisions=False,
                           algorithm=Algos.RRTConnect) -> HolonomicConfigurationPath:
        path = self._get_nonlinear_path_points(position, angle, boundaries, path_pts, ignore_collisions, algorithm)
        return HolonomicConfigurationPath(self, path)

    def get_base_actuation(self):
        """([forward, side, rotation] speeds, whether the target is reached)."""
        to_target = self.target_base.get_position(relative_to=self)
        yaw_to_target = self.target_base.get_orientation(relative_to=self)[2]
        to_inter = self.intermediate_target_base.get_position(relative_to=self)
        yaw_to_inter = self.intermediate_target_base.get_orientation(relative_to=self)[2]
        previous = [self.previous_forw_back_vel, self.previous_left_right_vel, self.previous_rot_vel]
        if math.hypot(to_target[0], to_target[1]) - self.dist1 < 0.001 and abs(yaw_to_target) < 0.1 * math.pi / 180:
            return previous, True
        forward = to_inter[1] * self.paramP
        side = to_inter[0] * self.paramP
        turn = -yaw_to_inter * self.paramO
        speed = math.hypot(forward, side)
        if speed > self.maxV:
            forward *= self.maxV / speed
            side *= self.maxV / speed
        turn = _limit(turn, self.max_v_rot)
        forward = previous[0] + _limit(forward - previous[0], self.maxV * self.accelF)
        side = previous[1] + _limit(side - previous[1], self.maxV * self.accelF)
        turn = previous[2] + _limit(turn - previous[2], self.max_v_rot * self.accelF)
        self.previous_forw_back_vel, self.previous_left_right_vel, self.previous_rot_vel = forward, side, turn
        return [forward, side, turn], False

    def _reset_wheel(self) -> None:
        """Puts the wheels and their slipping joints back on their joints (the
        rollers' arrangement of a mecanum wheel), resetting their dynamics."""
        for wheel in self.wheels:
            wheel.reset_dynamic_object()
        roller_orientations = [[-math.pi / 4, 0, 0], [math.pi / 4, 0, math.pi], [-math.pi / 4, 0, 0],
                               [math.pi / 4, 0, math.pi]]
        for i in range(self.num_wheels):
            joint = self.joints[i]
            self.joints_slipping[i].set_position([0, 0, 0], relative_to=joint, reset_dynamics=False)
            self.joints_slipping[i].set_orientation(roller_orientations[i % 4], relative_to=joint,
                                                    reset_dynamics=False)
            self.wheels[i].set_position([0, 0, 0], relative_to=joint, reset_dynamics=False)
            self.wheels[i].set_orientation([0, 0, 0], relative_to=joint, reset_dynamics=False)
