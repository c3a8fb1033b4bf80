"""`CartesianPath`: CoppeliaSim 4.1's path object (control points with Bézier
interpolation), for `Arm.get_path_from_cartesian_path` and RLBench's waypoints."""

from typing import List, Sequence, Tuple

from pyrep.backend import sim
from pyrep.const import ObjectType
from pyrep.objects.object import Object, object_type_to_class


class CartesianPath(Object):
    @staticmethod
    def create(show_line: bool = True, show_orientation: bool = True, show_position: bool = True,
               closed_path: bool = False, automatic_orientation: bool = True, flat_path: bool = False,
               keep_x_up: bool = False, line_size: int = 1,
               length_calculation_method: int = sim.sim_distcalcmethod_dl_if_nonzero,
               control_point_size: float = 0.01, ang_to_lin_conv_coeff: float = 1.0,
               virt_dist_scale_factor: float = 1.0, path_color: Sequence[float] = (0.1, 0.75, 1.0)) -> "CartesianPath":
        """An empty path (the flags are CoppeliaSim's path properties)."""
        flags = [
            (show_line, sim.sim_pathproperty_show_line),
            (show_orientation, sim.sim_pathproperty_show_orientation),
            (closed_path, sim.sim_pathproperty_closed_path),
            (automatic_orientation, sim.sim_pathproperty_automatic_orientation),
            (flat_path, sim.sim_pathproperty_flat_path),
            (show_position, sim.sim_pathproperty_show_position),
            (keep_x_up, sim.sim_pathproperty_keep_x_up),
        ]
        attributes = 0
        for on, bit in flags:
            if on:
                attributes |= bit
        handle = sim.simCreatePath(
            attributes,
            [line_size, length_calculation_method, 0],
            [control_point_size, ang_to_lin_conv_coeff, virt_dist_scale_factor],
            list(path_color),
        )
        return CartesianPath(handle)

    def _get_requested_type(self) -> ObjectType:
        return ObjectType.PATH

    def get_pose_on_path(self, relative_distance: float) -> Tuple[List[float], List[float]]:
        """The world position (m) and Euler angles (rad) at a fraction 0..1 of the
        path's length."""
        pos = sim.simGetPositionOnPath(self._handle, relative_distance)
        ori = sim.simGetOrientationOnPath(self._handle, relative_distance)
        return pos, ori

    def insert_control_points(self, poses: List[List[float]]) -> None:
        """Inserts control points at the start of the path, each (x, y, z, alpha,
        beta, gamma) in the path's frame, with the defaults PyRep uses for the rest
        (no relative velocity or virtual distance, 20 Bézier points, factors 0.99)."""
        data: List[float] = []
        for pose in poses:
            if len(pose) != 6:
                raise ValueError(f"a control point is (x, y, z, alpha, beta, gamma), not {len(pose)} values")
            data.extend([*map(float, pose), 0.0, 0.0, 20, 0.99, 0.99])
        sim.simInsertPathCtrlPoints(self._handle, 0, 0, len(poses), data)


object_type_to_class[ObjectType.PATH] = CartesianPath
