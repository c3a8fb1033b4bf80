"""`Distance`: a distance object of a 4.1 scene, read after each step."""

from typing import Union

from pyrep.backend import sim


class Distance:
    def __init__(self, name_or_handle: Union[str, int]):
        if isinstance(name_or_handle, int):
            self._handle = name_or_handle
        else:
            self._handle = sim.simGetDistanceHandle(name_or_handle)
        # Computed now, so that the first read has a value.
        sim.simHandleDistance(self._handle)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Distance):
            raise NotImplementedError
        return self.get_handle() == other.get_handle()

    def get_handle(self) -> int:
        return self._handle

    def read(self):
        """The minimum distance (m), or None when it is beyond the object's
        threshold."""
        sim.simHandleDistance(self._handle)
        return sim.simReadDistance(self._handle)
