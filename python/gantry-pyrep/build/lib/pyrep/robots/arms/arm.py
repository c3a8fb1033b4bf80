"""`Arm`: a serial arm with inverse kinematics and motion planning.

An arm named `Name` is found by its parts: the joints `Name_joint1..N`, the dummies
`Name_tip` (the end effector's frame) and `Name_target` (where IK drives the tip), the
IK group `Name_ik` and the collection `Name_arm` used for collision checks; the k-th
copy of the model has `#k-1` after each name.
"""

from __future__ import annotations

import warnings
from typing import List, Optional, Union

import numpy as np

from pyrep.backend import sim
from pyrep.const import ConfigurationPathAlgorithms as Algos
from pyrep.errors import ConfigurationError, ConfigurationPathError, IKError
from pyrep.objects.cartesian_path import CartesianPath
from pyrep.objects.dummy import Dummy
from pyrep.objects.object import Object
from pyrep.robots import planning
from pyrep.robots.configuration_paths.arm_configuration_path import ArmConfigurationPath
from pyrep.robots.robot_component import RobotComponent, copy_suffix

Vector = Union[List[float], np.ndarray]

# gantry's `sim.getConfigForTipPose` searches the same 10,000 samples (a fixed seed)
# on every call (docs/api.md), so a search that found nothing finds nothing again:
# the remaining trials are skipped instead of repeating it `trials` times.
_DETERMINISTIC_SAMPLER = True

_RESOLUTION_METHODS = ("pseudo_inverse", "damped_least_squares", "jacobian_transpose")


class Arm(RobotComponent):
    """An arm; `count` picks the copy (0: the original). `max_velocity`,
    `max_acceleration` and `max_jerk` bound the motion along a path (in path-length
    units, radians or metres, per second)."""

    def __init__(self, count: int, name: str, num_joints: int, base_name: Optional[str] = None,
                 max_velocity: float = 1.0, max_acceleration: float = 4.0, max_jerk: float = 1000):
        joint_names = ["%s_joint%d" % (name, i + 1) for i in range(num_joints)]
        super().__init__(count, name, joint_names, base_name)
        self.max_velocity = max_velocity
        self.max_acceleration = max_acceleration
        self.max_jerk = max_jerk
        suffix = copy_suffix(count)
        self._ik_target = Dummy("%s_target%s" % (name, suffix))
        self._ik_tip = Dummy("%s_tip%s" % (name, suffix))
        self._ik_group = sim.simGetIkGroupHandle("%s_ik%s" % (name, suffix))
        self._collision_collection = sim.simGetCollectionHandle("%s_arm%s" % (name, suffix))
        sim.register_ik_element(self._ik_group, self._ik_tip.get_handle(), self._ik_target.get_handle(),
                                self._joint_handles)

    # --- IK settings --------------------------------------------------------------

    def set_ik_element_properties(self, constraint_x=True, constraint_y=True, constraint_z=True,
                                  constraint_alpha_beta=True, constraint_gamma=True) -> None:
        """Which components of the tip's pose IK matches to the target's."""
        constraints = 0
        for on, bit in ((constraint_x, sim.sim_ik_x_constraint), (constraint_y, sim.sim_ik_y_constraint),
                        (constraint_z, sim.sim_ik_z_constraint),
                        (constraint_alpha_beta, sim.sim_ik_alpha_beta_constraint),
                        (constraint_gamma, sim.sim_ik_gamma_constraint)):
            if on:
                constraints |= bit
        sim.simSetIkElementProperties(self._ik_group, self._ik_tip.get_handle(), constraints, None, None)

    def set_ik_group_properties(self, resolution_method="pseudo_inverse", max_iterations=6, dls_damping=0.1) -> None:
        """The IK solver: `resolution_method` one of 'pseudo_inverse',
        'damped_least_squares', 'jacobian_transpose'."""
        if resolution_method not in _RESOLUTION_METHODS:
            raise ValueError(f"Invalid resolution method '{resolution_method}': must be one of "
                            + ", ".join(_RESOLUTION_METHODS))
        method = getattr(sim, f"sim_ik_{resolution_method}_method")
        sim.simSetIkGroupProperties(self._ik_group, method, max_iterations, dls_damping)

    # --- target pose --------------------------------------------------------------

    def _put_target(self, position: Vector, euler: Optional[Vector], quaternion: Optional[Vector],
                    relative_to: Optional[Object]) -> None:
        if position is None or len(position) != 3:
            raise ValueError(f"a target position has 3 values, not {position!r}")
        self._ik_target.set_position(position, relative_to)
        if euler is not None:
            if len(euler) != 3:
                raise ValueError(f"Euler angles have 3 values, not {len(euler)}")
            self._ik_target.set_orientation(euler, relative_to)
        elif quaternion is not None:
            self._ik_target.set_quaternion(quaternion, relative_to)

    @staticmethod
    def _one_rotation(euler, quaternion, error) -> None:
        if (euler is None) == (quaternion is None):
            raise error("Specify either euler or quaternion values, but not both.")

    def _joint_limits(self):
        """Lower limits and ranges of the joints, huge (cyclic) ones cut to 2 pi."""
        _, intervals = self.get_joint_intervals()
        lows = np.array([i[0] for i in intervals], dtype=np.float64)
        ranges = np.array([i[1] for i in intervals], dtype=np.float64)
        lows = np.maximum(lows, -2 * np.pi)
        ranges = np.minimum(ranges, 4 * np.pi)
        return lows.tolist(), ranges.tolist()

    # --- IK -------------------------------------------------------------------------

    def solve_ik_via_sampling(self, position: Vector, euler: Vector = None, quaternion: Vector = None,
                              ignore_collisions: bool = False, trials: int = 300, max_configs: int = 1,
                              distance_threshold: float = 0.65, max_time_ms: int = 10,
                              relative_to: Object = None) -> np.ndarray:
        """Up to `max_configs` joint configurations putting the tip at the pose,
        searched by random sampling (then IK from samples whose tip is within
        `distance_threshold` of the target) in at most `trials` attempts, sorted by
        their distance from the current configuration (nearest first). Raises
        ConfigurationError when none is found. For poses far from the current one."""
        self._one_rotation(euler, quaternion, ConfigurationError)
        if trials < 1 or max_configs < 1:
            raise ValueError("trials and max_configs must be at least 1")
        saved_pose = self._ik_target.get_pose()
        try:
            self._put_target(position, euler, quaternion, relative_to)
            lows, ranges = self._joint_limits()
            pairs = [] if ignore_collisions else [self._collision_collection, sim.sim_handle_all]
            configs: List[List[float]] = []
            for _ in range(trials):
                config = sim.simGetConfigForTipPose(self._ik_group, self._joint_handles, distance_threshold,
                                                    int(max_time_ms), None, pairs, None, lows, ranges)
                if len(config) > 0:
                    configs.append(config)
                elif _DETERMINISTIC_SAMPLER:
                    break
                if len(configs) >= max_configs:
                    break
        finally:
            self._ik_target.set_pose(saved_pose)
        if not configs:
            raise ConfigurationError("Could not find a valid joint configuration for desired end effector pose.")
        current = np.array(self.get_joint_positions())
        configs.sort(key=lambda c: float(np.linalg.norm(current - np.asarray(c))))
        return np.array(configs)

    def get_configs_for_tip_pose(self, position: Vector, euler: Vector = None, quaternion: Vector = None,
                                 ignore_collisions=False, trials=300, max_configs=60,
                                 relative_to: Object = None) -> List[List[float]]:
        """Deprecated: `solve_ik_via_sampling`."""
        warnings.warn("Please use 'solve_ik_via_sampling' instead.", DeprecationWarning)
        return list(self.solve_ik_via_sampling(position, euler, quaternion, ignore_collisions, trials, max_configs,
                                               relative_to=relative_to))

    def solve_ik_via_jacobian(self, position: Vector, euler: Vector = None, quaternion: Vector = None,
                              relative_to: Object = None, locked_joints: List[int] = None) -> List[float]:
        """The joint values that bring the tip onto the pose, by Jacobian-based IK
        from the current configuration (for nearby poses; far ones need
        `solve_ik_via_sampling`). The target dummy stays at the pose; the arm does not
        move. `locked_joints`: indices of joints IK must not move. Raises IKError."""
        self._put_target(position, euler, quaternion, relative_to)
        joints = self.joints
        if locked_joints:
            bad = [i for i in locked_joints if not 0 <= int(i) < self._num_joints]
            if bad:
                raise IKError(f"locked joint indices {bad} out of range 0..{self._num_joints - 1}")
            joints = [j for i, j in enumerate(self.joints) if i not in set(locked_joints)]
        result, values = sim.simCheckIkGroup(self._ik_group, [j.get_handle() for j in joints])
        if result == sim.sim_ikresult_fail:
            raise IKError("IK failed. Perhaps the distance between the tip and target was too large.")
        if result == sim.sim_ikresult_not_performed:
            raise IKError("IK not performed.")
        return values

    def solve_ik(self, position: Vector, euler: Vector = None, quaternion: Vector = None,
                 relative_to: Object = None) -> List[float]:
        """Deprecated: `solve_ik_via_jacobian`."""
        warnings.warn("Please use 'solve_ik_via_jacobian' instead.", DeprecationWarning)
        return self.solve_ik_via_jacobian(position, euler, quaternion, relative_to)

    # --- paths ----------------------------------------------------------------------

    def get_path_from_cartesian_path(self, path: CartesianPath) -> ArmConfigurationPath:
        """The configuration path that follows a Cartesian path (its start must be
        reachable in a straight line). Raises ConfigurationPathError."""
        points = planning.path_from_cartesian_path(path.get_handle(), self._ik_group, self._ik_target.get_handle(),
                                                   self._joint_handles)
        if len(points) == 0:
            raise ConfigurationPathError("Could not create a path from cartesian path.")
        return ArmConfigurationPath(self, points)

    def get_linear_path(self, position: Vector, euler: Vector = None, quaternion: Vector = None, steps=50,
                        ignore_collisions=False, relative_to: Object = None) -> ArmConfigurationPath:
        """A path of `steps` configurations moving the tip in a straight line (and
        its orientation evenly) from where it is to the pose. Raises
        ConfigurationPathError if IK fails on the way or the arm collides."""
        self._one_rotation(euler, quaternion, ConfigurationPathError)
        if steps < 2:
            raise ConfigurationPathError(f"a linear path needs at least 2 steps, not {steps}")
        saved_pose = self._ik_target.get_pose()
        try:
            self._put_target(position, euler, quaternion, relative_to)
            pairs = [] if ignore_collisions else [self._collision_collection, sim.sim_handle_all]
            points = sim.generateIkPath(self._ik_group, self._joint_handles, steps, pairs, None)
        finally:
            self._ik_target.set_pose(saved_pose)
        if len(points) == 0:
            raise ConfigurationPathError("Could not create path.")
        return ArmConfigurationPath(self, points)

    def get_nonlinear_path(self, position: Vector, euler: Vector = None, quaternion: Vector = None,
                           ignore_collisions=False, trials=300, max_configs=1, distance_threshold: float = 0.65,
                           max_time_ms: int = 10, trials_per_goal=1, algorithm=Algos.SBL,
                           relative_to: Object = None) -> ArmConfigurationPath:
        """A planned path in configuration space to configurations found by
        `solve_ik_via_sampling` (same arguments), planned `trials_per_goal` times with
        `algorithm` (gantry's simOMPL), the shortest kept. Raises
        ConfigurationPathError."""
        try:
            configs = self.solve_ik_via_sampling(position, euler, quaternion, ignore_collisions, trials, max_configs,
                                                 distance_threshold, max_time_ms, relative_to)
        except ConfigurationError as e:
            raise ConfigurationPathError("Could not create path.") from e
        points = planning.nonlinear_path(self._joint_handles, configs, algorithm,
                                         None if ignore_collisions else self._collision_collection,
                                         trials_per_goal)
        if len(points) == 0:
            raise ConfigurationPathError("Could not create path.")
        return ArmConfigurationPath(self, points)

    def get_path(self, position: Vector, euler: Vector = None, quaternion: Vector = None, ignore_collisions=False,
                 trials=300, max_configs=1, distance_threshold: float = 0.65, max_time_ms: int = 10,
                 trials_per_goal=1, algorithm=Algos.SBL, relative_to: Object = None) -> ArmConfigurationPath:
        """A linear path if there is one, else a planned one."""
        try:
            return self.get_linear_path(position, euler, quaternion, ignore_collisions=ignore_collisions,
                                        relative_to=relative_to)
        except ConfigurationPathError:
            pass
        return self.get_nonlinear_path(position, euler, quaternion, ignore_collisions, trials, max_configs,
                                       distance_threshold, max_time_ms, trials_per_goal, algorithm, relative_to)

    # --- other ------------------------------------------------------------------------

    def get_tip(self) -> Dummy:
        return self._ik_tip

    def get_jacobian(self) -> np.ndarray:
        """The Jacobian at the current configuration, one row per joint (base to
        tip) and one column per constrained component of the tip's pose."""
        self._ik_target.set_matrix(self._ik_tip.get_matrix())
        values, (cols, rows) = sim.simGetIkGroupMatrix(self._ik_group, 0)
        return np.array(values, dtype=np.float64).reshape((cols, rows), order="F")

    def check_arm_collision(self, obj: Optional[Object] = None) -> bool:
        """Whether the arm's collision collection touches `obj` (None: any
        collidable object)."""
        other = sim.sim_handle_all if obj is None else obj.get_handle()
        return sim.simCheckCollision(self._collision_collection, other) == 1
