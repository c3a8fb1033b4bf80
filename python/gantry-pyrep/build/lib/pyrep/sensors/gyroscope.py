"""`Gyroscope`: the angular velocity of an object, from how its orientation changed
since the last reading over the simulation time that passed."""

from __future__ import annotations

from typing import List

from pyrep.backend import sim
from pyrep.const import ObjectType
from pyrep.objects.object import Object


class Gyroscope(Object):
    def __init__(self, name):
        super().__init__(name)
        self._ref = "%s_reference" % self.get_name()
        self._last_time = sim.simGetSimulationTime()
        self._old_transformation_matrix = self._matrix12()

    def _get_requested_type(self) -> ObjectType:
        return ObjectType(sim.simGetObjectType(self.get_handle()))

    def _matrix12(self) -> List[float]:
        return self.get_matrix()[:3, :4].reshape(12).tolist()

    def read(self) -> List[float]:
        """[wx, wy, wz] (rad/s) about the gyroscope's own axes, averaged since the
        last reading (or its creation); zeros if no simulation time passed."""
        now = sim.simGetSimulationTime()
        dt = now - self._last_time
        current = self._matrix12()
        relative = sim.simMultiplyMatrices(sim.simInvertMatrix(self._old_transformation_matrix), current)
        angles = sim.simGetEulerAnglesFromMatrix(relative)
        self._last_time = now
        self._old_transformation_matrix = current
        if dt == 0:
            return [0.0, 0.0, 0.0]
        return [a / dt for a in angles]
