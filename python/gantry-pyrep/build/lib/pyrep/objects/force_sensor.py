"""`ForceSensor`: the force (N) and torque (N·m) transmitted between the sensor's
parent and child, in the sensor's frame."""

from typing import List, Tuple

from pyrep.backend import sim
from pyrep.const import ObjectType
from pyrep.objects.object import Object, object_type_to_class


class ForceSensor(Object):
    def _get_requested_type(self) -> ObjectType:
        return ObjectType.FORCE_SENSOR

    @classmethod
    def create(cls, sensor_size: float = 0.01) -> "ForceSensor":
        """A new force sensor without thresholds."""
        return cls(sim.simCreateForceSensor(0, [0, 0, 0, 0, 0], [sensor_size, 0, 0, 0, 0], None))

    def read(self) -> Tuple[List[float], List[float]]:
        """(force, torque)."""
        _, forces, torques = sim.simReadForceSensor(self._handle)
        return forces, torques


object_type_to_class[ObjectType.FORCE_SENSOR] = ForceSensor
