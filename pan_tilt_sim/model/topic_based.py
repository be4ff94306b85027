"""Topic-based hardware: reading what PickNik's ``topic_based_ros2_control`` sends. No ROS.

Users who run ros2_control's real controller_manager against Isaac Sim give
their URDF's ``<ros2_control>`` block the hardware plugin
``topic_based_ros2_control/TopicBasedSystem``.  Each controller_manager cycle
it publishes the commands of its joints as one ``sensor_msgs/JointState`` on
``joint_commands_topic`` (default ``/robot_joint_commands``) and reads the
latest JointState on ``joint_states_topic`` (``/robot_joint_states``).  Its
message has ``name`` = every joint of the block, and ``position``,
``velocity``, ``effort`` hold values only for the joints that declare that
command interface, in joint order -- so with uniform interfaces an array is
one value per name, and with mixed ones it is shorter (packed).  A
hand-written publisher may send any joints by name with index-aligned arrays.

Design notes: docs/design/model.md#topic_basedpy.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence

from pan_tilt_sim.model.robot import ControlSystem, RobotModel

PLUGIN = 'topic_based_ros2_control/TopicBasedSystem'
COMMANDS_TOPIC_PARAM = 'joint_commands_topic'
STATES_TOPIC_PARAM = 'joint_states_topic'
DEFAULT_COMMANDS_TOPIC = '/robot_joint_commands'  # the plugin's defaults
DEFAULT_STATES_TOPIC = '/robot_joint_states'
POSITION, VELOCITY, EFFORT = 'position', 'velocity', 'effort'
INTERFACES = (POSITION, VELOCITY, EFFORT)  # also the order of preference


def topic_based_system(model: RobotModel) -> ControlSystem | None:
    """Return the URDF's ``<ros2_control>`` block whose hardware is TopicBasedSystem, if any."""
    return next((system for system in model.ros2_control if system.plugin == PLUGIN), None)


def declared_interfaces(model: RobotModel, joint: str) -> tuple[str, ...]:
    """Return the command interfaces the joint's ``<ros2_control>`` entry declares, known ones."""
    entry = model.control_joint(joint)
    if entry is None:
        return ()
    return tuple(name for name in entry.command_interface_names if name in INTERFACES)


def command_interface(model: RobotModel, joint: str, override: str = '') -> str:
    """Return the interface that commands ``joint``: ``override``, else the preferred declared.

    Position is preferred to velocity, velocity to effort; a joint with no
    ``<ros2_control>`` entry takes position.
    """
    if override:
        return override
    declared = declared_interfaces(model, joint)
    return next((name for name in INTERFACES if name in declared), POSITION)


@dataclasses.dataclass
class Decoded:
    """One message, read: the command of each commanded joint, and what was wrong."""

    commands: dict[str, float] = dataclasses.field(default_factory=dict)
    problems: list[str] = dataclasses.field(default_factory=list)


class CommandReader:
    """Reads command JointStates for the ``commanded`` joints (joint -> its interface).

    ``declared`` gives each joint the plugin knows its declared command
    interfaces (to unpack shorter arrays); ``ignored`` are joints that may be
    named but take no command (mimic joints, which the plugin names too).
    """

    def __init__(self, commanded: Mapping[str, str], declared: Mapping[str, Sequence[str]],
                 ignored: Sequence[str] = ()) -> None:
        self._commanded = dict(commanded)
        self._declared = {joint: tuple(names) for joint, names in declared.items()}
        self._ignored = set(ignored)

    def read(self, names: Sequence[str], fields: Mapping[str, Sequence[float]]) -> Decoded:
        """Return each commanded joint's command in a message (its ``name`` and arrays)."""
        decoded = Decoded()
        names = list(names)
        if len(set(names)) != len(names):
            decoded.problems.append(f'a joint is named twice in {names}: message ignored')
            return decoded
        values: dict[str, dict[str, float]] = {}
        for interface in INTERFACES:
            array = list(fields.get(interface, ()))
            if not array:
                continue
            if len(array) == len(names):
                holders = names
            else:
                holders = [name for name in names if interface in self._declared.get(name, ())]
                if len(holders) != len(array):
                    decoded.problems.append(
                        f'{interface} has {len(array)} values for {len(names)} names, neither '
                        f'one per name nor one per named joint with a {interface} command '
                        f'interface ({len(holders)}): ignored')
                    continue
            for name, value in zip(holders, array, strict=True):
                values.setdefault(name, {})[interface] = value
        for name in names:
            given = values.get(name, {})
            if name in self._ignored or not given:
                continue
            interface = self._commanded.get(name)
            if interface is None:
                decoded.problems.append(f"'{name}' is not a commanded joint: ignored")
                continue
            if interface not in given:
                decoded.problems.append(
                    f"'{name}' takes {interface} commands; its {', '.join(given)} ignored")
                continue
            value = given[interface]
            if not math.isfinite(value):
                decoded.problems.append(f"'{name}': {interface} {value} is not finite: ignored")
                continue
            decoded.commands[name] = value
        return decoded
