"""`Camera`: a viewpoint of the scene (gantry's viewer uses it; nothing renders it
for Python)."""

from pyrep.const import ObjectType
from pyrep.objects.object import Object, object_type_to_class


class Camera(Object):
    @staticmethod
    def create() -> "Camera":
        raise NotImplementedError("API does not provide simCreateCamera.")

    def _get_requested_type(self) -> ObjectType:
        return ObjectType.CAMERA


object_type_to_class[ObjectType.CAMERA] = Camera
