"""`ProximitySensor`: the distance to the nearest detectable object in its volume."""

import math

from pyrep.backend import sim
from pyrep.const import ObjectType
from pyrep.objects.object import Object, object_type_to_class


class ProximitySensor(Object):
    def _get_requested_type(self) -> ObjectType:
        return ObjectType.PROXIMITY_SENSOR

    def read(self) -> float:
        """The distance (m) to the detected point, or -1.0 when nothing is detected."""
        state, _, point, _ = sim.simReadProximitySensor(self._handle)
        if state:
            return math.sqrt(sum(c * c for c in point))
        return -1.0

    def is_detected(self, obj: Object) -> bool:
        """Whether `obj` is in the sensor's volume now."""
        state, _ = sim.simCheckProximitySensor(self._handle, obj.get_handle())
        return state == 1


object_type_to_class[ObjectType.PROXIMITY_SENSOR] = ProximitySensor
