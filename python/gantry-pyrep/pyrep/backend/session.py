"""Which gantry simulation the `pyrep` API talks to, per thread.

PyRep's objects find their simulator through a module (`pyrep.backend.sim`), not
through the `PyRep` instance: `Shape('cube')` names no instance. CoppeliaSim allows one
simulator per process; gantry allows one per thread, so the simulation a call reaches
is the one the calling thread launched (`PyRep.launch`), and several `PyRep` instances
run side by side in several threads.
"""

from __future__ import annotations

import threading
from typing import Any, Optional

from pyrep.errors import CallError, PyRepError

_local = threading.local()


class Session:
    """One launched simulation: the gantry client and its `sim` module."""

    def __init__(self, client: Any):
        self.client = client
        self.sim = client.require("sim")
        self.running = False


def current() -> Session:
    """The session of the calling thread; an error naming the fix if there is none."""
    session: Optional[Session] = getattr(_local, "session", None)
    if session is None:
        raise PyRepError(
            "no simulation is launched in this thread: call PyRep().launch(scene) first "
            "(gantry runs one simulation per thread)"
        )
    return session


def bind(session: Optional[Session]) -> None:
    """Makes `session` the calling thread's (None: the thread has none)."""
    _local.session = session


def active() -> Optional[Session]:
    """The calling thread's session, or None."""
    return getattr(_local, "session", None)


def call(name: str, *args: Any) -> Any:
    """`sim.<name>(*args)` (or a qualified `module.name`) in the calling thread's
    simulation. A failure raises
    `CallError`: a RuntimeError, as the C API's -1 makes PyRep raise, and a
    PyRepError, with gantry's reason."""
    if "." in name:
        # A function of another module (`simVision.handleSpherical`), by its full name.
        client = current().client

        def f(*a: Any) -> Any:
            return client.call(name, list(a))

    else:
        f = getattr(current().sim, name, None)
    if f is None:
        raise CallError(f"sim.{name} is not available in gantry")
    try:
        return f(*args)
    except CallError:
        raise
    except Exception as e:  # gantry's errors are plain Exceptions with the reason
        raise CallError(str(e)) from e


def floats(values: Any) -> list:
    """Any array-like of numbers (a list, a numpy array of any shape) as a flat list of
    Python floats, the form gantry's functions take."""
    import numpy as np

    return [float(v) for v in np.asarray(values, dtype=np.float64).ravel()]
