"""`Octree`: voxels in space, filled from points or objects."""

from typing import List, Optional

from pyrep.backend import sim
from pyrep.const import ObjectType
from pyrep.objects.object import Object, object_type_to_class


def _check_points(points) -> None:
    if not isinstance(points, list):
        raise ValueError("Octree points must be a flat list of floats (x, y, z, x, y, z, ...).")
    if len(points) % 3 != 0:
        raise ValueError("Octree points must come in triples (x, y, z); got %d values." % len(points))


def _check_color(color) -> None:
    if color is not None and (not isinstance(color, list) or len(color) != 3):
        raise ValueError("An octree colour is a list of 3 floats (r, g, b).")


class Octree(Object):
    @staticmethod
    def create(voxel_size: float, point_size: Optional[float] = None, options: int = 0) -> "Octree":
        """An empty octree of cubes `voxel_size` metres wide."""
        return Octree(sim.simCreateOctree(voxel_size, options, voxel_size if point_size is None else point_size))

    def _get_requested_type(self) -> ObjectType:
        return ObjectType.OCTREE

    def insert_voxels(self, points: List[float], color: Optional[List[float]] = None, options: int = 0) -> None:
        _check_points(points)
        _check_color(color)
        sim.simInsertVoxelsIntoOctree(self._handle, options, points, color, None)

    def remove_voxels(self, points: Optional[List[float]], options: int = 0) -> None:
        """Removes the voxels at these points (None: all)."""
        if points is not None:
            _check_points(points)
        sim.simRemoveVoxelsFromOctree(self._handle, options, points)

    def get_voxels(self) -> list:
        """The voxels' centres, flat (x, y, z, ...)."""
        return sim.simGetOctreeVoxels(self._handle)

    def insert_object(self, obj: Object, color: Optional[List[float]] = None, options: int = 0) -> None:
        _check_color(color)
        sim.simInsertObjectIntoOctree(self._handle, obj.get_handle(), options, color, 0)

    def subtract_object(self, obj: Object, options: int = 0) -> None:
        sim.simSubtractObjectFromOctree(self._handle, obj.get_handle(), options)

    def check_point_occupancy(self, points: List[float], options: int = 0) -> bool:
        _check_points(points)
        return sim.simCheckOctreePointOccupancy(self._handle, options, points)

    def clear_voxels(self) -> None:
        sim.simRemoveVoxelsFromOctree(self._handle, 0, None)


object_type_to_class[ObjectType.OCTREE] = Octree
