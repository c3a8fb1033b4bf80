"""`RobotComponent`: a model whose joints are driven together (an arm, a gripper, a
mobile base): every joint quantity as one vector, in the order of `joint_names`."""

from __future__ import annotations

from typing import List, Optional, Sequence, Tuple

from pyrep.backend import sim, utils
from pyrep.const import JointMode, JointType, ObjectType
from pyrep.objects.joint import Joint
from pyrep.objects.object import Object


def copy_suffix(count: int) -> str:
    """The name suffix of the `count`-th copy of a model: '' for the original (0),
    '#0' for the first copy (1), '#1' for the next, as CoppeliaSim 4.1 names them."""
    if count < 0:
        raise ValueError(f"a robot's count is 0 (the original) or more, not {count}")
    return "" if count == 0 else "#%d" % (count - 1)


def _copy_count(name: str, handle: int, limit: int = 10000) -> int:
    """The `count` of the copy `handle` of the model named `name`: k + 1 when
    `name#k` names it. (gantry may report a copy's name without its suffix, so the
    suffix is found by looking the candidates up.)"""
    base = name.split("#", 1)[0]
    for k in range(limit):
        try:
            if sim.simGetObjectHandle("%s#%d" % (base, k)) == handle:
                return k + 1
        except RuntimeError:
            continue
    raise RuntimeError(f"the copy {handle} of '{base}' has no name '{base}#k' (k < {limit})")


class RobotComponent(Object):
    """The model base named `name` (or `base_name`) and its joints `joint_names`,
    each name taking the `#k` suffix of the `count`-th copy."""

    def __init__(self, count: int, name: str, joint_names: List[str], base_name: Optional[str] = None):
        suffix = copy_suffix(count)
        super().__init__((name if base_name is None else base_name) + suffix)
        self._num_joints = len(joint_names)
        self.joints = [Joint(joint_name + suffix) for joint_name in joint_names]
        self._joint_handles = [j.get_handle() for j in self.joints]

    def _get_requested_type(self) -> ObjectType:
        # A robot's base may be any kind of object: accept what it is.
        return ObjectType(sim.simGetObjectType(self.get_handle()))

    def copy(self) -> "RobotComponent":
        """Pastes a copy of the whole model (with its scripts) and returns it as a
        component of the same class."""
        handle = sim.simCopyPasteObjects([self._handle], 1)[0]
        return self.__class__(_copy_count(self.get_name(), handle))  # type: ignore[call-arg]

    # --- joint vectors ------------------------------------------------------------

    def _assert_len(self, inputs: Sequence) -> None:
        if len(inputs) != self._num_joints:
            raise RuntimeError(
                f"Tried to set values for {len(inputs)} joints, but joint group consists of "
                f"{self._num_joints} joints.")

    def get_joint_count(self) -> int:
        return self._num_joints

    def get_joint_types(self) -> List[JointType]:
        return [j.get_joint_type() for j in self.joints]

    def get_joint_positions(self) -> List[float]:
        """Radians or metres per joint."""
        return [j.get_joint_position() for j in self.joints]

    def set_joint_positions(self, positions: Sequence[float], disable_dynamics: bool = False) -> None:
        """Puts the joints at `positions` at once. Joints driven by the physics engine
        follow their motors instead, unless `disable_dynamics`: then the model leaves
        the dynamics for a step while the joints are placed (and given the positions
        as targets), and comes back."""
        self._assert_len(positions)
        values = [float(p) for p in positions]
        if not disable_dynamics:
            for handle, value in zip(self._joint_handles, values):
                sim.simSetJointPosition(handle, value)
            return
        was_model = self.is_model()
        if not was_model:
            self.set_model(True)
        prior = sim.simGetModelProperty(self._handle)
        sim.simSetModelProperty(self._handle, prior | sim.sim_modelproperty_not_dynamic)
        with utils.step_lock:
            sim.simExtStep(True)
        for joint, value in zip(self.joints, values):
            sim.simSetJointPosition(joint.get_handle(), value)
            joint.set_joint_target_position(value)
        with utils.step_lock:
            sim.simExtStep(True)
        sim.simSetModelProperty(self._handle, prior)
        self.set_model(was_model)

    def get_joint_target_positions(self) -> List[float]:
        return [j.get_joint_target_position() for j in self.joints]

    def set_joint_target_positions(self, positions: Sequence[float]) -> None:
        """Targets of the joints' position controllers."""
        self._assert_len(positions)
        for joint, value in zip(self.joints, positions):
            joint.set_joint_target_position(float(value))

    def get_joint_target_velocities(self) -> List[float]:
        return [j.get_joint_target_velocity() for j in self.joints]

    def set_joint_target_velocities(self, velocities: Sequence[float]) -> None:
        self._assert_len(velocities)
        for joint, value in zip(self.joints, velocities):
            joint.set_joint_target_velocity(float(value))

    def get_joint_forces(self) -> List[float]:
        """The force or torque each joint applies along or about its z axis."""
        return [j.get_joint_force() for j in self.joints]

    def set_joint_forces(self, forces: Sequence[float]) -> None:
        """The most force or torque each motor may apply (not negative)."""
        self._assert_len(forces)
        for joint, value in zip(self.joints, forces):
            joint.set_joint_force(float(value))

    def get_joint_velocities(self) -> List[float]:
        return [j.get_joint_velocity() for j in self.joints]

    def get_joint_intervals(self) -> Tuple[List[bool], List[List[float]]]:
        """(cyclic flags, [minimum, range] per joint)."""
        cyclics, intervals = [], []
        for joint in self.joints:
            cyclic, interval = joint.get_joint_interval()
            cyclics.append(cyclic)
            intervals.append(interval)
        return cyclics, intervals

    def set_joint_intervals(self, cyclic: Sequence[bool], intervals: Sequence[Sequence[float]]) -> None:
        self._assert_len(cyclic)
        self._assert_len(intervals)
        for joint, c, interval in zip(self.joints, cyclic, intervals):
            joint.set_joint_interval(c, list(interval))

    def get_joint_upper_velocity_limits(self) -> List[float]:
        return [j.get_joint_upper_velocity_limit() for j in self.joints]

    def set_control_loop_enabled(self, value: bool) -> None:
        for joint in self.joints:
            joint.set_control_loop_enabled(value)

    def set_motor_locked_at_zero_velocity(self, value: bool) -> None:
        for joint in self.joints:
            joint.set_motor_locked_at_zero_velocity(value)

    def set_joint_mode(self, value: JointMode) -> None:
        for joint in self.joints:
            joint.set_joint_mode(value)

    def get_joint_modes(self) -> List[JointMode]:
        return [j.get_joint_mode() for j in self.joints]

    def get_visuals(self) -> List[Object]:
        """The shapes of the model whose name says 'visual' (for domain
        randomisation, say)."""
        shapes = self.get_objects_in_tree(ObjectType.SHAPE, exclude_base=False)
        return [s for s in shapes if "visual" in s.get_name()]
