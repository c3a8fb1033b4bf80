"""`Object`: what every scene object offers in PyRep (poses in any frame, the tree,
special and model properties, collisions, copies), over `pyrep.backend.sim`.

Frames: positions in metres, orientations as CoppeliaSim's Euler angles (alpha, beta,
gamma, radians) or quaternions (x, y, z, w); `relative_to=None` is the world frame.
"""

from __future__ import annotations

import warnings
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from pyrep.backend import sim
from pyrep.const import ObjectType
from pyrep.errors import ObjectAlreadyRemovedError, ObjectIsNotModelError, WrongObjectTypeError

# Filled by each subclass's module: the class to open an object of a given type as.
object_type_to_class: Dict[ObjectType, Any] = {}


def _handle_of(relative_to: Optional["Object"]) -> int:
    return -1 if relative_to is None else relative_to.get_handle()


def _object_type(handle: int) -> ObjectType:
    return ObjectType(sim.simGetObjectType(handle))


class Object:
    """A scene object, opened by name (CoppeliaSim 4.1 names: `cube`, `cube#0`) or
    handle. Subclasses check the type: `Joint('a_shape')` raises
    `WrongObjectTypeError`."""

    def __init__(self, name_or_handle: Union[str, int]):
        if isinstance(name_or_handle, (int, np.integer)):
            self._handle = int(name_or_handle)
        else:
            self._handle = sim.simGetObjectHandle(name_or_handle)
        wanted = self._get_requested_type()
        actual = _object_type(self._handle)
        if actual != wanted:
            raise WrongObjectTypeError(
                f"You requested object of type {wanted.name}, but the actual type was {actual.name}"
            )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Object):
            raise NotImplementedError
        return self.get_handle() == other.get_handle()

    def __hash__(self) -> int:
        return hash(self._handle)

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._handle})"

    # --- finding objects ----------------------------------------------------------

    @staticmethod
    def exists(name: str) -> bool:
        """Whether an object of that name is in the scene."""
        try:
            sim.simGetObjectHandle(name)
        except RuntimeError:
            return False
        return True

    @staticmethod
    def get_object_type(name: str) -> ObjectType:
        return _object_type(sim.simGetObjectHandle(name))

    @staticmethod
    def get_object_name(name_or_handle: Union[str, int]) -> str:
        if isinstance(name_or_handle, (int, np.integer)):
            return sim.simGetObjectName(int(name_or_handle))
        return name_or_handle

    @staticmethod
    def get_object(name_or_handle: Union[str, int]) -> "Object":
        """The object as the class of its type (`Shape`, `Joint`, ...)."""
        handle = (
            int(name_or_handle)
            if isinstance(name_or_handle, (int, np.integer))
            else sim.simGetObjectHandle(name_or_handle)
        )
        cls = object_type_to_class[_object_type(handle)]
        return cls(handle)

    def _get_requested_type(self) -> ObjectType:
        raise NotImplementedError("Must be overridden.")

    # --- identity -----------------------------------------------------------------

    def get_type(self) -> ObjectType:
        return _object_type(self._handle)

    def get_handle(self) -> int:
        return self._handle

    def still_exists(self) -> bool:
        return sim.simGetObjectName(self._handle) != ""

    def get_name(self) -> str:
        return sim.simGetObjectName(self._handle)

    def set_name(self, name: str) -> None:
        sim.simSetObjectName(self._handle, name)

    def get_extension_string(self) -> str:
        """The object's extension string (RLBench's waypoints hold their gripper
        commands there)."""
        return sim.simGetExtensionString(self._handle, -1, "")

    # --- size ---------------------------------------------------------------------

    def scale_object(self, scale_x: float, scale_y: float, scale_z: float) -> None:
        """Scales the object by these factors (applied on top of earlier scalings)."""
        sim.simScaleObject(self._handle, scale_x, scale_y, scale_z, 0)

    def get_size_factor(self) -> float:
        return sim.simGetObjectSizeFactor(self._handle)

    # --- pose ---------------------------------------------------------------------

    def _reset_tree_dynamics(self) -> None:
        for ob in self.get_objects_in_tree(exclude_base=False):
            ob.reset_dynamic_object()

    def get_position(self, relative_to: Optional["Object"] = None) -> np.ndarray:
        return np.array(sim.simGetObjectPosition(self._handle, _handle_of(relative_to)), dtype=np.float64)

    def set_position(self, position, relative_to: Optional["Object"] = None, reset_dynamics: bool = True) -> None:
        if reset_dynamics:
            self._reset_tree_dynamics()
        sim.simSetObjectPosition(self._handle, _handle_of(relative_to), list(position))

    def get_orientation(self, relative_to: Optional["Object"] = None) -> np.ndarray:
        return np.array(sim.simGetObjectOrientation(self._handle, _handle_of(relative_to)), dtype=np.float64)

    def set_orientation(self, orientation, relative_to: Optional["Object"] = None, reset_dynamics: bool = True) -> None:
        if reset_dynamics:
            self._reset_tree_dynamics()
        sim.simSetObjectOrientation(self._handle, _handle_of(relative_to), list(orientation))

    def get_quaternion(self, relative_to: Optional["Object"] = None) -> np.ndarray:
        """(x, y, z, w)."""
        return np.array(sim.simGetObjectQuaternion(self._handle, _handle_of(relative_to)), dtype=np.float64)

    def set_quaternion(self, quaternion, relative_to: Optional["Object"] = None, reset_dynamics: bool = True) -> None:
        """(x, y, z, w), normalised here if it is not."""
        q = np.asarray(quaternion, dtype=np.float64)
        if q.shape != (4,):
            raise ValueError(f"a quaternion has 4 components (x, y, z, w), not {q.size}")
        norm = np.linalg.norm(q)
        if not np.isfinite(norm) or norm == 0.0:
            raise ValueError(f"quaternion {list(q)} cannot be normalised")
        if reset_dynamics:
            self._reset_tree_dynamics()
        sim.simSetObjectQuaternion(self._handle, _handle_of(relative_to), list(q / norm))

    def get_pose(self, relative_to: Optional["Object"] = None) -> np.ndarray:
        """(x, y, z, qx, qy, qz, qw)."""
        return np.r_[self.get_position(relative_to), self.get_quaternion(relative_to)]

    def set_pose(self, pose, relative_to: Optional["Object"] = None, reset_dynamics: bool = True) -> None:
        if len(pose) != 7:
            raise ValueError(f"a pose has 7 values (x, y, z, qx, qy, qz, qw), not {len(pose)}")
        self.set_position(pose[:3], relative_to, reset_dynamics)
        self.set_quaternion(pose[3:], relative_to, reset_dynamics)

    def get_matrix(self, relative_to: Optional["Object"] = None) -> np.ndarray:
        """The 4 x 4 homogeneous transform."""
        m = np.array(sim.simGetObjectMatrix(self._handle, _handle_of(relative_to)), dtype=np.float64)
        return np.vstack([m.reshape(3, 4), [0.0, 0.0, 0.0, 1.0]])

    def set_matrix(self, matrix: np.ndarray, relative_to: Optional["Object"] = None) -> None:
        if not isinstance(matrix, np.ndarray):
            raise ValueError("Expected Numpy 4x4 array.")
        sim.simSetObjectMatrix(self._handle, _handle_of(relative_to), matrix[:3, :4].reshape(12).tolist())

    def rotate(self, rotation: Sequence[float]) -> None:
        """Turns the object about its own x, y and z axes, in place, by these angles
        (radians): z first, then y, then x, each about the axis as it was before."""
        m = self.get_matrix()
        r = np.eye(3)
        for axis, angle in ((2, rotation[2]), (1, rotation[1]), (0, rotation[0])):
            r = _axis_rotation(m[:3, axis], angle) @ r
        out = m.copy()
        out[:3, :3] = r @ m[:3, :3]
        self.set_matrix(out)

    def get_velocity(self) -> Tuple[np.ndarray, np.ndarray]:
        """Linear (m/s) and angular (rad/s) velocity in the world frame."""
        linear, angular = sim.simGetObjectVelocity(self._handle)
        return np.array(linear, dtype=np.float64), np.array(angular, dtype=np.float64)

    # --- tree ---------------------------------------------------------------------

    def get_parent(self) -> Optional["Object"]:
        try:
            handle = sim.simGetObjectParent(self._handle)
        except RuntimeError:
            return None
        cls = object_type_to_class.get(_object_type(handle), Object)
        return cls(handle)

    def set_parent(self, parent_object: Optional["Object"], keep_in_place: bool = True) -> None:
        sim.simSetObjectParent(self._handle, _handle_of(parent_object), keep_in_place)

    @staticmethod
    def _get_objects_in_tree(
        root_object=None, object_type: ObjectType = ObjectType.ALL, exclude_base: bool = True,
        first_generation_only: bool = False,
    ) -> List["Object"]:
        if root_object is None:
            root = sim.sim_handle_scene
        elif isinstance(root_object, Object):
            root = root_object.get_handle()
        elif isinstance(root_object, (int, np.integer)):
            root = int(root_object)
        else:
            raise ValueError("root_object must be None, int or Object")
        options = (1 if exclude_base else 0) | (2 if first_generation_only else 0)
        objects = []
        for handle in sim.simGetObjectsInTree(root, object_type.value, options):
            kind = _object_type(handle)
            cls = object_type_to_class.get(kind)
            if cls is None:
                warnings.warn(f"Object ({handle}, '{sim.simGetObjectName(handle)}') has {kind}, which is not supported")
                continue
            objects.append(cls(handle))
        return objects

    def get_objects_in_tree(self, *args, **kwargs) -> List["Object"]:
        """The objects below this one (`object_type`, `exclude_base=True`,
        `first_generation_only=False`)."""
        return self._get_objects_in_tree(self._handle, *args, **kwargs)

    def copy(self) -> "Object":
        """A copy of the object (and what belongs to it: its scripts)."""
        return self.__class__(sim.simCopyPasteObjects([self._handle], 0)[0])

    def remove(self) -> None:
        """Removes the object (the whole model if it is a model base)."""
        try:
            if self.is_model():
                sim.simRemoveModel(self._handle)
            else:
                sim.simRemoveObject(self._handle)
        except RuntimeError as e:
            raise ObjectAlreadyRemovedError("The object/model was already deleted.") from e

    def reset_dynamic_object(self) -> None:
        """Rebuilds the object's body in the physics engine where it now is (its
        velocities are lost)."""
        sim.simResetDynamicObject(self._handle)

    def get_configuration_tree(self) -> bytes:
        """The poses and joint values of this object and those below it, for
        `PyRep.set_configuration_tree` to restore later."""
        return sim.simGetConfigurationTree(self._handle)

    # --- bounding boxes -----------------------------------------------------------

    def get_bounding_box(self) -> List[float]:
        """min x, max x, min y, max y, min z, max z in the object's frame."""
        return [
            sim.simGetObjectFloatParameter(self._handle, getattr(sim, f"sim_objfloatparam_objbbox_{end}_{axis}"))
            for axis in "xyz"
            for end in ("min", "max")
        ]

    def get_model_bounding_box(self) -> List[float]:
        """The same, of the whole model (this object must be a model base)."""
        self._check_model()
        return [
            sim.simGetObjectFloatParameter(self._handle, getattr(sim, f"sim_objfloatparam_modelbbox_{end}_{axis}"))
            for axis in "xyz"
            for end in ("min", "max")
        ]

    # --- collisions and contacts --------------------------------------------------

    def check_collision(self, obj: Optional["Object"] = None) -> bool:
        """Whether this object collides with `obj` (None: with any collidable
        object)."""
        other = sim.sim_handle_all if obj is None else obj.get_handle()
        return sim.simCheckCollision(self._handle, other) == 1

    def check_distance(self, other: "Object") -> float:
        """The smallest distance to `other`, metres."""
        return sim.simCheckDistance(self._handle, other.get_handle(), -1)[6]

    def get_contact(self, contact_obj: Optional["Object"] = None, get_contact_normal: bool = True) -> List:
        contacts = sim.simGetContactInfo(self._handle, get_contact_normal)
        if contact_obj is None:
            return contacts
        other = contact_obj.get_handle()
        return [c for c in contacts if other in c["contact_handles"]]

    # --- special properties -------------------------------------------------------

    def _get_property(self, prop_type: int) -> bool:
        return bool(sim.simGetObjectSpecialProperty(self._handle) & prop_type)

    def _set_property(self, prop_type: int, value: bool) -> None:
        current = sim.simGetObjectSpecialProperty(self._handle)
        current = (current | prop_type) if value else (current & ~prop_type)
        sim.simSetObjectSpecialProperty(self._handle, current)

    def is_collidable(self) -> bool:
        return self._get_property(sim.sim_objectspecialproperty_collidable)

    def set_collidable(self, value: bool) -> None:
        self._set_property(sim.sim_objectspecialproperty_collidable, value)

    def is_measurable(self) -> bool:
        return self._get_property(sim.sim_objectspecialproperty_measurable)

    def set_measurable(self, value: bool) -> None:
        self._set_property(sim.sim_objectspecialproperty_measurable, value)

    def is_detectable(self) -> bool:
        return self._get_property(sim.sim_objectspecialproperty_detectable_all)

    def set_detectable(self, value: bool) -> None:
        self._set_property(sim.sim_objectspecialproperty_detectable_all, value)

    def is_renderable(self) -> bool:
        return self._get_property(sim.sim_objectspecialproperty_renderable)

    def set_renderable(self, value: bool) -> None:
        self._set_property(sim.sim_objectspecialproperty_renderable, value)

    # --- models -------------------------------------------------------------------

    def is_model(self) -> bool:
        return not (sim.simGetModelProperty(self._handle) & sim.sim_modelproperty_not_model)

    def set_model(self, value: bool) -> None:
        current = sim.simGetModelProperty(self._handle)
        flag = sim.sim_modelproperty_not_model
        sim.simSetModelProperty(self._handle, (current & ~flag) if value else (current | flag))

    def _check_model(self) -> None:
        if not self.is_model():
            raise ObjectIsNotModelError(
                f"Object '{self.get_name()}' is not a model. Use 'set_model(True)' to convert."
            )

    def _get_model_property(self, not_flag: int) -> bool:
        return (sim.simGetModelProperty(self._handle) & not_flag) == 0

    def _set_model_property(self, not_flag: int, value: bool) -> None:
        current = sim.simGetModelProperty(self._handle)
        sim.simSetModelProperty(self._handle, (current & ~not_flag) if value else (current | not_flag))

    def is_model_collidable(self) -> bool:
        return self._get_model_property(sim.sim_modelproperty_not_collidable)

    def set_model_collidable(self, value: bool) -> None:
        self._set_model_property(sim.sim_modelproperty_not_collidable, value)

    def is_model_measurable(self) -> bool:
        return self._get_model_property(sim.sim_modelproperty_not_measurable)

    def set_model_measurable(self, value: bool) -> None:
        self._set_model_property(sim.sim_modelproperty_not_measurable, value)

    def is_model_detectable(self) -> bool:
        return self._get_model_property(sim.sim_modelproperty_not_detectable)

    def set_model_detectable(self, value: bool) -> None:
        self._set_model_property(sim.sim_modelproperty_not_detectable, value)

    def is_model_renderable(self) -> bool:
        return self._get_model_property(sim.sim_modelproperty_not_renderable)

    def set_model_renderable(self, value: bool) -> None:
        self._set_model_property(sim.sim_modelproperty_not_renderable, value)

    def is_model_dynamic(self) -> bool:
        return self._get_model_property(sim.sim_modelproperty_not_dynamic)

    def set_model_dynamic(self, value: bool) -> None:
        self._set_model_property(sim.sim_modelproperty_not_dynamic, value)

    def is_model_respondable(self) -> bool:
        return self._get_model_property(sim.sim_modelproperty_not_respondable)

    def set_model_respondable(self, value: bool) -> None:
        self._set_model_property(sim.sim_modelproperty_not_respondable, value)

    def save_model(self, path: str) -> None:
        """Saves the model below this object (gantry writes its TOML scene format)."""
        self._check_model()
        sim.simSaveModel(self._handle, path)

    # --- physics engine -----------------------------------------------------------

    def get_bullet_friction(self) -> float:
        return sim.simGetEngineFloatParameter(sim.sim_bullet_body_friction, self._handle)

    def set_bullet_friction(self, friction: float) -> None:
        sim.simSetEngineFloatParameter(sim.sim_bullet_body_friction, self._handle, friction)

    def get_explicit_handling(self) -> int:
        return sim.simGetExplicitHandling(self._handle)

    def set_explicit_handling(self, value: int) -> None:
        sim.simSetExplicitHandling(self._handle, value)


def _axis_rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """The rotation matrix of `angle` radians about the unit vector `axis`."""
    a = np.asarray(axis, dtype=np.float64)
    a = a / np.linalg.norm(a)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * (k @ k)
