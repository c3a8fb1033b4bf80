"""`SuctionCup`: a shape that holds what its sensor `Name_sensor` detects, from its
force sensor `Name_connection` (a kinematic grasp: the object is not pulled in, so the
sensor's range should be short)."""

from __future__ import annotations

from typing import Optional

from pyrep.objects.force_sensor import ForceSensor
from pyrep.objects.proximity_sensor import ProximitySensor
from pyrep.objects.shape import Shape
from pyrep.robots.end_effectors._grasping import Grasping
from pyrep.robots.robot_component import copy_suffix


class SuctionCup(Grasping, Shape):
    def __init__(self, count: int, name: str, base_name: Optional[str] = None):
        suffix = copy_suffix(count)
        super().__init__((name if base_name is None else base_name) + suffix)
        self._proximity_sensor = ProximitySensor("%s_sensor%s" % (name, suffix))
        self._attach_point = ForceSensor("%s_connection%s" % (name, suffix))
        self._init_grasping()
