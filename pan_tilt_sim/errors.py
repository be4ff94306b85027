"""Errors a user can cause by what they give the simulator.

Every error here ends start-up with exit code 2 and one line of text that
names the file, field or parameter and what is wrong with it.
"""


class ConfigurationError(Exception):
    r"""A user-supplied file or parameter is wrong; the message says how.

    Its text is always one line: a line break it quotes (a joint named ``"a\nb"``)
    reads as ``\n``, so the one-line error of a start-up stays one line.
    """

    def __str__(self) -> str:
        return super().__str__().replace('\r', '\\r').replace('\n', '\\n')


class DescriptionError(ConfigurationError):
    """The robot description (URDF/xacro, meshes) cannot be used."""


class ControllerConfigError(ConfigurationError):
    """The controllers file cannot be used."""


class ControllerSwitchError(ControllerConfigError):
    """Activating or deactivating controllers would leave the robot in a state ros2_control refuses.

    Two active controllers claiming one joint, a controller that is not loaded, a
    command interface the joint does not have, or a combination of command interfaces
    the robot's hardware refuses; nothing was switched.
    """


class ParameterError(ConfigurationError):
    """A node parameter has a wrong type or value."""


class ArgumentError(ConfigurationError):
    """The command line's ROS arguments (``--ros-args ...``) cannot be parsed."""


def one_line(text: str) -> str:
    """Fold ``text`` (a wrapped or multi-line library message) into one line."""
    return ' '.join(text.split())
