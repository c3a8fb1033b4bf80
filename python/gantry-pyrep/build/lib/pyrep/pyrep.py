"""`PyRep`: launches a simulation, starts, steps and stops it.

On gantry the simulation runs in this process, in the thread that calls `launch`:
no CoppeliaSim, no UI thread, no X server. Several `PyRep` instances may run at once,
one per thread; each thread's objects talk to its own simulation.
"""

from __future__ import annotations

import logging
import os
import warnings
from typing import List, Optional, Tuple

import numpy as np

import gantry
from pyrep.backend import session, sim, utils
from pyrep.const import Verbosity
from pyrep.errors import PyRepError
from pyrep.objects.object import Object
from pyrep.objects.shape import Shape
from pyrep.textures.texture import Texture
import pyrep.objects  # noqa: F401  (registers every object class)

log = logging.getLogger("pyrep")


class PyRep:
    """The simulation: `launch`, then `start`, `step` and `stop`; `shutdown` ends it."""

    def __init__(self) -> None:
        self.running = False
        self._session: Optional[session.Session] = None
        # With `launch(headless=False)`: the address of gantry's browser viewer.
        self.viewer_address: Optional[str] = None

    def _launched(self) -> session.Session:
        if self._session is None:
            raise PyRepError("CoppeliaSim has not been launched. Call launch first.")
        return self._session

    def launch(self, scene_file: str = "", headless: bool = False, responsive_ui: bool = False,
               blocking: bool = False, verbosity: Verbosity = Verbosity.NONE) -> None:
        """Loads `scene_file` (`.ttt`, or gantry's `.toml`; empty: an empty scene)
        into a new simulation owned by the calling thread. `headless=False` opens
        gantry's browser viewer on a free local port (its address is logged) instead
        of a window; `responsive_ui` and `blocking` have no meaning without
        CoppeliaSim's UI and are ignored."""
        if self._session is not None:
            raise PyRepError("this PyRep is launched already; call shutdown() first, or make another PyRep")
        scene = None
        if scene_file:
            scene = os.path.abspath(scene_file)
            if not os.path.isfile(scene):
                raise PyRepError("Scene file does not exist: %s" % scene_file)
        viewer = {} if headless else {"http_port": 0}
        try:
            client = gantry.Client(scene, autostart=False, realtime=False, **viewer)
        except Exception as e:
            raise PyRepError(f"could not load {scene_file}: {e}") from e
        if not headless:
            log.warning("gantry's viewer for %s: %s", scene_file or "the empty scene", "http://" + client.addresses.get("http", "?"))
        self._session = session.Session(client)
        self.viewer_address = None if headless else "http://" + client.addresses.get("http", "")
        session.bind(self._session)
        self.step()

    def script_call(self, function_name_at_script_name: str, script_handle_or_type: int, ints=(), floats=(),
                    strings=(), bytes="") -> Tuple[List[int], List[float], List[str], str]:
        """Calls `function@scriptName` in a scene script (PyRep's four lists in and
        out)."""
        return utils.script_call(function_name_at_script_name, script_handle_or_type, ints, floats, strings, bytes)

    def shutdown(self) -> None:
        """Stops and closes the simulation."""
        s = self._launched()
        self.stop()
        if session.active() is s:
            session.bind(None)
        s.client.close()
        self._session = None

    def start(self) -> None:
        """Starts the simulation if it is not running."""
        self._launched()
        if not self.running:
            sim.simStartSimulation()
            self.running = True

    def stop(self) -> None:
        """Stops the simulation if it runs: the scene returns to its state at start,
        as in CoppeliaSim."""
        self._launched()
        if self.running:
            sim.simStopSimulation()
            self.running = False
            for _ in range(5):
                self.step()

    def step(self) -> None:
        """One simulation step if the simulation runs (otherwise nothing: there is no
        UI to refresh)."""
        self._launched()
        with utils.step_lock:
            sim.simExtStep(True)

    def step_ui(self) -> None:
        """Nothing to do on gantry (no UI); kept for PyRep's code."""
        self._launched()

    def set_simulation_timestep(self, dt: float) -> None:
        """The simulation's time step, seconds (default: the scene's, 0.05 in most)."""
        sim.simSetFloatParameter(sim.sim_floatparam_simulation_time_step, dt)
        if not np.allclose(self.get_simulation_timestep(), dt):
            warnings.warn("Could not change simulation timestep.")

    def get_simulation_timestep(self) -> float:
        return sim.simGetSimulationTimeStep()

    def set_configuration_tree(self, config_tree: bytes) -> None:
        """Restores poses and joint values saved by `Object.get_configuration_tree`
        (dynamic objects are reset first)."""
        sim.simSetConfigurationTree(config_tree)

    def group_objects(self, objects: List[Shape]) -> Shape:
        """Groups shapes into one compound shape."""
        return Shape(sim.simGroupShapes([o.get_handle() for o in objects]))

    def merge_objects(self, objects: List[Shape]) -> Shape:
        """Merges shapes into one mesh shape."""
        return Shape(sim.simGroupShapes([o.get_handle() for o in objects], merge=True))

    def export_scene(self, filename: str) -> None:
        """Saves the scene. gantry writes its TOML format (with the scripts and meshes
        beside it); a `.ttt` name is saved as TOML next to it, never as a CoppeliaSim
        file."""
        sim.simSaveScene(filename)

    def import_model(self, filename: str) -> Object:
        """Loads a model file (`.ttm`, `.urdf`, gantry's `.toml`) into the scene and
        returns its base object."""
        if not os.path.isfile(filename):
            raise PyRepError("Model file does not exist: %s" % filename)
        return utils.to_type(sim.simLoadModel(os.path.abspath(filename)))

    def create_texture(self, filename: str, interpolate: bool = True, decal_mode: bool = False,
                       repeat_along_u: bool = False, repeat_along_v: bool = False) -> Tuple[Shape, Texture]:
        """A plane textured with an image file, and its texture."""
        options = 0
        if not interpolate:
            options |= 1
        if decal_mode:
            options |= 2
        if repeat_along_u:
            options |= 4
        if repeat_along_v:
            options |= 8
        shape = Shape(sim.simCreateTexture(filename, options))
        return shape, shape.get_texture()

    def get_objects_in_tree(self, root_object=None, *args, **kwargs) -> List[Object]:
        """The objects of the scene (or below `root_object`)."""
        return Object._get_objects_in_tree(root_object, *args, **kwargs)

    def get_collection_handle_by_name(self, collection_name: str) -> int:
        return sim.simGetCollectionHandle(collection_name)
