"""`ArmConfigurationPath`: a sequence of arm configurations, followed at bounded
velocity, acceleration and jerk.

The path is timed as a one-dimensional motion along its length in configuration space
(the sum of the Euclidean distances between consecutive configurations), with an
online trajectory generator (Reflexxes in CoppeliaSim; gantry's Ruckig): each `step`
advances that motion by one simulation time step and gives the joints the
configuration at that length, interpolated linearly between path points, as position
targets. The velocity bound is lowered until no joint would exceed its own velocity
limit.
"""

from __future__ import annotations

from typing import List, Optional, Sequence, Union

import numpy as np

from pyrep.backend import sim
from pyrep.robots.configuration_paths.configuration_path import ConfigurationPath


class ArmConfigurationPath(ConfigurationPath):
    """Configurations of `arm`, flattened (`path_points`: one value per joint per
    point)."""

    def __init__(self, arm, path_points: Union[Sequence[float], np.ndarray]):
        self._arm = arm
        self._num_joints = arm.get_joint_count()
        self._path_points = np.asarray(path_points, dtype=np.float64).ravel()
        if self._path_points.size % self._num_joints != 0:
            raise ValueError(f"{self._path_points.size} path values are not whole configurations of "
                             f"{self._num_joints} joints")
        self._rml_handle: Optional[int] = None
        self._drawing_handle: Optional[int] = None
        self._path_done = False
        self._joint_position_action: Optional[np.ndarray] = None

    def __len__(self) -> int:
        return self._path_points.size // self._num_joints

    def __getitem__(self, i) -> "ArmConfigurationPath":
        points = self._configs()[i]
        return self.__class__(arm=self._arm, path_points=np.asarray(points).ravel())

    def _configs(self) -> np.ndarray:
        return self._path_points.reshape(-1, self._num_joints)

    def _lengths(self) -> np.ndarray:
        """The path length at each point (0 at the first)."""
        configs = self._configs()
        steps = np.linalg.norm(np.diff(configs, axis=0), axis=1)
        return np.concatenate([[0.0], np.cumsum(steps)])

    def _config_at(self, length: float, lengths: np.ndarray) -> np.ndarray:
        """The configuration `length` along the path (clamped to its ends)."""
        configs = self._configs()
        if len(configs) == 1 or length <= 0.0:
            return configs[0].copy()
        if length >= lengths[-1]:
            return configs[-1].copy()
        i = int(np.searchsorted(lengths, length, side="right")) - 1
        i = min(max(i, 0), len(configs) - 2)
        span = lengths[i + 1] - lengths[i]
        t = 0.0 if span <= 0.0 else (length - lengths[i]) / span
        return configs[i] + t * (configs[i + 1] - configs[i])

    # --- following the path ---------------------------------------------------------

    def step(self) -> bool:
        """Sets the joints' position targets to the next configuration along the
        path (the caller steps the simulation). True when the end is reached; a
        finished path must be `set_to_start` before it runs again."""
        if self._path_done:
            raise RuntimeError("This path has already been completed. If you want to re-run, then call set_to_start.")
        if self._rml_handle is None:
            self._rml_handle = self._make_trajectory()
        done = self._step_motion() == 1
        self._path_done = done
        return done

    def _new_trajectory(self, max_velocity: float, total: float) -> int:
        return sim.simRMLPos(1, 0.0001, -1, [0.0, 0.0, 0.0],
                             [max_velocity, self._arm.max_acceleration, self._arm.max_jerk], [1], [total, 0.0])

    def _make_trajectory(self) -> int:
        dt = sim.simGetSimulationTimeStep()
        lengths = self._lengths()
        total = float(lengths[-1])
        limits = np.abs(np.array(self._arm.get_joint_upper_velocity_limits(), dtype=np.float64))
        limits[limits <= 0] = np.inf
        scale = 1.0
        # Dry runs: lower the speed until no joint goes faster than its limit.
        for _ in range(20):
            handle = self._new_trajectory(self._arm.max_velocity * scale, total)
            worst = 0.0
            previous = self._config_at(0.0, lengths)
            try:
                state = 0
                while state == 0:
                    state, values = sim.simRMLStep(handle, dt, 1)
                    if state < 0:
                        break
                    q = self._config_at(values[0], lengths)
                    worst = max(worst, float(np.max(np.abs(q - previous) / dt / limits)))
                    previous = q
            finally:
                sim.simRMLRemove(handle)
            if worst > 1.001:
                scale /= worst
            else:
                break
        return self._new_trajectory(self._arm.max_velocity * scale, total)

    def _step_motion(self) -> int:
        self._joint_position_action = None
        dt = sim.simGetSimulationTimeStep()
        state, values = sim.simRMLStep(self._rml_handle, dt, 1)
        if state >= 0:
            q = self._config_at(values[0], self._lengths())
            if state == 1:
                q = self._configs()[-1].copy()
            self._joint_position_action = q
            self._arm.set_joint_target_positions(q.tolist())
        if state != 0:
            sim.simRMLRemove(self._rml_handle)
            self._rml_handle = None
        if state < 0:
            raise RuntimeError(f"the trajectory generator failed (state {state})")
        return state

    def get_executed_joint_position_action(self) -> Optional[np.ndarray]:
        """The configuration the last `step` gave the joints as targets."""
        return self._joint_position_action

    def set_to_start(self, disable_dynamics: bool = False) -> None:
        """Puts the arm at the path's first configuration."""
        self._arm.set_joint_positions(self._configs()[0].tolist(), disable_dynamics=disable_dynamics)
        if self._rml_handle is not None:
            sim.simRMLRemove(self._rml_handle)
            self._rml_handle = None
        self._path_done = False

    def set_to_end(self, disable_dynamics: bool = False) -> None:
        """Puts the arm at the path's last configuration."""
        self._arm.set_joint_positions(self._configs()[-1].tolist(), disable_dynamics=disable_dynamics)

    # --- drawing ------------------------------------------------------------------------

    def visualize(self) -> None:
        """Draws the tip's path as lines in the scene (`clear_visualization` removes
        them); the arm is put back where it was."""
        if self._path_points.size == 0:
            raise RuntimeError("Can't visualise a path with no points.")
        tip = self._arm.get_tip()
        if self._drawing_handle is None:
            self._drawing_handle = sim.simAddDrawingObject(
                objectType=sim.sim_drawing_lines, size=3, duplicateTolerance=0, parentObjectHandle=-1,
                maxItemCount=99999, ambient_diffuse=[1, 0, 1])
        sim.simAddDrawingObjectItem(self._drawing_handle, None)
        saved = self._arm.get_joint_positions()
        try:
            previous: Optional[List[float]] = None
            for config in self._configs():
                self._arm.set_joint_positions(config.tolist())
                point = list(tip.get_position())
                if previous is not None:
                    sim.simAddDrawingObjectItem(self._drawing_handle, previous + point)
                previous = point
        finally:
            self._arm.set_joint_positions(saved)

    def clear_visualization(self) -> None:
        if self._drawing_handle is not None:
            sim.simAddDrawingObjectItem(self._drawing_handle, None)
