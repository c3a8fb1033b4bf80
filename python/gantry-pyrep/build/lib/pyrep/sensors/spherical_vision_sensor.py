"""`SphericalVisionSensor`: a 360 x 180 degree camera made of six 90-degree vision
sensors on the faces of a cube.

The model `name` holds the six sensors `name_front`, `name_top`, `name_back`,
`name_bottom`, `name_left`, `name_right` and two output sensors `name_sensorRGB` and
`name_sensorDepth` whose resolution (width = 2 x height) is the panorama's. The
panorama is equirectangular: the centre column looks where `front` looks, the top row
where `top` looks, longitude grows to the right (towards `right`), latitude upwards.
Each of its pixels takes the face pixel its ray passes through (nearest pixel). Depth
is measured along the ray (radial), not along a face's axis.

CoppeliaSim assembles the panorama in its vision plugin (`simVision.handleSpherical`,
called by PyRep's add-on); here it is assembled in numpy from the six sensors'
images, with the six sensors' poses as the scene gives them.
"""

from __future__ import annotations

from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from pyrep.backend import sim
from pyrep.const import ObjectType, RenderMode
from pyrep.objects.object import Object
from pyrep.objects.vision_sensor import VisionSensor

_FACES = ["front", "top", "back", "bottom", "left", "right"]


class SphericalVisionSensor(Object):
    def __init__(self, name):
        super().__init__(name)
        base = self.get_name()
        self._sensor_depth = VisionSensor("%s_sensorDepth" % base)
        self._sensor_rgb = VisionSensor("%s_sensorRGB" % base)
        self._six_sensors = [VisionSensor("%s_%s" % (base, face)) for face in _FACES]
        self._front = self._six_sensors[0]
        self._six_sensor_handles = [s.get_handle() for s in self._six_sensors]
        for sensor in [self._sensor_depth, self._sensor_rgb] + self._six_sensors:
            sensor.set_explicit_handling(1)
        self._check_faces_match()
        self._near_clipping_plane = self.get_near_clipping_plane()
        self._far_clipping_plane = self.get_far_clipping_plane()
        self._clipping_plane_diff = self._far_clipping_plane - self._near_clipping_plane
        self._lookup_key: Optional[Tuple] = None
        self._lookup: Dict[str, np.ndarray] = {}

    def _get_requested_type(self) -> ObjectType:
        return ObjectType(sim.simGetObjectType(self.get_handle()))

    def _check_faces_match(self) -> None:
        """The six faces must be alike (one resolution, square; one clipping
        range), as the panorama assumes."""
        def same(values, what):
            if any(v != values[0] for v in values[1:]):
                raise ValueError(f"spherical vision sensor '{self.get_name()}': its six sensors differ in {what} "
                                 f"({values})")
        same([s.get_resolution() for s in self._six_sensors], "resolution")
        same([s.get_near_clipping_plane() for s in self._six_sensors], "near clipping plane")
        same([s.get_far_clipping_plane() for s in self._six_sensors], "far clipping plane")
        same([self._sensor_rgb.get_resolution(), self._sensor_depth.get_resolution()], "output resolution")

    # --- assembling the panorama ------------------------------------------------------

    def _ray_lookup(self, out_res: Sequence[int], face_res: Sequence[int]) -> Dict[str, np.ndarray]:
        """For each panorama pixel: the face it sees, the face pixel, and the ratio
        of ray length to face depth. Cached while resolutions and poses stay."""
        frames = [s.get_matrix(self)[:3, :3] for s in self._six_sensors]
        key = (tuple(out_res), tuple(face_res), tuple(np.round(np.concatenate([f.ravel() for f in frames]), 6)))
        if key == self._lookup_key:
            return self._lookup
        width, height = int(out_res[0]), int(out_res[1])
        face_w, face_h = int(face_res[0]), int(face_res[1])
        forward = frames[0][:, 2]
        up = frames[1][:, 2]
        right = np.cross(forward, up)
        lon = ((np.arange(width) + 0.5) / width - 0.5) * 2 * np.pi
        lat = (0.5 - (np.arange(height) + 0.5) / height) * np.pi
        lon, lat = np.meshgrid(lon, lat)
        rays = (np.cos(lat)[..., None] * (np.cos(lon)[..., None] * forward + np.sin(lon)[..., None] * right)
                + np.sin(lat)[..., None] * up)
        # Each ray goes to the face whose axis it is closest to.
        along = np.stack([rays @ f[:, 2] for f in frames])
        face = np.argmax(along, axis=0)
        dz = np.take_along_axis(along, face[None], axis=0)[0]
        axes = np.stack(frames)[face]
        dx = np.einsum("hwi,hwi->hw", rays, axes[..., :, 0])
        dy = np.einsum("hwi,hwi->hw", rays, axes[..., :, 1])
        # Image right is the sensor's -x, image down its -y (90-degree faces).
        col = np.clip(np.floor((1.0 - dx / dz) / 2.0 * face_w), 0, face_w - 1).astype(np.intp)
        row = np.clip(np.floor((1.0 - dy / dz) / 2.0 * face_h), 0, face_h - 1).astype(np.intp)
        self._lookup_key = key
        self._lookup = {"face": face, "row": row, "col": col, "ray_per_depth": 1.0 / dz}
        return self._lookup

    def _panorama(self, images: List[np.ndarray]) -> Tuple[np.ndarray, Dict[str, np.ndarray]]:
        """The panorama of the six face images (and the lookup that made it); the
        faces are read at the size their images have (a new resolution applies
        once they have rendered again)."""
        face_h, face_w = images[0].shape[:2]
        lookup = self._ray_lookup(self.get_resolution(), [face_w, face_h])
        stack = np.stack(images)
        return stack[lookup["face"], lookup["row"], lookup["col"]], lookup

    def _face_images(self, depth: bool) -> List[np.ndarray]:
        images = [s.capture_depth(in_meters=True) if depth else s.capture_rgb() for s in self._six_sensors]
        if len({img.shape[:2] for img in images}) != 1:
            # Some faces have rendered since a resolution change and some not.
            self.handle_explicitly()
            images = [s.capture_depth(in_meters=True) if depth else s.capture_rgb() for s in self._six_sensors]
        return images

    # --- public -----------------------------------------------------------------------

    def handle_explicitly(self) -> None:
        """Renders the six sensors now (the panorama is what they saw)."""
        for handle in self._six_sensor_handles:
            sim.simHandleVisionSensor(handle)

    def capture_rgb(self) -> np.ndarray:
        """The panorama as float RGB in [0, 1], shape (height, width, 3), from the
        six sensors' last images."""
        panorama, _ = self._panorama(self._face_images(depth=False))
        return panorama.astype(np.float32)

    def capture_depth(self, in_meters: bool = False) -> np.ndarray:
        """The panorama's depth along each ray, shape (height, width): metres, or
        normalised between the near and far clipping planes (it exceeds 1 towards
        the faces' corners, as the ray is longer than the face's depth)."""
        planar, lookup = self._panorama(self._face_images(depth=True))
        radial = planar * lookup["ray_per_depth"]
        if in_meters:
            return radial.astype(np.float32)
        return ((radial - self._near_clipping_plane) / self._clipping_plane_diff).astype(np.float32)

    def get_resolution(self) -> List[int]:
        return self._sensor_depth.get_resolution()

    def set_resolution(self, resolution: List[int]) -> None:
        """[width, height] of the panorama: width twice the height, height even (each
        face gets height/2 squared)."""
        if len(resolution) != 2 or resolution[0] != 2 * resolution[1]:
            raise ValueError("Spherical vision sensors must have an X resolution 2x the Y resolution")
        if resolution[1] % 2 != 0:
            raise ValueError("Spherical vision sensors must have an even Y resolution")
        face = [resolution[1] // 2, resolution[1] // 2]
        for sensor in self._six_sensors:
            sensor.set_resolution(face)
        self._sensor_depth.set_resolution(list(resolution))
        self._sensor_rgb.set_resolution(list(resolution))

    def get_render_mode(self) -> RenderMode:
        return self._sensor_depth.get_render_mode()

    def set_render_mode(self, render_mode: RenderMode) -> None:
        for sensor in [self._sensor_depth, self._sensor_rgb] + self._six_sensors:
            sensor.set_render_mode(render_mode)

    def get_windowed_size(self) -> Sequence[int]:
        return self._sensor_depth.get_windowed_size()

    def set_windowed_size(self, resolution: Sequence[int] = (0, 0)) -> None:
        self._sensor_depth.set_windowed_size(resolution)
        self._sensor_rgb.set_windowed_size(resolution)

    def get_near_clipping_plane(self) -> float:
        """Metres (the six sensors')."""
        return self._front.get_near_clipping_plane()

    def set_near_clipping_plane(self, near_clipping: float) -> None:
        self._near_clipping_plane = near_clipping
        self._clipping_plane_diff = self._far_clipping_plane - near_clipping
        for sensor in self._six_sensors:
            sensor.set_near_clipping_plane(near_clipping)

    def get_far_clipping_plane(self) -> float:
        """Metres (the six sensors')."""
        return self._front.get_far_clipping_plane()

    def set_far_clipping_plane(self, far_clipping: float) -> None:
        self._far_clipping_plane = far_clipping
        self._clipping_plane_diff = far_clipping - self._near_clipping_plane
        for sensor in self._six_sensors:
            sensor.set_far_clipping_plane(far_clipping)

    def set_entity_to_render(self, entity_to_render: int) -> None:
        """The object or collection the panorama shows (-1: everything)."""
        for sensor in [self._sensor_depth, self._sensor_rgb] + self._six_sensors:
            sensor.set_entity_to_render(entity_to_render)

    def get_entity_to_render(self) -> int:
        return self._sensor_depth.get_entity_to_render()
