"""`Light`: on/off, diffuse and specular colours, and intensity properties."""

import warnings
from typing import Optional

import numpy as np

from pyrep.backend import sim
from pyrep.const import ObjectType
from pyrep.objects.object import Object, object_type_to_class


class Light(Object):
    def _get_requested_type(self) -> ObjectType:
        return ObjectType.LIGHT

    def _parameters(self):
        state, diffuse, specular = sim.simGetLightParameters(self._handle)
        return state, diffuse, specular

    def turn_on(self) -> None:
        sim.simSetLightParameters(self._handle, True)

    def turn_off(self) -> None:
        sim.simSetLightParameters(self._handle, False)

    def is_on(self) -> bool:
        return bool(self._parameters()[0])

    def is_off(self) -> bool:
        return not self.is_on()

    def get_diffuse(self) -> np.ndarray:
        return np.asarray(self._parameters()[1])

    def set_diffuse(self, diffuse) -> None:
        sim.simSetLightParameters(self._handle, self.is_on(), list(diffuse), None)

    def get_specular(self) -> np.ndarray:
        return np.asarray(self._parameters()[2])

    def set_specular(self, specular) -> None:
        sim.simSetLightParameters(self._handle, self.is_on(), None, list(specular))

    def get_intensity_properties(self):
        """(cast_shadows, spot_exponent, spot_cutoff (rad), constant, linear and
        quadratic attenuation factors)."""
        h = self._handle
        return (
            bool(sim.simGetObjectInt32Parameter(h, sim.sim_lightintparam_pov_casts_shadows)),
            sim.simGetObjectFloatParameter(h, sim.sim_lightfloatparam_spot_exponent),
            sim.simGetObjectFloatParameter(h, sim.sim_lightfloatparam_spot_cutoff),
            sim.simGetObjectFloatParameter(h, sim.sim_lightfloatparam_const_attenuation),
            sim.simGetObjectFloatParameter(h, sim.sim_lightfloatparam_lin_attenuation),
            sim.simGetObjectFloatParameter(h, sim.sim_lightfloatparam_quad_attenuation),
        )

    def set_intensity_properties(self, cast_shadows: Optional[bool] = None, spot_exponent=None, spot_cutoff=None,
                                 const_atten_factor=None, linear_atten_factor=None, quad_atten_factor=None) -> None:
        """Sets the given properties. The spot exponent is a whole number (others are
        rounded, with a warning); the cutoff at most pi/2 (larger values are held
        there, with a warning). Attenuation factors cannot be set (as in CoppeliaSim
        4.1)."""
        h = self._handle
        if cast_shadows is not None:
            sim.simSetObjectInt32Parameter(h, sim.sim_lightintparam_pov_casts_shadows, int(cast_shadows))
        if spot_exponent is not None:
            if spot_exponent % 1 != 0:
                warnings.warn(f"the spot exponent is a whole number: {spot_exponent} is rounded to {round(spot_exponent)}")
            sim.simSetObjectFloatParameter(h, sim.sim_lightfloatparam_spot_exponent, float(round(spot_exponent)))
        if spot_cutoff is not None:
            cutoff = float(spot_cutoff)
            # The simulator holds the cutoff at pi/2 at most (in single precision, as
            # CoppeliaSim stores it, so a value read back from a light sets again).
            if cutoff > float(np.float32(np.pi / 2)):
                warnings.warn(f"the spot cutoff is at most pi/2: {cutoff} is set to pi/2")
            sim.simSetObjectFloatParameter(h, sim.sim_lightfloatparam_spot_cutoff, cutoff)
        if any(f is not None for f in (const_atten_factor, linear_atten_factor, quad_atten_factor)):
            raise Exception("CoppeliaSim currently does not support setting attenuation factors")


object_type_to_class[ObjectType.LIGHT] = Light
