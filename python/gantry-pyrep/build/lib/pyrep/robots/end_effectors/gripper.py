"""`Gripper`: fingers driven by velocity, and a kinematic grasp.

A gripper named `Name` has the joints given by its class, the proximity sensor
`Name_attachProxSensor` that decides what can be grasped, the force sensor
`Name_attachPoint` grasped objects hang from, and optionally touch sensors
`Name_touchSensor0..` (force sensors).
"""

from __future__ import annotations

from typing import List, Optional

import numpy as np

from pyrep.objects.force_sensor import ForceSensor
from pyrep.objects.proximity_sensor import ProximitySensor
from pyrep.robots.end_effectors._grasping import Grasping
from pyrep.robots.robot_component import RobotComponent, copy_suffix

# A finger that moves less than this in a step (m or rad) has stopped.
POSITION_ERROR = 0.001


class Gripper(Grasping, RobotComponent):
    def __init__(self, count: int, name: str, joint_names: List[str]):
        super().__init__(count, name, joint_names)
        suffix = copy_suffix(count)
        self._proximity_sensor = ProximitySensor("%s_attachProxSensor%s" % (name, suffix))
        self._attach_point = ForceSensor("%s_attachPoint%s" % (name, suffix))
        self._init_grasping()
        self._prev_positions: List[Optional[float]] = [None] * len(joint_names)
        self._prev_vels: List[Optional[float]] = [None] * len(joint_names)
        # Steps each finger has been driven at its current velocity: a motor takes a
        # step to reach its speed, so a finger is judged stopped only after that.
        self._driven_steps: List[int] = [0] * len(joint_names)
        self._touch_sensors: List[ForceSensor] = []
        i = 0
        while ForceSensor.exists("%s_touchSensor%d%s" % (name, i, suffix)):
            self._touch_sensors.append(ForceSensor("%s_touchSensor%d%s" % (name, i, suffix)))
            i += 1

    def _intervals(self) -> np.ndarray:
        """[lowest, highest] position of each finger joint."""
        _, intervals = self.get_joint_intervals()
        lows = np.array([i[0] for i in intervals], dtype=np.float64)
        spans = np.array([i[1] for i in intervals], dtype=np.float64)
        return np.stack([lows, lows + spans], axis=1)

    def _reset_actuation(self) -> None:
        self._prev_positions = [None] * self._num_joints
        self._prev_vels = [None] * self._num_joints
        self._driven_steps = [0] * self._num_joints

    def actuate(self, amount: float, velocity: float) -> bool:
        """Drives the fingers towards `amount` open (1 open, 0 closed) at `velocity`;
        call once per simulation step until it returns True: every finger has reached
        its position, stopped (held by an object) or started to oscillate."""
        if not 0.0 <= amount <= 1.0:
            raise ValueError("'open_amount' should be between 0 and 1.'")
        limits = self._intervals()
        targets = limits[:, 0] + (limits[:, 1] - limits[:, 0]) * amount
        current = self.get_joint_positions()
        done = True
        for i, (joint, target, position) in enumerate(zip(self.joints, targets, current)):
            previous = self._prev_positions[i]
            stopped = (previous is not None and self._driven_steps[i] >= 2
                       and abs(position - previous) < POSITION_ERROR)
            arrived = abs(target - position) < POSITION_ERROR
            vel = -velocity if position > target else velocity
            oscillating = self._prev_vels[i] is not None and vel != self._prev_vels[i]
            if stopped or arrived or oscillating:
                joint.set_joint_target_velocity(0.0)
                continue
            done = False
            self._prev_vels[i] = vel
            self._driven_steps[i] += 1
            joint.set_joint_target_velocity(vel)
        self._prev_positions = list(current)
        if done:
            self._reset_actuation()
            self.set_joint_target_velocities([0.0] * self._num_joints)
        return done

    def get_open_amount(self) -> List[float]:
        """How open each finger is, 0 (closed) to 1 (open)."""
        limits = self._intervals()
        spans = limits[:, 1] - limits[:, 0]
        spans[spans == 0] = 1.0
        amounts = (np.array(self.get_joint_positions()) - limits[:, 0]) / spans
        return list(np.clip(amounts, 0.0, 1.0))

    def get_touch_sensor_forces(self) -> List[List[float]]:
        """The force each touch sensor reads."""
        if not self._touch_sensors:
            raise NotImplementedError("No touch sensors for this robot!")
        return [sensor.read()[0] for sensor in self._touch_sensors]
