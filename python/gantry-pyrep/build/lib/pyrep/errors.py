"""The exceptions of PyRep's API, raised by gantry's `pyrep` where PyRep raises them."""


class PyRepError(Exception):
    """A misuse of the API (not launched, a missing scene file, ...)."""


class WrongObjectTypeError(Exception):
    """An object was opened as a type it is not (`Joint('a_shape')`)."""


class ObjectAlreadyRemovedError(Exception):
    """The object was removed from the scene already."""


class ObjectIsNotModelError(Exception):
    """A model operation on an object that is not a model base."""


class ConfigurationError(Exception):
    """No configuration of a robot reaches the asked pose."""


class ConfigurationPathError(Exception):
    """No path to the asked configuration or pose was found."""


class GripperError(Exception):
    """A gripper or suction cup could not do what was asked."""


class IKError(Exception):
    """Inverse kinematics failed to reach the target."""


class CallError(PyRepError, RuntimeError):
    """A simulator function refused a call (bad input, an object that is gone, ...),
    with gantry's reason. PyRep raises a bare RuntimeError for these (the C API's
    failure); this is both, so code catching either works."""
