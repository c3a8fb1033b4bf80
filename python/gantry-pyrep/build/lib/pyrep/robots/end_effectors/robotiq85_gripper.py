"""The Robotiq 85 gripper (ROBOTIQ_85): two active joints, opened or closed fully;
its opening is read from the passive finger joints."""

from __future__ import annotations

from typing import List

import numpy as np

from pyrep.objects.joint import Joint
from pyrep.robots.end_effectors.gripper import Gripper
from pyrep.robots.robot_component import copy_suffix

# The active joints barely move near the ends of their travel.
POSITION_ERROR = 0.00001


class Robotiq85Gripper(Gripper):
    def __init__(self, count: int = 0):
        super().__init__(count, "ROBOTIQ_85", ["ROBOTIQ_85_active1", "ROBOTIQ_85_active2"])
        suffix = copy_suffix(count)
        self._open_amount_query_joints = [Joint(n + suffix) for n in ("ROBOTIQ_85_Rjoint1", "ROBOTIQ_85_Ljoint1")]

    def actuate(self, amount: float, velocity: float) -> bool:
        """Opens (`amount` 1) or closes (0) the gripper at `velocity`; call each step
        until True (every active joint has stopped)."""
        if amount not in (0.0, 1.0):
            raise ValueError("This gripper currently only supports fully open or closed.")
        vel = velocity if amount == 1.0 else -velocity
        current = self.get_joint_positions()
        done = True
        for i, (joint, position) in enumerate(zip(self.joints, current)):
            previous = self._prev_positions[i]
            if (previous is not None and self._driven_steps[i] >= 2
                    and abs(position - previous) < POSITION_ERROR):
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
        """1 open, 0 closed, per finger (the passive joints close as they rise)."""
        lows, spans, positions = [], [], []
        for joint in self._open_amount_query_joints:
            _, (low, span) = joint.get_joint_interval()
            lows.append(low)
            spans.append(span if span != 0 else 1.0)
            positions.append(joint.get_joint_position())
        amounts = (np.array(positions) - np.array(lows)) / np.array(spans)
        return list(1.0 - np.clip(amounts, 0.0, 1.0))
