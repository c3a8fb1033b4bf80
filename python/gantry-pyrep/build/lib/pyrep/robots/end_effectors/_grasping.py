"""Kinematic grasping shared by grippers and suction cups: an object the end
effector's proximity sensor detects is re-parented (kept in place) under its attach
point, and given back to its old parent on release."""

from __future__ import annotations

from typing import List, Optional

from pyrep.objects.force_sensor import ForceSensor
from pyrep.objects.object import Object
from pyrep.objects.proximity_sensor import ProximitySensor


class Grasping:
    _proximity_sensor: ProximitySensor
    _attach_point: ForceSensor

    def _init_grasping(self) -> None:
        self._old_parents: List[Optional[Object]] = []
        self._grasped_objects: List[Object] = []

    def grasp(self, obj: Object) -> bool:
        """Attaches `obj` if the proximity sensor detects it (the end effector is not
        moved: the grasp is kinematic). True if it is detected."""
        if not isinstance(obj, Object):
            raise TypeError(f"grasp takes a scene Object, not {type(obj).__name__}")
        detected = self._proximity_sensor.is_detected(obj)
        if detected and obj not in self._grasped_objects:
            self._grasped_objects.append(obj)
            self._old_parents.append(obj.get_parent())
            obj.set_parent(self._attach_point, keep_in_place=True)
        return detected

    def release(self) -> None:
        """Gives every grasped object (still in the scene) back to its old parent,
        where it is now."""
        for obj, parent in zip(self._grasped_objects, self._old_parents):
            if obj.still_exists():
                obj.set_parent(parent, keep_in_place=True)
        self._grasped_objects = []
        self._old_parents = []

    def get_grasped_objects(self) -> List[Object]:
        return self._grasped_objects
