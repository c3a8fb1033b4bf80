"""`ConfigurationPath`: what every path a robot can follow offers."""


class ConfigurationPath:
    """A path in a robot's configuration space."""

    def step(self) -> bool:
        """Moves the robot's controllers one simulation step along the path (the
        caller steps the simulation); True once the end is reached."""
        raise NotImplementedError()

    def set_to_start(self) -> None:
        raise NotImplementedError()

    def set_to_end(self) -> None:
        raise NotImplementedError()

    def visualize(self) -> None:
        raise NotImplementedError()

    def clear_visualization(self) -> None:
        raise NotImplementedError()
