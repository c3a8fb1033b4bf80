"""`Dummy`: a reference frame."""

from pyrep.backend import sim
from pyrep.const import ObjectType
from pyrep.objects.object import Object, object_type_to_class


class Dummy(Object):
    @staticmethod
    def create(size: float = 0.01) -> "Dummy":
        """A new dummy at the world origin (`size`: its drawn diameter, metres)."""
        return Dummy(sim.simCreateDummy(size, None))

    def _get_requested_type(self) -> ObjectType:
        return ObjectType.DUMMY


object_type_to_class[ObjectType.DUMMY] = Dummy
