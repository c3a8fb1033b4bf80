"""gantry in Python: the simulator in-process, with the same ``sim`` API as its Lua
scripts and its ZMQ remote API.

A program written for CoppeliaSim's ZMQ remote API ports by changing how the client
is made::

    # from coppeliasim_zmqremoteapi_client import RemoteAPIClient
    # client = RemoteAPIClient()
    import gantry
    client = gantry.Client("assets/scenes/bubble_rob.toml")
    sim = client.require("sim")
    client.setStepping(True)
    sim.startSimulation()
    ...

Every function of ``sim``, ``simIK``, ``simUI`` and ``simVision`` is the one
implementation that Lua scripts and ZMQ clients call too: the same arguments, the same
return shapes (one value as itself, several as a tuple, arrays as lists) and the same
errors (a plain ``Exception`` whose text ends ``(in function 'sim.name')``).

See docs/python.md for the Gymnasium environments (``gantry.gym``) and batch runs on
Ray (``gantry.batch``).
"""

from __future__ import annotations

import copy as _copy
import os as _os
import threading as _threading
from typing import TYPE_CHECKING, Any, Iterable, Literal, Optional, overload

from ._gantry import Engine as _Engine
from ._gantry import Function, __version__, log_to_stderr

if TYPE_CHECKING:
    # Generated from the registry (tests/api_doc.rs): what editors complete.
    from ._api import Sim, SimIK, SimUI, SimVision

__all__ = ["Client", "Function", "bundled_scenes", "log_to_stderr", "__version__"]


def bundled_scenes() -> list[str]:
    """The names of the scenes compiled into gantry."""
    return list(_Engine.bundled_scenes())


class _Module:
    """One namespace of the API (``sim``, ``simIK``, ...): its functions and constants
    as attributes, as the remote client's ``require`` gives them."""

    def __init__(self, name: str, members: dict[str, Any]):
        self.__dict__.update(members)
        self.__name__ = name

    def __repr__(self) -> str:
        return f"<gantry module {self.__name__}>"


class Client:
    """A simulation in this process, and the client that drives it.

    ``scene`` is a gantry scene (``.toml``), a robot (``.urdf``), or the name of a
    scene compiled into gantry (``bundled_scenes()``: ``"showroom"``, ``"bubble_rob"``,
    ``"fk_arm"``); ``None`` starts with an empty scene, to be filled with
    ``sim.loadScene(path)`` as CoppeliaSim's examples do. As ``gantry run`` does, the
    simulation starts at once (``autostart``). ``scripts=False`` leaves the scene's
    Lua scripts out, so that the Python program is the only controller.

    Without ``sim.setStepping(True)`` the simulation runs free in real time: each call
    first takes the steps the wall clock says are due. With ``realtime=False`` it only
    advances on ``sim.step()`` (or ``advance(n)``), as PyBullet and MuJoCo do.

    ``http_port``, ``zmq_port`` or ``text_port`` (0 = any free port) move the
    simulation to gantry's simulation thread with those listeners open, so that the
    run can be watched in the browser viewer or joined by other clients; calls then
    cost a thread hop (tens of microseconds) instead of a function call. There, as with
    ``gantry run``, the simulation runs on its own between calls: in real time, or as
    fast as it can with ``realtime=False`` (``--fast``); hold it with stepping.
    Listeners bind 127.0.0.1 unless ``bind`` says otherwise; ``token`` requires an
    access token on the text channel and the viewer, as ``gantry run --token`` does.

    ``record="run.mcap"`` records the run as ``gantry run --record`` does (poses, joint
    states, graphs, log lines, the scene's files and every call this client makes, at
    most ``record_rate`` snapshots per simulated second); the file is complete once the
    client is closed, and ``gantry verify run.mcap`` re-runs it (docs/recording.md).

    ``ros2=True`` joins the ROS 2 graph as ``gantry run --ros2`` does: ``/clock``,
    ``/tf``, ``/tf_static``, ``/joint_states``, camera topics and joint command topics,
    in the domain of ``ROS_DOMAIN_ID``, on this host unless
    ``ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET`` (docs/ros2.md). Scripts' ``simROS2`` works
    without it.

    ``seed`` overrides the scene's random seed (the scripts' ``math.random`` and
    ``sim.floatparam_rand``; default the scene's, else 0): one seed, one sequence.

    The client belongs to the thread that made it. Several clients in several threads
    are independent simulations that step in parallel (steps release the GIL).
    """

    def __init__(
        self,
        scene: Optional[str | _os.PathLike] = None,
        *,
        dt: Optional[float] = None,
        substeps: Optional[int] = None,
        autostart: bool = True,
        realtime: bool = True,
        package_paths: Iterable[str | _os.PathLike] = (),
        free_base: bool = False,
        scripts: bool = True,
        bind: Optional[str] = None,
        http_port: Optional[int] = None,
        zmq_port: Optional[int] = None,
        text_port: Optional[int] = None,
        token: Optional[str] = None,
        record: Optional[str | _os.PathLike] = None,
        record_rate: Optional[float] = None,
        seed: Optional[int] = None,
        ros2: bool = False,
    ):
        self._engine = _Engine(
            None if scene is None else _os.fspath(scene),
            dt=dt,
            substeps=substeps,
            autostart=autostart,
            realtime=realtime,
            package_paths=[_os.fspath(p) for p in package_paths],
            free_base=free_base,
            scripts=scripts,
            bind=bind,
            http_port=http_port,
            zmq_port=zmq_port,
            text_port=text_port,
            token=token,
            record=None if record is None else _os.fspath(record),
            record_rate=record_rate,
            seed=seed,
            ros2=ros2,
        )
        self._required: dict[str, _Module] = {}
        self._owner = _threading.get_ident()

    @property
    def _engine_here(self) -> _Engine:
        """The engine, from the thread that owns it (otherwise a clear error rather
        than the extension's panic)."""
        if _threading.get_ident() != self._owner:
            raise RuntimeError("a gantry client belongs to the thread that created it; make one client per thread")
        return self._engine

    # --- what RemoteAPIClient offers -------------------------------------------------

    @overload
    def require(self, name: Literal["sim"]) -> "Sim": ...
    @overload
    def require(self, name: Literal["simIK"]) -> "SimIK": ...
    @overload
    def require(self, name: Literal["simUI"]) -> "SimUI": ...
    @overload
    def require(self, name: Literal["simVision"]) -> "SimVision": ...
    @overload
    def require(self, name: str) -> Any: ...

    def require(self, name: str) -> Any:
        """The module ``name`` (``sim``, ``simIK``, ``simUI``, ``simVision``)."""
        module = self._required.get(name)
        if module is None:
            members: dict[str, Any] = dict(self._engine_here.functions(name))
            for constant, value in _Engine.constants(name):
                # ``simOMPL.StateSpaceType.pose3d``: a dotted name is a member of a
                # nested namespace, as the remote client builds it.
                group, dot, member = constant.partition(".")
                if dot:
                    members.setdefault(group, _Module(f"{name}.{group}", {})).__dict__[member] = value
                else:
                    members[constant] = value
            if name == "sim":
                # Helpers the remote client adds on its own side. Bound to the engine,
                # not to this client: a module referring back to the client would make
                # a cycle, freed by the garbage collector in whatever thread it runs,
                # while the simulation must end in its own thread.
                members["getScriptFunctions"] = _script_functions(self)
                members["copyTable"] = _copy.deepcopy
            module = _Module(name, members)
            self._required[name] = module
        return module

    def call(self, func: str, args: Iterable[Any] = ()) -> Any:
        """Calls a function by its qualified name (``"sim.getObject"``)."""
        return self._engine_here.call(func, list(args))

    def setStepping(self, enable: bool = True) -> int:
        """``sim.setStepping(enable)``: returns the previous stepping level."""
        return self.call("sim.setStepping", [enable])

    def step(self, *, wait: bool = True) -> None:
        """``sim.step()``: one step (with stepping), or the next due step."""
        self.call("sim.step", [wait])

    def getScriptFunctions(self, scriptHandle: int) -> Any:
        """An object whose attributes call the script's functions
        (``sim.callScriptFunction``)."""
        return _script_functions(self)(scriptHandle)

    # --- extras ----------------------------------------------------------------------

    def advance(self, steps: int = 1) -> int:
        """Takes ``steps`` steps as fast as possible (starting a stopped simulation),
        whatever the stepping mode; returns the steps taken. In-process only."""
        return self._engine_here.advance(steps)

    def image(self, sensor: int, options: int = 0, rgba_cutoff: float = 0.0, top_first: bool = True):
        """A vision sensor's image as a ``(height, width, channels)`` ``uint8`` numpy
        array, without copying the pixels. Row 0 is the top unless ``top_first`` is
        false (CoppeliaSim's order, bottom row first)."""
        return self._engine_here.image(sensor, options, rgba_cutoff, top_first)

    def depth(self, sensor: int, metres: bool = False, top_first: bool = True):
        """A vision sensor's depth map as a ``(height, width)`` ``float32`` numpy
        array: 0..1 between the clipping planes, or metres."""
        return self._engine_here.depth(sensor, metres, top_first)

    def mask(self, sensor: int, top_first: bool = True):
        """A vision sensor's segmentation mask as a ``(height, width)`` ``int32`` numpy
        array: the handle of the shape seen at each pixel, -1 where nothing is. It
        comes from the same render as ``image`` and ``depth`` (the first call may render
        the sensor again, with its mask)."""
        return self._engine_here.mask(sensor, top_first)

    @property
    def addresses(self) -> dict[str, str]:
        """The listeners of a served simulation (``{"http": "127.0.0.1:8080"}``)."""
        return self._engine_here.addresses()

    @property
    def in_process(self) -> bool:
        """Whether the simulation runs in this thread (no listeners)."""
        return self._engine_here.in_process()

    def close(self) -> None:
        """Ends the simulation (cleanup hooks run; listeners close)."""
        self._engine_here.close()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def _script_functions(client: Client):
    """``getScriptFunctions(scriptHandle)`` over ``client``'s engine. It holds the engine,
    not the client: the ``sim`` module that keeps this function belongs to the client,
    and a reference back would make a cycle, freed by the garbage collector in whatever
    thread it runs, while a simulation must end in its own."""
    engine, owner = client._engine, client._owner

    def get(scriptHandle: int) -> Any:
        class _ScriptFunctions:
            def __getattr__(self, func: str):
                def call(*args):
                    if _threading.get_ident() != owner:
                        raise RuntimeError(
                            "a gantry client belongs to the thread that created it; make one client per thread"
                        )
                    return engine.call("sim.callScriptFunction", [func, scriptHandle, *args])

                return call

        return _ScriptFunctions()

    return get
