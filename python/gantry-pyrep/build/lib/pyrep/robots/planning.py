"""What PyRep's Lua add-on (`simAddOnScript_PyRep.lua`) does for the robots, in Python
over gantry's `sim` and `simOMPL`: planning an arm's path between configurations,
following a Cartesian path with IK, planning a mobile base's path, and the facing
angle a holonomic base approaches its target with."""

from __future__ import annotations

import logging
import math
from typing import List, Optional, Sequence

import numpy as np

from pyrep.backend import session, sim

log = logging.getLogger("pyrep")

# A joint with a wider interval than this (a cyclic one) is planned within it.
_JOINT_SPAN = 2 * math.pi
_SEARCH_TIME_S = 4.0
_STATES = 300


def _ompl():
    try:
        return session.current().client.require("simOMPL")
    except Exception as e:
        raise RuntimeError(f"gantry's simOMPL is not available: {e}") from e


def _ompl_call(f, *args):
    try:
        return f(*args)
    except Exception as e:
        raise RuntimeError(str(e)) from e


def _algorithm(ompl, algorithm) -> int:
    name = getattr(algorithm, "value", algorithm)
    value = getattr(ompl.Algorithm, str(name), None)
    if value is None:
        raise ValueError(f"unknown planning algorithm '{name}'")
    return value


def _path_length(path: np.ndarray) -> float:
    return float(np.sum(np.linalg.norm(np.diff(path, axis=0), axis=1))) if len(path) > 1 else 0.0


def nonlinear_path(joint_handles: Sequence[int], goal_configs: np.ndarray, algorithm,
                   collision_collection: Optional[int], trials: int = 1) -> List[float]:
    """A collision-free path (flattened configurations) from the joints' current
    configuration to one of `goal_configs`: planned `trials` times, the shortest valid
    one kept; [] if none was found. `collision_collection` None plans without
    collision checks."""
    ompl = _ompl()
    handles = [int(h) for h in joint_handles]
    n = len(handles)
    goals = np.asarray(goal_configs, dtype=np.float64).reshape(-1, n)
    start = [sim.simGetJointPosition(h) for h in handles]
    task = _ompl_call(ompl.createTask, "pyrep_arm_task")
    try:
        _ompl_call(ompl.setVerboseLevel, task, 0)
        _ompl_call(ompl.setAlgorithm, task, _algorithm(ompl, algorithm))
        spaces = []
        for i, h in enumerate(handles):
            cyclic, (low, span) = sim.simGetJointInterval(h)
            high = low + span
            if cyclic or span > 2 * _JOINT_SPAN:
                low, high = -_JOINT_SPAN, _JOINT_SPAN
            projection = i + 1 if i < 3 else 0
            spaces.append(_ompl_call(ompl.createStateSpace, f"pyrep_j{i + 1}", ompl.StateSpaceType.joint_position, h,
                                     [low], [high], projection))
        _ompl_call(ompl.setStateSpace, task, spaces)
        if collision_collection is not None:
            _ompl_call(ompl.setCollisionPairs, task, [int(collision_collection), sim.sim_handle_all])
        _ompl_call(ompl.setStartState, task, start)
        _ompl_call(ompl.setGoalState, task, goals[0].tolist())
        for goal in goals[1:]:
            _ompl_call(ompl.addGoalState, task, goal.tolist())
        best: Optional[np.ndarray] = None
        for _ in range(max(1, int(trials))):
            ret = _ompl_call(ompl.compute, task, _SEARCH_TIME_S, -1.0, _STATES)
            solved, path = (ret[0], ret[1]) if isinstance(ret, tuple) else (bool(ret), None)
            if not solved or not path:
                continue
            states = np.asarray(path, dtype=np.float64).reshape(-1, n)
            # Shortcutting may graze an invalid state: keep only paths whose states
            # are all valid.
            if collision_collection is not None and not all(
                    _ompl_call(ompl.isStateValid, task, s.tolist()) for s in states[:-1]):
                continue
            if best is None or _path_length(states) < _path_length(best):
                best = states
    finally:
        try:
            ompl.destroyTask(task)
        except Exception:  # the task is gone with the simulation
            pass
        for h, v in zip(handles, start):
            sim.simSetJointPosition(h, v)
    return [] if best is None else best.ravel().tolist()


def path_from_cartesian_path(path_handle: int, ik_group: int, ik_target: int,
                             joint_handles: Sequence[int]) -> List[float]:
    """Configurations following a Cartesian path: the IK target is moved along it in
    20 stages (5 % of its length each), each reached by a 20-point linear IK path
    from the previous stage's end; [] if a stage fails. The arm and target are put
    back."""
    handles = [int(h) for h in joint_handles]
    saved_config = [sim.simGetJointPosition(h) for h in handles]
    saved_pos = sim.simGetObjectPosition(ik_target, -1)
    saved_ori = sim.simGetObjectOrientation(ik_target, -1)
    n = len(handles)
    full: List[float] = []
    try:
        for k in range(1, 21):
            fraction = k / 20.0
            sim.simSetObjectPosition(ik_target, -1, sim.simGetPositionOnPath(path_handle, fraction))
            sim.simSetObjectOrientation(ik_target, -1, sim.simGetOrientationOnPath(path_handle, fraction))
            stage = sim.generateIkPath(ik_group, handles, 20, [], None)
            if not stage:
                return []
            full.extend(stage)
            for h, v in zip(handles, stage[-n:]):
                sim.simSetJointPosition(h, v)
        return full
    finally:
        for h, v in zip(handles, saved_config):
            sim.simSetJointPosition(h, v)
        sim.simSetObjectPosition(ik_target, -1, saved_pos)
        sim.simSetObjectOrientation(ik_target, -1, saved_ori)


def box_adjusted_matrix_and_facing_angle(base_handle: int, target_handle: int) -> List[float]:
    """The 12-value matrix at the target's position turned about z to the target's
    axis most aligned with the base-to-target direction, then that angle minus
    pi/2: the pose a holonomic base approaches its target in."""
    p_target = np.array(sim.simGetObjectPosition(target_handle, -1))
    p_base = np.array(sim.simGetObjectPosition(base_handle, -1))
    direction = p_target - p_base
    norm = np.linalg.norm(direction)
    if norm == 0.0:
        raise RuntimeError("the base is at its target: no facing direction")
    direction /= norm
    m = np.array(sim.simGetObjectMatrix(target_handle, -1)).reshape(3, 4)
    best, best_score = m[:, 0], -1.0
    for axis in range(3):
        v = m[:, axis]
        score = float(np.dot(v, direction))
        if abs(score) > best_score:
            best_score = abs(score)
            best = v if score >= 0 else -v
    angle = math.atan2(best[1], best[0])
    c, s = math.cos(angle), math.sin(angle)
    matrix = [c, -s, 0.0, float(p_target[0]), s, c, 0.0, float(p_target[1]), 0.0, 0.0, 1.0, float(p_target[2])]
    return matrix + [angle - math.pi / 2]


def nonlinear_path_mobile(base_handle: int, target_handle: int, collision_collection: Optional[int],
                          boundaries: float, path_pts: int, algorithm) -> List[float]:
    """A planned path (x, y, yaw per state, flattened) of a base from its pose to the
    target dummy's, within [-boundaries, boundaries] in x and y. CoppeliaSim plans in
    a Dubins space (turning radius 0.1 m); gantry's simOMPL has none yet, so the path
    is planned in SE(2) (pose2d) when Dubins is refused."""
    ompl = _ompl()
    start_pos = sim.simGetObjectPosition(base_handle, -1)
    start_ori = sim.simGetObjectOrientation(base_handle, -1)
    goal_pos = sim.simGetObjectPosition(target_handle, -1)
    goal_ori = sim.simGetObjectOrientation(target_handle, -1)
    saved_pos, saved_ori = start_pos, start_ori
    task = _ompl_call(ompl.createTask, "pyrep_mobile_task")
    try:
        _ompl_call(ompl.setVerboseLevel, task, 0)
        bounds = ([-boundaries, -boundaries], [boundaries, boundaries])
        try:
            space = ompl.createStateSpace("pyrep_2d", ompl.StateSpaceType.dubins, base_handle, bounds[0], bounds[1], 1)
            try:
                ompl.setDubinsParams(space, 0.1, True)
            except Exception:
                pass
        except Exception:
            log.warning("gantry's simOMPL has no Dubins space: the base's path is planned in SE(2)")
            space = _ompl_call(ompl.createStateSpace, "pyrep_2d", ompl.StateSpaceType.pose2d, base_handle,
                               bounds[0], bounds[1], 1)
        _ompl_call(ompl.setStateSpace, task, [space])
        _ompl_call(ompl.setAlgorithm, task, _algorithm(ompl, algorithm))
        if collision_collection is not None:
            _ompl_call(ompl.setCollisionPairs, task, [int(collision_collection), sim.sim_handle_all])
        _ompl_call(ompl.setStartState, task, [start_pos[0], start_pos[1], start_ori[2]])
        _ompl_call(ompl.setGoalState, task, [goal_pos[0], goal_pos[1], goal_ori[2]])
        ret = _ompl_call(ompl.compute, task, _SEARCH_TIME_S, -1.0, int(path_pts))
        solved, path = (ret[0], ret[1]) if isinstance(ret, tuple) else (bool(ret), None)
        return [float(v) for v in path] if solved and path else []
    finally:
        try:
            ompl.destroyTask(task)
        except Exception:
            pass
        sim.simSetObjectPosition(base_handle, -1, saved_pos)
        sim.simSetObjectOrientation(base_handle, -1, saved_ori)
