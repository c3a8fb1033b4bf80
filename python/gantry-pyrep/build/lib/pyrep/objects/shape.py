"""`Shape`: geometry with mass, colour, texture and contacts."""

from __future__ import annotations

import collections
import os
from typing import List, Optional, Sequence, Tuple

import numpy as np

from pyrep.backend import sim
from pyrep.const import ObjectType, PrimitiveShape, TextureMappingMode
from pyrep.objects.object import Object, object_type_to_class
from pyrep.textures.texture import Texture

SShapeVizInfo = collections.namedtuple(
    "SShapeVizInfo",
    ["vertices", "indices", "normals", "shading_angle", "colors", "texture", "texture_id",
     "texture_coords", "texture_apply_mode", "texture_options"],
)


def _bits(*flags: Tuple[bool, int]) -> int:
    out = 0
    for on, bit in flags:
        if on:
            out |= bit
    return out


class Shape(Object):
    """A shape: a primitive, a mesh or a group of them."""

    def _get_requested_type(self) -> ObjectType:
        return ObjectType.SHAPE

    # --- making shapes ------------------------------------------------------------

    @staticmethod
    def create(type: PrimitiveShape, size: List[float], mass: float = 1.0, backface_culling: bool = False,
               visible_edges: bool = False, smooth: bool = False, respondable: bool = True, static: bool = False,
               renderable: bool = True, position=None, orientation=None, color=None) -> "Shape":
        """A primitive (`size`: x, y, z extents in metres; `mass` in kg)."""
        options = _bits((backface_culling, 1), (visible_edges, 2), (smooth, 4), (respondable, 8), (static, 16))
        shape = Shape(sim.simCreatePureShape(type.value, options, list(size), mass, None))
        shape.set_renderable(renderable)
        if position is not None:
            shape.set_position(position)
        if orientation is not None:
            shape.set_orientation(orientation)
        if color is not None:
            shape.set_color(color)
        return shape

    @classmethod
    def import_shape(cls, filename: str, scaling_factor: float = 1.0, keep_identical_vertices: bool = False,
                     ignore_color: bool = False, ignore_texture: bool = False, reorient_bounding_box: bool = False,
                     ignore_up_vector: bool = False) -> "Shape":
        """A shape from a mesh file (OBJ, STL)."""
        if not os.path.isfile(filename):
            raise ValueError("Filename does not exist: " + filename)
        options = _bits((keep_identical_vertices, 1), (ignore_color, 8), (not ignore_texture, 16),
                        (reorient_bounding_box, 32), (ignore_up_vector, 128))
        return cls(sim.simImportShape(0, filename, options, 0, scaling_factor))

    @staticmethod
    def import_mesh(filename: str, scaling_factor: float = 1.0, keep_identical_vertices: bool = False,
                    ignore_up_vector: bool = False) -> "Shape":
        """A shape from every mesh of a file (several meshes are grouped)."""
        if not os.path.isfile(filename):
            raise ValueError("Filename does not exist: " + filename)
        options = _bits((keep_identical_vertices, 1), (ignore_up_vector, 128))
        vertices, indices, _names = sim.simImportMesh(0, filename, options, 0, scaling_factor)
        meshes = [Shape.create_mesh(v, i) for v, i in zip(vertices, indices)]
        if not meshes:
            raise ValueError(f"{filename} holds no mesh")
        if len(meshes) == 1:
            return meshes[0]
        return Shape(sim.simGroupShapes([m.get_handle() for m in meshes]))

    @staticmethod
    def create_mesh(vertices: Sequence[float], indices: Sequence[int], shading_angle: Optional[float] = None,
                    backface_culling: bool = False, visible_edges: bool = False) -> "Shape":
        """A mesh shape from flat vertex coordinates (metres) and triangle indices."""
        options = _bits((backface_culling, 1), (visible_edges, 2))
        angle = np.radians(20.0) if shading_angle is None else shading_angle
        return Shape(sim.simCreateMeshShape(options, angle, vertices, indices))

    # --- dynamics -----------------------------------------------------------------

    def is_respondable(self) -> bool:
        return bool(sim.simGetObjectInt32Parameter(self._handle, sim.sim_shapeintparam_respondable))

    def set_respondable(self, value: bool) -> None:
        sim.simSetObjectInt32Parameter(self._handle, sim.sim_shapeintparam_respondable, int(value))
        self.reset_dynamic_object()

    def is_dynamic(self) -> bool:
        return not sim.simGetObjectInt32Parameter(self._handle, sim.sim_shapeintparam_static)

    def set_dynamic(self, value: bool) -> None:
        sim.simSetObjectInt32Parameter(self._handle, sim.sim_shapeintparam_static, int(not value))
        self.reset_dynamic_object()

    def get_mass(self) -> float:
        return sim.simGetObjectFloatParameter(self._handle, sim.sim_shapefloatparam_mass)

    def set_mass(self, mass: float) -> None:
        sim.simSetObjectFloatParameter(self._handle, sim.sim_shapefloatparam_mass, mass)

    def compute_mass_and_inertia(self, density: float) -> None:
        """Mass and inertia from the shape's geometry and a density (kg/m³)."""
        if sim.simComputeMassAndInertia(self._handle, density) == 0:
            raise ValueError("The shape must be a convex shape (or convex compound shape)")

    def add_force(self, position, force, reset_force_torque: bool = False) -> None:
        """A force (N, world frame) at `position` (shape frame), cumulative until the
        next step."""
        h = self._handle | sim.sim_handleflag_resetforcetorque if reset_force_torque else self._handle
        sim.simAddForce(h, list(position), list(force))

    def add_force_and_torque(self, force, torque, reset_force: bool = False, reset_torque: bool = False) -> None:
        """A force (N) and torque (N·m) at the centre of mass, world frame."""
        h = self._handle
        if reset_force:
            h |= sim.sim_handleflag_resetforce
        if reset_torque:
            h |= sim.sim_handleflag_resettorque
        sim.simAddForceAndTorque(h, None if force is None else list(force), None if torque is None else list(torque))

    # --- looks --------------------------------------------------------------------

    def get_color(self) -> List[float]:
        return sim.simGetShapeColor(self._handle, None, sim.sim_colorcomponent_ambient_diffuse)

    def set_color(self, color: Sequence[float]) -> None:
        sim.simSetShapeColor(self._handle, None, sim.sim_colorcomponent_ambient_diffuse, list(color))

    def get_transparency(self) -> float:
        return sim.simGetShapeColor(self._handle, None, sim.sim_colorcomponent_transparency)[0]

    def set_transparency(self, value: float) -> None:
        if not 0.0 <= value <= 1.0:
            raise ValueError("Value must be between 0 and 1.")
        sim.simSetShapeColor(self._handle, None, sim.sim_colorcomponent_transparency, [value])

    def get_texture(self) -> Texture:
        return Texture(sim.simGetShapeTextureId(self._handle))

    def remove_texture(self) -> None:
        sim.simSetShapeTexture(self._handle, -1, 0, 0, [1.0, 1.0], None, None)

    def set_texture(self, texture: Texture, mapping_mode: TextureMappingMode, interpolate: bool = True,
                    decal_mode: bool = False, repeat_along_u: bool = False, repeat_along_v: bool = False,
                    uv_scaling=(1.0, 1.0), position=None, orientation=None) -> None:
        options = _bits((not interpolate, 1), (decal_mode, 2), (repeat_along_u, 4), (repeat_along_v, 8))
        sim.simSetShapeTexture(self._handle, texture.get_texture_id(), mapping_mode.value, options,
                               list(uv_scaling), position, orientation)

    def apply_texture(self, texture_coords: np.ndarray, texture: np.ndarray, interpolate: bool = True,
                      decal_mode: bool = False, is_rgba: bool = False, fliph: bool = False,
                      flipv: bool = False) -> None:
        """Textures the shape with an image (height x width x 3 or 4, uint8) and one
        UV pair per triangle corner."""
        coords = np.asarray(texture_coords)
        if not isinstance(texture, np.ndarray):
            raise TypeError("texture must be np.ndarray type")
        height, width = texture.shape[:2]
        options = _bits((not interpolate, 1), (decal_mode, 2), (is_rgba, 16), (fliph, 32), (flipv, 64))
        sim.simApplyTexture(self._handle, coords.ravel().tolist(), coords.size, texture, (width, height), options)

    # --- mesh ---------------------------------------------------------------------

    def get_mesh_data(self) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Vertices (n x 3, shape frame), triangles (m x 3) and normals (3m x 3)."""
        vertices, indices, normals = sim.simGetShapeMesh(self._handle)
        return (np.array(vertices, dtype=np.float64).reshape(-1, 3),
                np.array(indices, dtype=np.int64).reshape(-1, 3),
                np.array(normals, dtype=np.float64).reshape(-1, 3))

    def decimate_mesh(self, percentage: float) -> "Shape":
        """A new shape with about `percentage` (0.1 to 0.9) of the triangles."""
        if not 0.1 <= percentage <= 0.9:
            raise ValueError("percentage param must be between 0.1 and 0.9.")
        vertices, indices, _ = sim.simGetShapeMesh(self._handle)
        new_vertices, new_indices = sim.simGetDecimatedMesh(vertices, indices, percentage)
        shape = Shape.create_mesh(new_vertices, new_indices)
        shape.set_matrix(self.get_matrix())
        return shape

    def get_convex_decomposition(self, morph: bool = False, same: bool = False, use_vhacd: bool = False,
                                 individual_meshes: bool = False, hacd_extra_points: bool = True,
                                 hacd_face_points: bool = True, hacd_min_clusters: int = 1,
                                 hacd_tri_target: int = 500, hacd_max_vertex: int = 200, hacd_max_iter: int = 4,
                                 hacd_max_concavity: float = 100, hacd_max_dist: float = 30,
                                 hacd_cluster_thresh: float = 0.25, vhacd_pca: bool = False,
                                 vhacd_tetrahedron: bool = False, vhacd_res: int = 100000, vhacd_depth: int = 20,
                                 vhacd_plane_downsample: int = 4, vhacd_hull_downsample: int = 4,
                                 vhacd_max_vertex: int = 64, vhacd_concavity: float = 0.0025,
                                 vhacd_alpha: float = 0.05, vhacd_beta: float = 0.05, vhacd_gamma: float = 0.00125,
                                 vhacd_min_vol: float = 0.0001) -> "Shape":
        """The shape as a group of convex parts (CoppeliaSim's option bits and
        parameter lists)."""
        options = _bits((morph, 1), (same, 4), (hacd_extra_points, 8), (hacd_face_points, 16),
                        (individual_meshes, 32), (use_vhacd, 128), (vhacd_pca, 256), (vhacd_tetrahedron, 512))
        ints = [hacd_min_clusters, hacd_tri_target, hacd_max_vertex, hacd_max_iter, 0, vhacd_res, vhacd_depth,
                vhacd_plane_downsample, vhacd_hull_downsample, vhacd_max_vertex]
        floats = [hacd_max_concavity, hacd_max_dist, hacd_cluster_thresh, 0.0, 0.0, vhacd_concavity, vhacd_alpha,
                  vhacd_beta, vhacd_gamma, vhacd_min_vol]
        return Shape(sim.simConvexDecompose(self._handle, options, ints, floats))

    def get_shape_viz(self, index: int) -> SShapeVizInfo:
        """The visual of element `index` of the shape (a group has several)."""
        info = sim.simGetShapeViz(self._handle, index)
        res = list(info.textureRes or [0, 0])
        texture = np.frombuffer(bytes(info.texture or b""), dtype=np.uint8)
        if res[0] * res[1] > 0:
            texture = texture.reshape(res[1], res[0], 4)
        return SShapeVizInfo(
            vertices=np.array(info.vertices, dtype=float).reshape(-1, 3),
            indices=np.array(info.indices, dtype=float).reshape(-1, 3),
            normals=np.array(info.normals, dtype=float).reshape(-1, 3),
            shading_angle=info.shadingAngle,
            colors=np.array(info.colors, dtype=float),
            texture=texture,
            texture_id=info.textureId,
            texture_coords=np.array(info.textureCoords, dtype=float).reshape(-1, 2),
            texture_apply_mode=info.textureApplyMode,
            texture_options=info.textureOptions,
        )

    def reorient_bounding_box(self, relative_to: Optional[Object] = None) -> None:
        sim.simReorientShapeBoundingBox(self._handle, -1 if relative_to is None else relative_to.get_handle())

    def ungroup(self) -> List["Shape"]:
        return [Shape(h) for h in sim.simUngroupShape(self._handle)]


object_type_to_class[ObjectType.SHAPE] = Shape
