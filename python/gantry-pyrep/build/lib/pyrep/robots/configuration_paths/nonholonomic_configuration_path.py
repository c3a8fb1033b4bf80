"""`NonHolonomicConfigurationPath`: a differential-drive base's path."""

from __future__ import annotations

import math

from pyrep.robots.configuration_paths.mobile_configuration_path import MobileConfigurationPath


class NonHolonomicConfigurationPath(MobileConfigurationPath):
    def step(self) -> bool:
        """Sets the wheels' speeds for one step towards the next intermediate target
        (the caller steps the simulation); True at the end of the path."""
        if self._path_done:
            raise RuntimeError("This path has already been completed. If you want to re-run, then call set_to_start.")
        mobile = self._mobile
        to_inter = mobile.intermediate_target_base.get_position(relative_to=mobile)
        if len(self._path_points) > 2:
            if self.inter_done:
                self._next_i_path()
                self._set_inter_target(self.i_path)
                self.inter_done = False
            if math.hypot(to_inter[0], to_inter[1]) < 0.1:
                self.inter_done = True
            actuation, _ = mobile.get_base_actuation()
            mobile.set_joint_target_velocities(actuation)
            if self.i_path == len(self._path_points) - 1:
                self._path_done = True
        else:
            actuation, self._path_done = mobile.get_base_actuation()
            mobile.set_joint_target_velocities(actuation)
        return self._path_done
