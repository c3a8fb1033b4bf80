"""PyRep's `pyrep.backend.sim` over gantry: CoppeliaSim 4.1's C function names and
`sim_*` constants, for code that calls the backend directly and for the classes of
this package, which call nothing else.

Each C function is the Lua function of the same name without `sim` and with its first
letter lowered (`simGetObjectPosition` is `sim.getObjectPosition`), and runs gantry's
one implementation of it, in the simulation the calling thread launched
(`pyrep.backend.session`). What differs is the C calling convention, which this module
restores:
  * a failed call raises `RuntimeError` (the C API returns -1 and PyRep raises);
  * results the C API returns through pointers come back as PyRep returns them
    (`simReadForceSensor` gives `(state, force, torque)`, images come as numpy arrays
    with the first row at the top, ...);
  * names are objects' 4.1 names (`Panda_joint1`, `cube#0`).
A C function with no explicit wrapper below is looked up by name (module
`__getattr__`), so `sim.simGetSimulationTime()` works as its Lua twin does.
"""

from __future__ import annotations

import os
from typing import Any, Callable, List, Sequence

import numpy as np

from gantry._gantry import Engine as _Engine
from pyrep.backend import session as _session
from pyrep.backend.session import call as _call
from pyrep.backend.session import floats as _flat
from pyrep.errors import CallError

# --- constants -------------------------------------------------------------------

# CoppeliaSim 4.1 constants PyRep's API uses that gantry's registry does not define (no
# gantry function takes them, or gantry names them otherwise). gantry's own values
# below take precedence where both exist.
_SIM_41_CONSTANTS = {
    "object_volume_type": 10,
    "object_mill_type": 11,
    "object_mirror_type": 14,
    "object_octree_type": 15,
    "jointmode_motion": 1,
    "jointmode_ikdependent": 3,
    "pathproperty_show_line": 0x0001,
    "pathproperty_show_orientation": 0x0002,
    "pathproperty_closed_path": 0x0004,
    "pathproperty_automatic_orientation": 0x0008,
    "pathproperty_invert_velocity": 0x0010,
    "pathproperty_infinite_acceleration": 0x0020,
    "pathproperty_flat_path": 0x0040,
    "pathproperty_show_position": 0x0080,
    "pathproperty_auto_velocity_profile_translation": 0x0100,
    "pathproperty_auto_velocity_profile_rotation": 0x0200,
    "pathproperty_endpoints_at_zero": 0x0400,
    "pathproperty_keep_x_up": 0x0800,
    "rendermode_auxchannels": 1,
    "rendermode_povray": 3,
    "rendermode_extrenderer": 4,
    "rendermode_extrendererwindowed": 5,
    "scripttype_mainscript": 0,
    "scripttype_addonscript": 2,
    "scripttype_addonfunction": 3,
    "scripttype_customizationscript": 6,
    "stringparam_verbosity": 121,
    "texturemap_plane": 0,
    "texturemap_cylinder": 1,
    "texturemap_sphere": 2,
    "texturemap_cube": 3,
    "gui_all": 0xFFFF,
    "gui_headless": 0x10000,
}


def _constants() -> dict:
    values = {f"sim_{k}": v for k, v in _SIM_41_CONSTANTS.items()}
    for name, value in _Engine.constants("sim"):
        if "." not in name:
            values[f"sim_{name}"] = value
    return values


globals().update(_constants())

# --- calling gantry --------------------------------------------------------------


def _sim() -> Any:
    return _session.current().sim


def _lua_name(c_name: str) -> str:
    rest = c_name[3:]
    return rest[:1].lower() + rest[1:]


def __getattr__(name: str) -> Callable[..., Any]:
    # Only C names are looked up; anything else is a real missing attribute.
    if name.startswith("sim") and len(name) > 3 and name[3].isupper():
        lua = _lua_name(name)

        def call(*args: Any) -> Any:
            return _call(lua, *args)

        call.__name__ = name
        call.__doc__ = f"CoppeliaSim's {name}: gantry's sim.{lua}."
        return call
    raise AttributeError(f"module 'pyrep.backend.sim' has no attribute '{name}'")


# --- launch and stepping (PyRep's own entry points, simExt*) -----------------------


def simExtStep(stepIfRunning: bool = True) -> None:
    """One simulation step if the simulation runs (False, or stopped: nothing to do,
    gantry has no UI to refresh)."""
    s = _session.current()
    if stepIfRunning and s.running:
        try:
            s.client.step()
        except Exception as e:
            raise CallError(str(e)) from e


def simExtCallScriptFunction(
    functionNameAtScriptName: str, scriptHandleOrType: int, inputInts, inputFloats, inputStrings, inputBuffer
):
    """Calls a Lua function of a scene script with PyRep's four argument lists; it
    returns (ints, floats, strings, bytes), as PyRep's add-on protocol does."""
    name, _, script = functionNameAtScriptName.partition("@")
    handle = scriptHandleOrType
    if script:
        handle = _call("getScriptHandle", script)
    ret = _call("callScriptFunction", name, handle, list(inputInts), list(inputFloats), list(inputStrings), inputBuffer)
    if not isinstance(ret, tuple):
        ret = (ret,)
    ret = list(ret) + [[]] * (4 - len(ret))
    ints, floats, strings, buf = ret[:4]
    return list(ints or []), list(floats or []), list(strings or []), buf if buf else ""


# --- objects ---------------------------------------------------------------------


def simGetObjectHandle(objectName: str) -> int:
    return _call("getObjectHandle", objectName)


def simGetObjectName(objectHandle: int) -> str:
    """The name, or '' when the handle names no object (PyRep's `still_exists`)."""
    try:
        return _call("getObjectName", objectHandle)
    except RuntimeError:
        return ""


def simSetObjectName(objectHandle: int, name: str) -> None:
    _call("setObjectName", objectHandle, name)


def simGetObjectType(objectHandle: int) -> int:
    return _call("getObjectType", objectHandle)


def simGetObjectParent(objectHandle: int) -> int:
    parent = _call("getObjectParent", objectHandle)
    if parent == -1:
        raise CallError(f"object {objectHandle} has no parent")
    return parent


def simGetObjectChild(objectHandle: int, index: int) -> int:
    return _call("getObjectChild", objectHandle, index)


def simSetObjectParent(objectHandle: int, parentObjectHandle: int, keepInPlace: bool) -> None:
    _call("setObjectParent", objectHandle, parentObjectHandle, bool(keepInPlace))


def simGetObjectsInTree(treeBaseHandle: int, objectType: int, options: int) -> List[int]:
    return list(_call("getObjectsInTree", treeBaseHandle, objectType, options))


def simGetObjectPosition(objectHandle: int, relativeToObjectHandle: int) -> List[float]:
    return list(_call("getObjectPosition", objectHandle, relativeToObjectHandle))


def simSetObjectPosition(objectHandle: int, relativeToObjectHandle: int, position) -> None:
    _call("setObjectPosition", objectHandle, relativeToObjectHandle, _flat(position))


def simGetObjectOrientation(objectHandle: int, relativeToObjectHandle: int) -> List[float]:
    return list(_call("getObjectOrientation", objectHandle, relativeToObjectHandle))


def simSetObjectOrientation(objectHandle: int, relativeToObjectHandle: int, eulerAngles) -> None:
    _call("setObjectOrientation", objectHandle, relativeToObjectHandle, _flat(eulerAngles))


def simGetObjectQuaternion(objectHandle: int, relativeToObjectHandle: int) -> List[float]:
    return list(_call("getObjectQuaternion", objectHandle, relativeToObjectHandle))


def simSetObjectQuaternion(objectHandle: int, relativeToObjectHandle: int, quaternion) -> None:
    _call("setObjectQuaternion", objectHandle, relativeToObjectHandle, _flat(quaternion))


def simGetObjectMatrix(objectHandle: int, relativeToObjectHandle: int) -> List[float]:
    return list(_call("getObjectMatrix", objectHandle, relativeToObjectHandle))


def simSetObjectMatrix(objectHandle: int, relativeToObjectHandle: int, matrix) -> None:
    _call("setObjectMatrix", objectHandle, relativeToObjectHandle, _flat(matrix))


def simGetObjectVelocity(objectHandle: int):
    linear, angular = _call("getObjectVelocity", objectHandle)
    return list(linear), list(angular)


def simGetObjectSizeFactor(objectHandle: int) -> float:
    return _call("getObjectSizeFactor", objectHandle)


def simScaleObject(objectHandle: int, xScale: float, yScale: float, zScale: float, options: int = 0) -> None:
    _call("scaleObject", objectHandle, xScale, yScale, zScale, options)


def simRemoveObject(objectHandle: int) -> None:
    _call("removeObject", objectHandle)


def simRemoveModel(objectHandle: int) -> int:
    return _call("removeModel", objectHandle)


def simCopyPasteObjects(objectHandles: Sequence[int], options: int) -> List[int]:
    return list(_call("copyPasteObjects", list(objectHandles), options))


def simGetExtensionString(objectHandle: int, index: int, key: str) -> str:
    s = _call("getExtensionString", objectHandle, index, key or None)
    return "" if s is None else s


def simGetConfigurationTree(objectHandle: int) -> bytes:
    tree = _call("getConfigurationTree", objectHandle)
    return tree.encode("latin-1") if isinstance(tree, str) else bytes(tree)


def simSetConfigurationTree(data: bytes) -> None:
    _call("setConfigurationTree", data)


def simLoadModel(modelPathAndName: str) -> int:
    return _call("loadModel", os.fspath(modelPathAndName))


def simSaveModel(modelBaseHandle: int, modelPathAndName: str) -> None:
    _call("saveModel", modelBaseHandle, os.fspath(modelPathAndName))


def simSaveScene(filename: str) -> None:
    _call("saveScene", os.fspath(filename))


# --- shapes ----------------------------------------------------------------------


def simCreatePureShape(primitiveType: int, options: int, sizes, mass: float, precision=None) -> int:
    return _call("createPureShape", primitiveType, options, _flat(sizes), mass, list(precision) if precision else None)


def simGroupShapes(shapeHandles: Sequence[int], merge: bool = False) -> int:
    handles = list(shapeHandles)
    return _call("groupShapes", handles, bool(merge))


def simUngroupShape(shapeHandle: int) -> List[int]:
    return list(_call("ungroupShape", shapeHandle))


def simGetShapeColor(shapeHandle: int, colorName, colorComponent: int) -> List[float]:
    ret = _call("getShapeColor", shapeHandle, colorName or None, colorComponent)
    colour = ret[1] if isinstance(ret, tuple) else ret
    return list(colour)


def simSetShapeColor(shapeHandle: int, colorName, colorComponent: int, rgbData) -> None:
    _call("setShapeColor", shapeHandle, colorName or None, colorComponent, _flat(rgbData))


def simGetShapeMesh(shapeHandle: int):
    vertices, indices, normals = _call("getShapeMesh", shapeHandle)
    return list(vertices), list(indices), list(normals)


def simGetShapeMassAndInertia(shapeHandle: int, transformation=None):
    return _call("getShapeMassAndInertia", shapeHandle)


def simReorientShapeBoundingBox(shapeHandle: int, relativeToHandle: int) -> None:
    _call("reorientShapeBoundingBox", shapeHandle, relativeToHandle)


# --- joints ----------------------------------------------------------------------


def simGetJointInterval(jointHandle: int):
    cyclic, interval = _call("getJointInterval", jointHandle)
    return bool(cyclic), list(interval)


def simSetJointInterval(jointHandle: int, cyclic: bool, interval) -> None:
    _call("setJointInterval", jointHandle, bool(cyclic), _flat(interval))


def simGetJointMode(jointHandle: int) -> int:
    """The mode alone (the C API returns the options through a pointer PyRep
    ignores)."""
    ret = _call("getJointMode", jointHandle)
    return ret[0] if isinstance(ret, tuple) else ret


def simGetJointForce(jointHandle: int) -> float:
    """The force or torque on the joint along or about its axis, with CoppeliaSim
    4.1's sign: the reaction to what the motor applies (4.2 turned the sign round to
    the motor's own, which gantry's `sim.getJointForce` gives). PyRep's tests rely on
    4.1's: a motor driving towards negative positions at 0.6 N reads +0.6."""
    return -_call("getJointForce", jointHandle)


# --- sensors ---------------------------------------------------------------------


def simReadForceSensor(forceSensorHandle: int):
    state, force, torque = _call("readForceSensor", forceSensorHandle)
    return state, list(force), list(torque)


def simReadProximitySensor(sensorHandle: int):
    ret = _call("readProximitySensor", sensorHandle)
    ret = ret if isinstance(ret, tuple) else (ret,)
    state = ret[0]
    if not state:
        return 0, -1, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
    _, distance, point, handle, normal = (list(ret) + [None] * 5)[:5]
    return state, handle, list(point or []), list(normal or [])


def simCheckProximitySensor(sensorHandle: int, entityHandle: int):
    """(state, detected point in the sensor frame)."""
    ret = _call("checkProximitySensor", sensorHandle, entityHandle)
    ret = ret if isinstance(ret, tuple) else (ret,)
    point = list(ret[2]) if len(ret) > 2 and ret[2] else [0.0, 0.0, 0.0]
    return ret[0], point


def simHandleVisionSensor(sensorHandle: int):
    ret = _call("handleVisionSensor", sensorHandle)
    ret = ret if isinstance(ret, tuple) else (ret,)
    detections = ret[0]
    aux = [v for part in ret[1:] if isinstance(part, list) for v in part]
    return detections, aux


def simGetVisionSensorResolution(sensorHandle: int) -> List[int]:
    return list(_call("getVisionSensorResolution", sensorHandle))


def simGetVisionSensorImage(sensorHandle: int, resolution) -> np.ndarray:
    """RGB as float32 in [0, 1], first row at the top, shape (height, width, 3)."""
    client = _session.current().client
    img = client.image(sensorHandle, top_first=True)
    return np.asarray(img, dtype=np.float32) / 255.0


def simGetVisionSensorDepthBuffer(sensorHandle: int, resolution, in_meters: bool = False) -> np.ndarray:
    """Depth, first row at the top: normalised between the clipping planes, or in
    metres."""
    client = _session.current().client
    return np.asarray(client.depth(sensorHandle, metres=bool(in_meters), top_first=True), dtype=np.float32)


def simCheckVisionSensor(sensorHandle: int, entityHandle: int):
    return _call("checkVisionSensor", sensorHandle, entityHandle)


# --- collisions and distances ---------------------------------------------------


def simCheckCollision(entity1Handle: int, entity2Handle: int) -> int:
    ret = _call("checkCollision", entity1Handle, entity2Handle)
    return ret[0] if isinstance(ret, tuple) else ret


def simCheckDistance(entity1Handle: int, entity2Handle: int, threshold: float) -> List[float]:
    ret = _call("checkDistance", entity1Handle, entity2Handle, threshold)
    ret = ret if isinstance(ret, tuple) else (ret,)
    if not ret[0]:
        raise CallError("no distance below the threshold")
    return list(ret[1])


def simGetContactInfo(objectHandle: int, get_contact_normal: bool = True) -> list:
    """Every contact of the object: PyRep's list of dicts (the two handles, the
    contact point, and the force and its direction when asked)."""
    contacts = []
    index = 0
    while True:
        ret = _call("getContactInfo", _sim().handle_all, objectHandle, index)
        if not ret:
            break
        handles, point, force, normal = (list(ret) + [None] * 4)[:4]
        info = {"contact": list(point or []) + (list(force or []) if get_contact_normal else []),
                "contact_handles": list(handles or [])}
        if get_contact_normal:
            info["contact_normal"] = list(normal or [])
        contacts.append(info)
        index += 1
    return contacts


# --- signals ---------------------------------------------------------------------


def _signal(getter: str, name: str):
    value = _call(getter, name)
    if value is None:
        return 0, None
    return 1, value


def simGetIntegerSignal(signalName: str):
    return _signal("getInt32Signal", signalName)


def simSetIntegerSignal(signalName: str, signalValue: int) -> None:
    _call("setInt32Signal", signalName, int(signalValue))


def simClearIntegerSignal(signalName: str) -> int:
    return _call("clearInt32Signal", signalName) or 1


def simGetFloatSignal(signalName: str):
    return _signal("getFloatSignal", signalName)


def simSetFloatSignal(signalName: str, signalValue: float) -> None:
    _call("setFloatSignal", signalName, float(signalValue))


def simClearFloatSignal(signalName: str) -> int:
    return _call("clearFloatSignal", signalName) or 1


def simGetDoubleSignal(signalName: str):
    return _signal("getDoubleSignal", signalName)


def simSetDoubleSignal(signalName: str, signalValue: float) -> None:
    _call("setDoubleSignal", signalName, float(signalValue))


def simClearDoubleSignal(signalName: str) -> int:
    return _call("clearDoubleSignal", signalName) or 1


def simGetStringSignal(signalName: str):
    return _signal("getStringSignal", signalName)


def simSetStringSignal(signalName: str, signalValue) -> None:
    _call("setStringSignal", signalName, signalValue)


def simClearStringSignal(signalName: str) -> int:
    return _call("clearStringSignal", signalName) or 1


# --- simulation ------------------------------------------------------------------


def simStartSimulation() -> None:
    _call("startSimulation")
    _session.current().running = True


def simStopSimulation() -> None:
    _call("stopSimulation")
    _session.current().running = False


def simGetSimulationTimeStep() -> float:
    return _call("getSimulationTimeStep")


def simSetFloatParameter(parameter: int, value: float) -> None:
    _call("setFloatParam", parameter, float(value))


def simGetFloatParameter(parameter: int) -> float:
    return _call("getFloatParam", parameter)


def simSetInt32Parameter(parameter: int, value: int) -> None:
    _call("setInt32Param", parameter, int(value))


def simGetInt32Parameter(parameter: int) -> int:
    return _call("getInt32Param", parameter)


def simSetBoolParameter(parameter: int, value: bool) -> None:
    _call("setBoolParam", parameter, bool(value))


def simGetBoolParameter(parameter: int) -> bool:
    return _call("getBoolParam", parameter)


def simSetStringParameter(parameter: int, value: str) -> None:
    # Verbosity only tunes CoppeliaSim's console; gantry logs through Python.
    if parameter == _SIM_41_CONSTANTS["stringparam_verbosity"]:
        return
    _call("setStringParam", parameter, value)


def simGetObjectFloatParameter(objectHandle: int, parameterID: int) -> float:
    return _call("getObjectFloatParam", objectHandle, parameterID)


def simSetObjectFloatParameter(objectHandle: int, parameterID: int, parameter: float) -> None:
    _call("setObjectFloatParam", objectHandle, parameterID, float(parameter))


def simGetObjectInt32Parameter(objectHandle: int, parameterID: int) -> int:
    return _call("getObjectInt32Param", objectHandle, parameterID)


def simSetObjectInt32Parameter(objectHandle: int, parameterID: int, parameter: int) -> None:
    _call("setObjectInt32Param", objectHandle, parameterID, int(parameter))


def simGetEngineFloatParameter(paramId: int, objectHandle: int) -> float:
    return _call("getEngineFloatParam", paramId, objectHandle)


def simSetEngineFloatParameter(paramId: int, objectHandle: int, val: float) -> None:
    _call("setEngineFloatParam", paramId, objectHandle, float(val))


# --- paths -----------------------------------------------------------------------


def simGetPositionOnPath(pathHandle: int, relativeDistance: float) -> List[float]:
    return list(_call("getPositionOnPath", pathHandle, relativeDistance))


def simGetOrientationOnPath(pathHandle: int, relativeDistance: float) -> List[float]:
    return list(_call("getOrientationOnPath", pathHandle, relativeDistance))


# --- matrices --------------------------------------------------------------------


def simInvertMatrix(matrix) -> List[float]:
    return list(_call("getMatrixInverse", _flat(matrix)))


def simMultiplyMatrices(inMatrix1, inMatrix2) -> List[float]:
    return list(_call("multiplyMatrices", _flat(inMatrix1), _flat(inMatrix2)))


def simGetEulerAnglesFromMatrix(rotationMatrix) -> List[float]:
    return list(_call("getEulerAnglesFromMatrix", _flat(rotationMatrix)))


def simGetShapeViz(shapeHandle: int, index: int):
    """The visual of one element of a shape, as an object whose attributes are the
    fields of CoppeliaSim's answer (`vertices`, `indices`, `normals`, `colors`,
    `texture`, `textureRes`, `textureCoords`, `textureId`, `shadingAngle`, ...)."""
    from types import SimpleNamespace

    info = dict(_call("getShapeViz", shapeHandle, index))
    # gantry gives a shape's texture as one map (`texture`), CoppeliaSim 4.1's C struct
    # as flat fields: flattened here.
    texture = info.pop("texture", None) or {}
    fields = dict(info)
    fields.update({
        "texture": bytes(texture.get("texture", b"")),
        "textureRes": list(texture.get("resolution", [0, 0])),
        "textureCoords": list(texture.get("coordinates", [])),
        "textureId": int(texture.get("id", -1)),
        "textureApplyMode": int(texture.get("applyMode", 0)),
        "textureOptions": int(texture.get("options", 0)),
    })
    return SimpleNamespace(**fields)


def simApplyTexture(shapeHandle: int, textureCoordinates, textCoordSize: int, texture, textureResolution, options: int):
    _call("applyTexture", shapeHandle, _flat(textureCoordinates), bytes(np.asarray(texture, dtype=np.uint8).ravel()),
          [int(v) for v in textureResolution], options)


def simCreateMeshShape(options: int, shadingAngle: float, vertices, indices) -> int:
    return _call("createMeshShape", options, shadingAngle, _flat(vertices), [int(i) for i in np.asarray(indices).ravel()])


def simImportMesh(fileformat: int, pathAndFilename: str, options: int, identicalVerticeTolerance: float, scalingFactor: float):
    ret = _call("importMesh", fileformat, os.fspath(pathAndFilename), options, identicalVerticeTolerance, scalingFactor)
    vertices, indices = ret[0], ret[1]
    names = list(ret[2]) if len(ret) > 2 and ret[2] else [""] * len(vertices)
    return list(vertices), list(indices), names


def simImportShape(fileformat: int, pathAndFilename: str, options: int, identicalVerticeTolerance: float, scalingFactor: float) -> int:
    return _call("importShape", fileformat, os.fspath(pathAndFilename), options, identicalVerticeTolerance, scalingFactor)


def simGetDecimatedMesh(inVertices, inIndices, decimationPercentage: float):
    vertices, indices = _call("getDecimatedMesh", _flat(inVertices), [int(i) for i in inIndices], decimationPercentage)
    return list(vertices), list(indices)


def simConvexDecompose(shapeHandle: int, options: int, intParams, floatParams) -> int:
    return _call("convexDecompose", shapeHandle, options, list(intParams), _flat(floatParams))


def simComputeMassAndInertia(shapeHandle: int, density: float) -> int:
    return _call("computeMassAndInertia", shapeHandle, density)


def simCreateTexture(fileName: str, options: int, planeSizes=None, scalingUV=None, xy_g=None,
                     fixedResolution: int = 0, resolution=None) -> int:
    """A textured plane from an image file: its handle (its texture is the
    plane's `simGetShapeTextureId`)."""
    ret = _call("createTexture", os.fspath(fileName), options, planeSizes, scalingUV, xy_g, fixedResolution, resolution)
    return ret[0] if isinstance(ret, tuple) else ret


def simGetShapeTextureId(shapeHandle: int) -> int:
    return _call("getShapeTextureId", shapeHandle)


def simSetShapeTexture(shapeHandle: int, textureId: int, mappingMode: int, options: int, uvScaling,
                       position=None, orientation=None) -> None:
    _call("setShapeTexture", shapeHandle, textureId, mappingMode, options, _flat(uvScaling),
          None if position is None else _flat(position), None if orientation is None else _flat(orientation))


# --- lights ----------------------------------------------------------------------


def simGetLightParameters(objectHandle: int):
    """(state, diffuse rgb, specular rgb)."""
    ret = _call("getLightParameters", objectHandle)
    state, _zero, diffuse, specular = (list(ret) + [None] * 4)[:4]
    return state, list(diffuse or []), list(specular or [])


def simSetLightParameters(objectHandle: int, state, diffusePart=None, specularPart=None) -> None:
    _call("setLightParameters", objectHandle, int(bool(state)), None,
          None if diffusePart is None else _flat(diffusePart), None if specularPart is None else _flat(specularPart))


# --- octrees ---------------------------------------------------------------------


def simCreateOctree(voxelSize: float, options: int, pointSize: float) -> int:
    return _call("createOctree", voxelSize, options, pointSize)


def simInsertVoxelsIntoOctree(octreeHandle: int, options: int, pts, color=None, tag=None) -> int:
    return _call("insertVoxelsIntoOctree", octreeHandle, options, _flat(pts),
                 None if color is None else list(color), None if tag is None else list(tag))


def simRemoveVoxelsFromOctree(octreeHandle: int, options: int, pts) -> int:
    return _call("removeVoxelsFromOctree", octreeHandle, options, None if pts is None else _flat(pts))


def simGetOctreeVoxels(octreeHandle: int) -> List[float]:
    return list(_call("getOctreeVoxels", octreeHandle) or [])


def simInsertObjectIntoOctree(octreeHandle: int, objectHandle: int, options: int, color=None, tag: int = 0) -> int:
    return _call("insertObjectIntoOctree", octreeHandle, objectHandle, options,
                 None if color is None else list(color), tag)


def simSubtractObjectFromOctree(octreeHandle: int, objectHandle: int, options: int) -> int:
    return _call("subtractObjectFromOctree", octreeHandle, objectHandle, options)


def simCheckOctreePointOccupancy(octreeHandle: int, options: int, points) -> bool:
    ret = _call("checkOctreePointOccupancy", octreeHandle, options, _flat(points))
    return bool(ret[0] if isinstance(ret, tuple) else ret)


# --- paths (4.1's path objects) -----------------------------------------------------


def simCreatePath(attributes: int, intParams=None, floatParams=None, color=None) -> int:
    return _call("createPath", attributes, intParams, floatParams, color)


def simInsertPathCtrlPoints(pathHandle: int, options: int, startIndex: int, ptCnt: int, ptData) -> None:
    _call("insertPathCtrlPoints", pathHandle, options, startIndex, ptCnt, _flat(ptData))


# --- creating objects ----------------------------------------------------------------


def simCreateDummy(size: float, color=None) -> int:
    return _call("createDummy", size, None if color is None else _flat(color))


def simCreateForceSensor(options: int, intParams, floatParams, color=None) -> int:
    return _call("createForceSensor", options, list(intParams), _flat(floatParams), None if color is None else _flat(color))


def simCreateVisionSensor(options: int, intParams, floatParams, color=None) -> int:
    return _call("createVisionSensor", options, list(intParams), _flat(floatParams), None if color is None else _flat(color))


# The robots' functions (IK groups, Reflexxes, planning) live in their own file.
from pyrep.backend.sim_robots import *  # noqa: E402,F401,F403
