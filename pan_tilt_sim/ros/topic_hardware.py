"""Topic-based hardware: sim_node as the robot behind PickNik's ``topic_based_ros2_control``.

In this mode sim_node runs none of the controllers YAML's controllers: the
user's real controller_manager does, on its own ``topic_based_ros2_control/
TopicBasedSystem`` hardware (as with Isaac Sim), and sim_node is the robot
on the far side of two topics (see :mod:`pan_tilt_sim.model.topic_based`):

* it subscribes ``topic_based.joint_commands_topic`` (sensor_msgs/JointState;
  position, velocity or effort per joint, by name; partial messages and the
  plugin's packed arrays are read; the last command of each joint holds until
  the next, since the plugin sends nothing while on target);
* it publishes ``topic_based.joint_states_topic`` at ``topic_based.publish_rate``
  Hz of sim time: every movable joint (or ``topic_based.joints``), with name,
  position, velocity and effort aligned, stamped with sim time.

Design notes: docs/design/ros.md#topic_hardwarepy.
"""

from __future__ import annotations

import dataclasses
import pathlib
from collections.abc import Callable, Iterable

from rcl_interfaces.msg import ParameterDescriptor
from rclpy.node import Node
from sensor_msgs.msg import JointState

from pan_tilt_sim.controllers import CommandResult, Controller
from pan_tilt_sim.controllers.commands.forward_command_controller import ForwardCommandController
from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model.controller_config import ControllersConfig, ControllerSpec
from pan_tilt_sim.model.description import RobotDescription
from pan_tilt_sim.model.topic_based import (
    COMMANDS_TOPIC_PARAM,
    DEFAULT_COMMANDS_TOPIC,
    DEFAULT_STATES_TOPIC,
    INTERFACES,
    STATES_TOPIC_PARAM,
    CommandReader,
    command_interface,
    declared_interfaces,
    topic_based_system,
)
from pan_tilt_sim.ros import parameters as params

PREFIX = 'topic_based'
DEFAULT_PUBLISH_RATE = 100.0  # Hz of sim time: a controller_manager's usual update_rate
GAIN_FIELDS = ('p', 'i', 'd', 'i_clamp')
GROUP_TYPES = {'position': 'position_controllers/JointGroupPositionController',
               'velocity': 'velocity_controllers/JointGroupVelocityController',
               'effort': 'effort_controllers/JointGroupEffortController'}
BROADCASTER = f'{PREFIX}_joint_states'
SOURCE = pathlib.Path('<topic-based hardware>')
QUEUE_DEPTH = 10
WARNING_THROTTLE_S = 1.0


@dataclasses.dataclass(frozen=True)
class TopicHardwareSettings:
    """The ``topic_based.*`` parameters, checked."""

    commands_topic: str
    states_topic: str
    joints: tuple[str, ...]  # published
    interfaces: dict[str, str]  # commanded joint -> its command interface
    gains: dict[str, dict[str, float]]
    publish_rate: float


def declare(node: Node, description: RobotDescription) -> TopicHardwareSettings | None:
    """Declare the ``topic_based.*`` parameters; return the settings, or None if the mode is off."""
    model = description.model
    system = topic_based_system(model)
    hardware = dict(system.hardware_params) if system is not None else {}
    enabled = params.declare(
        node, f'{PREFIX}.enabled', params.BOOL, system is not None,
        'Be the robot of topic_based_ros2_control: take JointState commands, publish '
        "JointState, run no controllers (default: true when the URDF's <ros2_control> "
        'hardware is topic_based_ros2_control/TopicBasedSystem).')
    commands_topic = params.declare(
        node, f'{PREFIX}.joint_commands_topic', params.STRING,
        hardware.get(COMMANDS_TOPIC_PARAM, DEFAULT_COMMANDS_TOPIC),
        "JointState commands to take (default: the URDF hardware param, else the plugin's).")
    states_topic = params.declare(
        node, f'{PREFIX}.joint_states_topic', params.STRING,
        hardware.get(STATES_TOPIC_PARAM, DEFAULT_STATES_TOPIC),
        "JointState to publish (default: the URDF hardware param, else the plugin's).")
    joints = params.declare(
        node, f'{PREFIX}.joints', params.STRING_ARRAY, None,
        'Joints to publish and command; unset = every movable joint (mimic joints follow).')
    override = params.declare(
        node, f'{PREFIX}.command_interface', params.STRING, '',
        "position, velocity or effort for every joint; '' = per joint from the URDF's "
        '<ros2_control> (position if declared, else velocity, else effort).')
    rate = params.declare(node, f'{PREFIX}.publish_rate', params.DOUBLE, DEFAULT_PUBLISH_RATE,
                          'JointState messages per second of sim time.')
    movable = [joint.name for joint in model.actuated_joints]
    for joint in joints:
        if joint not in movable:
            raise ParameterError(f"parameter '{PREFIX}.joints': '{joint}' is not a movable "
                                 f"joint of the robot (movable: {', '.join(movable)})")
    if override and override not in INTERFACES:
        raise ParameterError(f"parameter '{PREFIX}.command_interface' must be one of "
                             f"{', '.join(INTERFACES)} or '', got '{override}'")
    if not rate > 0.0:
        raise ParameterError(f"parameter '{PREFIX}.publish_rate' must be > 0, got {rate}")
    published = tuple(joints) or tuple(movable)
    mimics = model.mimics
    commanded = [joint for joint in published if joint not in mimics]
    gains = {}
    for joint in commanded:
        given = {field: _optional_double(
            node, f'{PREFIX}.pid_gains.{joint}.{field}',
            f'PID gain {field} of {joint} (p given: a PID instead of the ideal actuator).')
            for field in GAIN_FIELDS}
        if given['p'] is not None:
            gains[joint] = {field: value for field, value in given.items() if value is not None}
    if not enabled:
        return None
    return TopicHardwareSettings(
        commands_topic, states_topic, published,
        {joint: command_interface(model, joint, override) for joint in commanded},
        gains, rate)


def _optional_double(node: Node, name: str, description: str) -> float | None:
    """Declare a double parameter that may stay unset; return it (None: unset)."""
    descriptor = ParameterDescriptor(name=name, type=params.DOUBLE, description=description,
                                     dynamic_typing=True)
    value = node.declare_parameter(name, None, descriptor).value
    return None if value is None else params.coerce(name, params.DOUBLE, value)


def controllers_config(settings: TopicHardwareSettings) -> ControllersConfig:
    """Return the controllers the mode runs: a broadcaster and a group per interface used."""
    specs = [ControllerSpec(BROADCASTER, 'joint_state_broadcaster/JointStateBroadcaster',
                            {'joints': list(settings.joints),
                             'publish_rate': settings.publish_rate})]
    for interface in INTERFACES:
        joints = [joint for joint, used in settings.interfaces.items() if used == interface]
        if not joints:
            continue
        spec = {'joints': joints}
        gains = {joint: settings.gains[joint] for joint in joints if joint in settings.gains}
        if gains:
            spec['gains'] = gains
        specs.append(ControllerSpec(f'{PREFIX}_{interface}', GROUP_TYPES[interface], spec))
    return ControllersConfig(tuple(specs), SOURCE)


def topics(settings: TopicHardwareSettings, robot_topic: Callable[..., str]) -> Callable[..., str]:
    """Return the node's topic namer with ``joint_states`` on the mode's states topic."""
    def topic(*names: str) -> str:
        return settings.states_topic if names == ('joint_states',) else robot_topic(*names)
    return topic


class TopicHardware:
    """The command subscription of the mode, on a SimNode (the broadcaster publishes states)."""

    def __init__(self, node: Node, settings: TopicHardwareSettings, description: RobotDescription,
                 controllers: Iterable[Controller]) -> None:
        self.settings = settings
        self.commands_received = 0
        self._logger = node.get_logger()
        model = description.model
        self._members = {}
        for controller in controllers:
            if isinstance(controller, ForwardCommandController):
                for joint, member in zip(controller.joint_names, controller.members,
                                         strict=True):
                    self._members[joint] = member
        self._reader = CommandReader(
            settings.interfaces,
            {joint.name: declared_interfaces(model, joint.name) for joint in model.joints},
            ignored=[joint for joint in settings.joints if joint not in settings.interfaces])
        self.subscription = node.create_subscription(
            JointState, settings.commands_topic, self._store, QUEUE_DEPTH)
        node.get_logger().info(
            f'topic-based hardware: commands from {self.subscription.topic_name}, states on '
            f'{node.resolve_topic_name(settings.states_topic)} at {settings.publish_rate:g} Hz '
            'of sim time; '
            + ', '.join(f'{joint}: {interface}' for joint, interface
                        in settings.interfaces.items()))

    def _store(self, message: JointState) -> None:
        self.commands_received += 1
        decoded = self._reader.read(message.name, {'position': message.position,
                                                   'velocity': message.velocity,
                                                   'effort': message.effort})
        problems = list(decoded.problems)
        for joint, value in decoded.commands.items():
            member = self._members[joint]
            result = member.set_command(value)
            if result is not CommandResult.ACCEPTED:
                problems.append(f"'{joint}': {member.command_problem(value, result)}")
        if problems:
            self._logger.warning(f'{self.subscription.topic_name}: ' + '; '.join(problems),
                                 throttle_duration_sec=WARNING_THROTTLE_S)
