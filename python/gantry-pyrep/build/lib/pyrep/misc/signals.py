"""Named signals: values scripts and Python share through the simulator."""

from pyrep.backend import sim
from pyrep.errors import PyRepError


class Signal:
    """A named signal of one type."""

    def __init__(self, name: str):
        self._name = name

    def set(self, value) -> None:
        raise NotImplementedError

    def get(self):
        raise NotImplementedError

    def clear(self) -> int:
        raise NotImplementedError

    def _check_signal(self, found: int, type_name: str) -> None:
        if found == 0:
            raise PyRepError(f"Signal {self._name} of type {type_name} does not exist.")


class IntegerSignal(Signal):
    def set(self, value: int) -> None:
        sim.simSetIntegerSignal(self._name, value)

    def get(self) -> int:
        found, value = sim.simGetIntegerSignal(self._name)
        self._check_signal(found, "int")
        return value

    def clear(self) -> int:
        return sim.simClearIntegerSignal(self._name)


class FloatSignal(Signal):
    def set(self, value: float) -> None:
        sim.simSetFloatSignal(self._name, value)

    def get(self) -> float:
        found, value = sim.simGetFloatSignal(self._name)
        self._check_signal(found, "float")
        return value

    def clear(self) -> int:
        return sim.simClearFloatSignal(self._name)


class DoubleSignal(Signal):
    def set(self, value: float) -> None:
        sim.simSetDoubleSignal(self._name, value)

    def get(self) -> float:
        found, value = sim.simGetDoubleSignal(self._name)
        self._check_signal(found, "double")
        return value

    def clear(self) -> int:
        return sim.simClearDoubleSignal(self._name)


class StringSignal(Signal):
    def set(self, value: str) -> None:
        sim.simSetStringSignal(self._name, value)

    def get(self) -> str:
        found, value = sim.simGetStringSignal(self._name)
        self._check_signal(found, "string")
        return value.decode() if isinstance(value, (bytes, bytearray)) else value

    def clear(self) -> int:
        return sim.simClearStringSignal(self._name)
