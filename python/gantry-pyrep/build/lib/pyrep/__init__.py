"""PyRep's API on gantry: `from pyrep import PyRep` works as with CoppeliaSim 4.1,
with no CoppeliaSim, X server or GPU. See docs/pyrep.md in gantry's repository."""

__version__ = "4.1.0.3"

# PyRep's tests set this; nothing depends on it here.
testing = False

from .pyrep import PyRep  # noqa: E402

__all__ = ["PyRep", "__version__"]
