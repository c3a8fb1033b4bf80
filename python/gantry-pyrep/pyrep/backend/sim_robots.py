"""CoppeliaSim 4.1's C functions that PyRep's robots use (IK groups, Reflexxes motion,
path generation, drawing objects), over gantry; re-exported by `pyrep.backend.sim`.

Where gantry has the function itself it is called. Where it has only the parts, the
function is composed here from them, with CoppeliaSim 4.1's behaviour:

  * `simCheckIkGroup` (gantry has no `sim.checkIkGroup`): the group is solved with
    `sim.handleIkGroup` from the current joint values, the solution is read, and the
    joints are put back;
  * `simGenerateIkPath` (no `sim.generateIkPath`): the target dummy is moved in a
    straight line (orientation by slerp) from the tip's pose to its own, the group is
    solved at each point, the collision pairs are checked there, and the scene is put
    back;
  * `simRMLPos`/`simRMLStep`/`simRMLRemove` (no Reflexxes): gantry's Ruckig objects,
    which take the same arguments and give the same states (0 working, 1 done).

This module cannot import `pyrep.backend.sim` at load time (that module imports this
one at its end), so it keeps its own small `_call`.
"""

from __future__ import annotations

import math
from typing import Any, Dict, List, Sequence, Tuple

import numpy as np

from pyrep.backend import session as _session
from pyrep.backend.session import call as _call
from pyrep.backend.session import floats as _floats
from pyrep.errors import CallError

__all__ = [
    "simGetIkGroupHandle", "simHandleIkGroup", "simCheckIkGroup", "simGetIkGroupMatrix",
    "simSetIkGroupProperties", "simSetIkElementProperties", "simGetConfigForTipPose",
    "simGenerateIkPath", "generateIkPath", "simRMLPos", "simRMLVel", "simRMLStep", "simRMLRemove",
    "simAddDrawingObject", "simAddDrawingObjectItem", "simRemoveDrawingObject",
    "simGetCollectionHandle", "register_ik_element",
]


def _sim() -> Any:
    return _session.current().sim


def _has(name: str) -> bool:
    return getattr(_sim(), name, None) is not None


# --- IK groups ---------------------------------------------------------------------

# The tip and target dummies and the joints of each IK group, as the robots that use
# the group name them (CoppeliaSim's C API has no getter for them; generating a path
# needs the dummies, checking a group needs its joints). Filled by
# `register_ik_element`; `Arm` registers its own.
_ik_elements: Dict[Tuple[int, int], Tuple[int, int, Tuple[int, ...]]] = {}


def _world_key(group: int) -> Tuple[int, int]:
    return id(_session.current()), group


def register_ik_element(ikGroupHandle: int, tipHandle: int, targetHandle: int,
                        jointHandles: Sequence[int] = ()) -> None:
    """Records the tip and target dummies and the joints of an IK group (used where
    gantry lacks `sim.generateIkPath` and `sim.checkIkGroup`)."""
    _ik_elements[_world_key(ikGroupHandle)] = (tipHandle, targetHandle, tuple(int(h) for h in jointHandles))


def simGetIkGroupHandle(ikGroupName: str) -> int:
    return _call("getIkGroupHandle", ikGroupName)


def simHandleIkGroup(ikGroupHandle: int) -> int:
    return _call("handleIkGroup", ikGroupHandle)


def _joint_positions(handles: Sequence[int]) -> List[float]:
    return [_call("getJointPosition", h) for h in handles]


def _set_joint_positions(handles: Sequence[int], values: Sequence[float]) -> None:
    for h, v in zip(handles, values):
        _call("setJointPosition", h, float(v))


def simCheckIkGroup(ikGroupHandle: int, jointHandles: Sequence[int], jointOptions=None) -> Tuple[int, List[float]]:
    """Solves the group without moving the robot: (`sim_ikresult_*`, the joint values
    of the solution for `jointHandles`)."""
    handles = [int(h) for h in jointHandles]
    if _has("checkIkGroup"):
        ret = _call("checkIkGroup", ikGroupHandle, handles, jointOptions)
        result, values = (ret[0], ret[1]) if isinstance(ret, tuple) else (ret, [])
        return result, list(values or [])
    # Solve in the scene, read the solution, put the joints back. gantry's solver
    # moves every joint of the chain, so it cannot leave some of them out.
    element = _ik_elements.get(_world_key(ikGroupHandle))
    group_joints = list(element[2]) if element and element[2] else handles
    if set(handles) != set(group_joints):
        raise CallError("sim.checkIkGroup is not available in gantry, and its stand-in (sim.handleIkGroup) "
                           "cannot lock joints: pass all the group's joints")
    saved = _joint_positions(group_joints)
    try:
        result = _call("handleIkGroup", ikGroupHandle)
        values = _joint_positions(handles)
    finally:
        _set_joint_positions(group_joints, saved)
    return result, values


def simGetIkGroupMatrix(ikGroupHandle: int, options: int) -> Tuple[List[float], List[int]]:
    """The group's Jacobian as CoppeliaSim's C API gives it: the values (row by row,
    one row per constrained component, one column per joint) and the size as
    `[column count, row count]`, so that reshaping the values to that size in
    Fortran order gives one row per joint (PyRep's `Arm.get_jacobian`). Options 1:
    the manipulability measure, a 1 x 1 matrix."""
    ret = _call("getIkGroupMatrix", ikGroupHandle, options)
    values, size = (ret[0], ret[1]) if isinstance(ret, tuple) and len(ret) > 1 else (ret, None)
    flat = _floats(values)
    if size is None or len(size) != 2 or int(size[0]) * int(size[1]) != len(flat):
        raise CallError(f"sim.getIkGroupMatrix gave {len(flat)} values and the size {size}")
    return flat, [int(size[0]), int(size[1])]


def simSetIkGroupProperties(ikGroupHandle: int, resolutionMethod: int, maxIterations: int, damping: float) -> None:
    _call("setIkGroupProperties", ikGroupHandle, int(resolutionMethod), int(maxIterations), float(damping))


def simSetIkElementProperties(ikGroupHandle: int, tipDummyHandle: int, constraints: int, precision=None,
                              weight=None) -> None:
    _call("setIkElementProperties", ikGroupHandle, tipDummyHandle, int(constraints),
          None if precision is None else _floats(precision), None if weight is None else _floats(weight))


def simGetConfigForTipPose(ikGroupHandle: int, jointHandles: Sequence[int], thresholdDist: float, maxTimeInMs: int,
                           metric=None, collisionPairs=None, jointOptions=None, lowLimits=None,
                           ranges=None) -> List[float]:
    """A configuration that puts the group's tip on its target, or [] if none was
    found. gantry's search ignores collision pairs, so the configuration found is
    checked against them here (a colliding one counts as none found)."""
    handles = [int(h) for h in jointHandles]
    pairs = [int(h) for h in (collisionPairs or [])]
    ret = _call("getConfigForTipPose", ikGroupHandle, handles, float(thresholdDist), int(maxTimeInMs),
                None if metric is None else _floats(metric), pairs or None,
                None if jointOptions is None else list(jointOptions),
                None if lowLimits is None else _floats(lowLimits), None if ranges is None else _floats(ranges))
    if isinstance(ret, tuple):
        ret = ret[0]
    if not ret:
        return []
    config = _floats(ret)
    if pairs and _config_collides(handles, config, pairs):
        return []
    return config


def _collides(pairs: Sequence[int]) -> bool:
    for i in range(0, len(pairs) - 1, 2):
        ret = _call("checkCollision", pairs[i], pairs[i + 1])
        if (ret[0] if isinstance(ret, tuple) else ret) == 1:
            return True
    return False


def _config_collides(handles: Sequence[int], config: Sequence[float], pairs: Sequence[int]) -> bool:
    saved = _joint_positions(handles)
    try:
        _set_joint_positions(handles, config)
        return _collides(pairs)
    finally:
        _set_joint_positions(handles, saved)


def _slerp(q0: np.ndarray, q1: np.ndarray, t: float) -> np.ndarray:
    """Spherical interpolation of unit quaternions (x, y, z, w), the short way."""
    dot = float(np.dot(q0, q1))
    if dot < 0.0:
        q1, dot = -q1, -dot
    if dot > 0.9995:
        q = q0 + t * (q1 - q0)
        return q / np.linalg.norm(q)
    theta = math.acos(min(1.0, dot))
    s = math.sin(theta)
    return (math.sin((1 - t) * theta) * q0 + math.sin(t * theta) * q1) / s


def simGenerateIkPath(ikGroupHandle: int, jointHandles: Sequence[int], ptCnt: int, collisionPairs=None,
                      jointOptions=None) -> List[float]:
    """`ptCnt` configurations (flattened) that take the group's tip in a straight
    line to its target, the first being the current one; [] if the IK fails on the
    way or a collision pair collides. The scene is left as it was."""
    handles = [int(h) for h in jointHandles]
    pairs = [int(h) for h in (collisionPairs or [])]
    if ptCnt < 2:
        raise CallError("a path needs at least 2 points")
    if _has("generateIkPath"):
        ret = _call("generateIkPath", ikGroupHandle, handles, int(ptCnt), pairs or None, jointOptions)
        return _floats(ret) if ret else []
    element = _ik_elements.get(_world_key(ikGroupHandle))
    if element is None:
        raise CallError(
            "sim.generateIkPath is not available in gantry, and the tip and target of IK group "
            f"{ikGroupHandle} are unknown (register_ik_element)")
    tip, target = element[0], element[1]
    saved_joints = _joint_positions(handles)
    target_pos = np.array(_call("getObjectPosition", target, -1), dtype=np.float64)
    target_quat = np.array(_call("getObjectQuaternion", target, -1), dtype=np.float64)
    start_pos = np.array(_call("getObjectPosition", tip, -1), dtype=np.float64)
    start_quat = np.array(_call("getObjectQuaternion", tip, -1), dtype=np.float64)
    success = _sim().ikresult_success
    path: List[float] = list(saved_joints)
    try:
        if pairs and _collides(pairs):
            return []
        for i in range(1, ptCnt):
            t = i / (ptCnt - 1)
            _call("setObjectPosition", target, -1, _floats(start_pos + t * (target_pos - start_pos)))
            _call("setObjectQuaternion", target, -1, _floats(_slerp(start_quat, target_quat, t)))
            if _call("handleIkGroup", ikGroupHandle) != success:
                return []
            if pairs and _collides(pairs):
                return []
            path.extend(_joint_positions(handles))
        return path
    finally:
        _call("setObjectPosition", target, -1, _floats(target_pos))
        _call("setObjectQuaternion", target, -1, _floats(target_quat))
        _set_joint_positions(handles, saved_joints)


def generateIkPath(ikGroupHandle: int, jointHandles: Sequence[int], ptCnt: int, collisionPairs=None,
                   jointOptions=None) -> List[float]:
    """PyRep's name for `simGenerateIkPath`."""
    return simGenerateIkPath(ikGroupHandle, jointHandles, ptCnt, collisionPairs, jointOptions)


# --- Reflexxes (gantry: Ruckig) ------------------------------------------------------


def _ruckig_flags(flags: int) -> int:
    # Reflexxes' -1 is its default synchronisation: phase, else time.
    return _sim().ruckig_phasesync if flags is None or flags < 0 else int(flags)


def simRMLPos(dofs: int, smallestTimeStep: float, flags: int, currentPosVelAccel, maxVelAccelJerk, selection,
              targetPosVel) -> int:
    """A position-based online trajectory: its handle, for `simRMLStep`."""
    current, limits, target = _floats(currentPosVelAccel), _floats(maxVelAccelJerk), _floats(targetPosVel)
    if len(current) != 3 * dofs or len(limits) != 3 * dofs or len(target) != 2 * dofs:
        raise CallError(f"simRMLPos: {dofs} dofs need 3x{dofs} current values, 3x{dofs} limits and "
                           f"2x{dofs} target values")
    sel = [int(s) for s in selection]
    if _has("rmlPos"):
        return _call("rmlPos", dofs, float(smallestTimeStep), flags, current, limits, sel, target)
    return _call("ruckigPos", dofs, float(smallestTimeStep), _ruckig_flags(flags), current, limits, sel, target)


def simRMLVel(dofs: int, smallestTimeStep: float, flags: int, currentPosVelAccel, maxAccelJerk, selection,
              targetVel) -> int:
    """A velocity-based online trajectory: its handle, for `simRMLStep`."""
    current, limits, target = _floats(currentPosVelAccel), _floats(maxAccelJerk), _floats(targetVel)
    sel = [int(s) for s in selection]
    if _has("rmlVel"):
        return _call("rmlVel", dofs, float(smallestTimeStep), flags, current, limits, sel, target)
    return _call("ruckigVel", dofs, float(smallestTimeStep), _ruckig_flags(flags), current, limits, sel, target)


def simRMLStep(handle: int, timeStep: float, dofs: int) -> Tuple[int, List[float]]:
    """One step of `timeStep` seconds: (state: 0 under way, 1 reached, negative an
    error; the new positions, velocities and accelerations)."""
    name = "rmlStep" if _has("rmlStep") else "ruckigStep"
    ret = _call(name, handle, float(timeStep))
    if not isinstance(ret, tuple):
        ret = (ret,)
    state = int(ret[0])
    values = _floats(ret[1]) if len(ret) > 1 and ret[1] is not None else [0.0] * (3 * dofs)
    return state, values


def simRMLRemove(handle: int) -> None:
    _call("rmlRemove" if _has("rmlRemove") else "ruckigRemove", handle)


# --- drawing objects -------------------------------------------------------------------


def simAddDrawingObject(objectType: int, size: float, duplicateTolerance: float, parentObjectHandle: int,
                        maxItemCount: int, ambient_diffuse=None, specular=None, emission=None) -> int:
    return _call("addDrawingObject", int(objectType), float(size), float(duplicateTolerance), int(parentObjectHandle),
                 int(maxItemCount), None if ambient_diffuse is None else _floats(ambient_diffuse), None,
                 None if specular is None else _floats(specular), None if emission is None else _floats(emission))


def simAddDrawingObjectItem(objectHandle: int, itemData) -> None:
    """Adds an item (3 values a point, 6 a line, ...); None empties the object."""
    _call("addDrawingObjectItem", objectHandle, None if itemData is None else _floats(itemData))


def simRemoveDrawingObject(objectHandle: int) -> None:
    _call("removeDrawingObject", objectHandle)


# --- collections -----------------------------------------------------------------------


def simGetCollectionHandle(collectionName: str) -> int:
    handle = _call("getCollectionHandle", collectionName)
    if handle is None or handle < 0:
        raise CallError(f"collection '{collectionName}' does not exist")
    return handle
