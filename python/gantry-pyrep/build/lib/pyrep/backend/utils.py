"""Helpers PyRep's users import from `pyrep.backend.utils`."""

from __future__ import annotations

import threading
from typing import List, Tuple

from pyrep.backend import sim

# PyRep serialises steps with this lock; gantry's simulations belong to one thread
# each, so it only orders a thread's own calls, but code that takes it keeps working.
step_lock = threading.Lock()


def to_type(handle: int):
    """The object `handle` names, as the class of its type."""
    from pyrep.objects.object import Object
    import pyrep.objects  # noqa: F401  (registers every object class)

    try:
        return Object.get_object(handle)
    except KeyError:
        raise ValueError(f"object {handle} is of a type PyRep has no class for") from None


def script_call(function_name_at_script_name: str, script_handle_or_type: int, ints=(), floats=(), strings=(),
                bytes="") -> Tuple[List[int], List[float], List[str], str]:
    """Calls `function@scriptName` in a scene script with PyRep's four argument
    lists; returns (ints, floats, strings, bytes)."""
    return sim.simExtCallScriptFunction(function_name_at_script_name, script_handle_or_type, list(ints),
                                        list(floats), list(strings), bytes)
