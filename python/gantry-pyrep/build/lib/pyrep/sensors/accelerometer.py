"""`Accelerometer`: a model `name` holding a small mass `name_mass` on a force sensor
`name_force_sensor`; the force the sensor transmits divided by the mass is the
acceleration the model feels (gravity included), in the sensor's frame."""

from __future__ import annotations

from typing import List

from pyrep.backend import sim
from pyrep.const import ObjectType
from pyrep.objects.force_sensor import ForceSensor
from pyrep.objects.object import Object
from pyrep.objects.shape import Shape


class Accelerometer(Object):
    def __init__(self, name):
        super().__init__(name)
        base = self.get_name()
        self._mass_object = Shape("%s_mass" % base)
        self._sensor = ForceSensor("%s_force_sensor" % base)

    def _get_requested_type(self) -> ObjectType:
        return ObjectType(sim.simGetObjectType(self.get_handle()))

    def read(self) -> List[float]:
        """[ax, ay, az] (m/s^2) along the force sensor's axes."""
        forces, _ = self._sensor.read()
        mass = self._mass_object.get_mass()
        if mass <= 0:
            raise RuntimeError(f"the accelerometer's mass '{self._mass_object.get_name()}' has no mass ({mass})")
        return [float(f) / mass for f in forces]
