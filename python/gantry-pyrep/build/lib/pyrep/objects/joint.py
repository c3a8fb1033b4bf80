"""`Joint`: revolute, prismatic and spherical joints, their modes and motors.

Positions in radians (revolute) or metres (prismatic); velocities per second; forces
in N, torques in N·m.
"""

from __future__ import annotations

from typing import List, Tuple

from pyrep.backend import sim
from pyrep.const import JointMode, JointType, ObjectType
from pyrep.objects.object import Object, object_type_to_class


class Joint(Object):
    def _get_requested_type(self) -> ObjectType:
        return ObjectType.JOINT

    def get_joint_type(self) -> JointType:
        return JointType(sim.simGetJointType(self._handle))

    def get_joint_position(self) -> float:
        return sim.simGetJointPosition(self._handle)

    def set_joint_position(self, position: float, disable_dynamics: bool = False) -> None:
        """Sets the position at once. A joint in force mode follows its motor, not a
        set position, unless `disable_dynamics`: then the joint is held out of the
        dynamics for a step, moved, given the position as its target, and stepped."""
        if not disable_dynamics:
            sim.simSetJointPosition(self._handle, position)
            return
        was_model = self.is_model()
        if not was_model:
            self.set_model(True)
        prior = sim.simGetModelProperty(self._handle)
        sim.simSetModelProperty(self._handle, prior | sim.sim_modelproperty_not_dynamic)
        sim.simExtStep(True)
        sim.simSetJointPosition(self._handle, position)
        self.set_joint_target_position(position)
        sim.simExtStep(True)
        sim.simSetModelProperty(self._handle, prior)
        self.set_model(was_model)

    def get_joint_target_position(self) -> float:
        return sim.simGetJointTargetPosition(self._handle)

    def set_joint_target_position(self, position: float) -> None:
        sim.simSetJointTargetPosition(self._handle, position)

    def get_joint_target_velocity(self) -> float:
        return sim.simGetJointTargetVelocity(self._handle)

    def set_joint_target_velocity(self, velocity: float) -> None:
        sim.simSetJointTargetVelocity(self._handle, velocity)

    def get_joint_force(self) -> float:
        """The force or torque the joint applies along or about its z axis."""
        return sim.simGetJointForce(self._handle)

    def set_joint_force(self, force: float) -> None:
        """The most force or torque the motor may apply."""
        sim.simSetJointMaxForce(self._handle, force)

    def get_joint_velocity(self) -> float:
        return sim.simGetObjectFloatParameter(self._handle, sim.sim_jointfloatparam_velocity)

    def get_joint_interval(self) -> Tuple[bool, List[float]]:
        """(cyclic, [minimum, range]); the maximum is minimum + range."""
        return sim.simGetJointInterval(self._handle)

    def set_joint_interval(self, cyclic: bool, interval: List[float]) -> None:
        sim.simSetJointInterval(self._handle, cyclic, interval)

    def get_joint_upper_velocity_limit(self) -> float:
        return sim.simGetObjectFloatParameter(self._handle, sim.sim_jointfloatparam_upper_limit)

    def is_control_loop_enabled(self) -> bool:
        return bool(sim.simGetObjectInt32Parameter(self._handle, sim.sim_jointintparam_ctrl_enabled))

    def set_control_loop_enabled(self, value: bool) -> None:
        sim.simSetObjectInt32Parameter(self._handle, sim.sim_jointintparam_ctrl_enabled, int(value))

    def is_motor_enabled(self) -> bool:
        return bool(sim.simGetObjectInt32Parameter(self._handle, sim.sim_jointintparam_motor_enabled))

    def set_motor_enabled(self, value: bool) -> None:
        sim.simSetObjectInt32Parameter(self._handle, sim.sim_jointintparam_motor_enabled, int(value))

    def is_motor_locked_at_zero_velocity(self) -> bool:
        return bool(sim.simGetObjectInt32Parameter(self._handle, sim.sim_jointintparam_velocity_lock))

    def set_motor_locked_at_zero_velocity(self, value: bool) -> None:
        sim.simSetObjectInt32Parameter(self._handle, sim.sim_jointintparam_velocity_lock, int(value))

    def get_joint_mode(self) -> JointMode:
        return JointMode(sim.simGetJointMode(self._handle))

    def set_joint_mode(self, value: JointMode) -> None:
        sim.simSetJointMode(self._handle, value.value)


object_type_to_class[ObjectType.JOINT] = Joint
