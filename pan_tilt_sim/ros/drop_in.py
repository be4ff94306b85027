"""sim_node in ros2_control_node's place: named ``controller_manager`` in a ros2_control launch.

A ros2_control launch file (ros2_control_demos' style) starts
``ros2_control_node`` (the node ``controller_manager``), robot_state_publisher
(which publishes the xacro output on ``robot_description``) and spawners.
Started there instead, as ``Node(package='pan_tilt_sim', executable='sim_node',
name='controller_manager', parameters=[...])``, sim_node is that node (see the design notes).

Design notes: docs/design/ros.md#drop_inpy.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any

from rcl_interfaces.msg import ParameterDescriptor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

from pan_tilt_sim.errors import ConfigurationError, ParameterError
from pan_tilt_sim.model.controller_config import (
    DEFAULT_UPDATE_RATE,
    UPDATE_RATE_FIELD,
    ControllersConfig,
    controller_manager_config,
    merge_parameters,
    node_parameters,
    plugin_controllers_files,
    unflatten,
)
from pan_tilt_sim.model.description import RobotDescription, description_from_text
from pan_tilt_sim.model.ros_arguments import RosArguments
from pan_tilt_sim.ros import parameters
from pan_tilt_sim.ros.controller_manager import ControllerManagerServices

NODE_NAME = 'controller_manager'  # ros2_control_node's
DESCRIPTION_TOPIC = 'robot_description'  # relative, as the controller_manager subscribes it
# As the controller_manager subscribes it: the last description, kept for late joiners.
# Parameters of the controller_manager that its arguments also give each controller.
SHARED_WITH_CONTROLLERS = (UPDATE_RATE_FIELD, 'use_sim_time')
# sim_node's own parameters that it declares only after it has read the controllers (its
# sensors, TF, simulation_interfaces and controller_manager services), by first name part:
# like every parameter sim_node declares, none is a controller's, though a launch file's
# `parameters=[{...}]` (a `/**` wildcard) and `-p` give them to every node.
DECLARED_AFTER_CONTROLLERS = ('world', 'camera', 'publish_tf', 'sensors',
                              'simulation_interfaces', 'defaults')
# ros2_control_node's own settings of its real-time thread: sim_node has none to set.
REAL_TIME_SETTINGS = ('thread_priority', 'cpu_affinity', 'lock_memory')
DESCRIPTION_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)


@dataclasses.dataclass(frozen=True)
class ManagerSettings:
    """The controller_manager's own parameters, read at start-up."""

    update_rate: int | None  # Hz; None: not given (a plugin's file, else 100 Hz)
    # The spawner's fields given at start-up, by name: {'arm_controller.type': '...'}.
    controller_fields: Mapping[str, Any]


def declare_manager_parameters(node: Node, arguments: RosArguments,
                               overrides: Iterable[Parameter] = ()) -> ManagerSettings:
    """Declare ``update_rate`` and the ``<controller>.<field>`` parameters the node was given.

    rclpy lists no parameter it was given but not asked for, so the names
    come from where they can be given -- the node's parameter files (its
    section and wildcards), its ``-p`` arguments and ``overrides`` -- and each
    is declared, which gives it the value rcl resolved for this node.
    """
    names = set(_flat(node_parameters(arguments.params_files, node.get_name())))
    names.update(arguments.parameters_for(node.get_name()))
    names.update(parameter.name for parameter in overrides)
    for name in sorted(names & set(REAL_TIME_SETTINGS)):
        node.get_logger().warning(
            f"parameter '{name}' is not honoured: sim_node steps controllers and physics in "
            "sim time on its executor, with no real-time thread to set up")
    rate = None  # declared with the simulation then, from a plugin's file or 100 Hz
    if UPDATE_RATE_FIELD in names:
        rate = parameters.declare(
            node, UPDATE_RATE_FIELD, parameters.INTEGER, int(DEFAULT_UPDATE_RATE),
            "Hz at which the controllers update (ros2_control_node's 'update_rate').")
        if rate <= 0:
            raise ParameterError(f"parameter '{UPDATE_RATE_FIELD}' must be > 0 Hz, got {rate}")
    fields = sorted(name for name in names if ControllerManagerServices.is_controller_field(name))
    declare_controller_fields(node, [Parameter(name) for name in fields])
    values = {name: node.get_parameter(name).value for name in fields}
    return ManagerSettings(rate, {name: value for name, value in values.items()
                                  if value is not None})


def declare_controller_fields(node: Node, changed: Sequence[Parameter]) -> None:
    """Declare the ``<controller>.<field>`` parameters among ``changed`` not declared yet.

    The controller_manager takes them for any controller name, as
    ros2_control's does (it allows undeclared parameters); sim_node's other
    parameters stay declared-only.
    """
    for parameter in changed:
        name = parameter.name
        if not node.has_parameter(name) and ControllerManagerServices.is_controller_field(name):
            node.declare_parameter(name, None, ParameterDescriptor(
                description="Set by ros2_control's spawner for the controller it loads.",
                dynamic_typing=True))


def manager_controllers(node: Node, settings: ManagerSettings, arguments: RosArguments,
                        description: RobotDescription) -> tuple[ControllersConfig, RosArguments]:
    """Return the controllers the node's parameters declare, and the arguments they read.

    None declared is fine: spawners give them.  As Gazebo starts its
    controller_manager with the files the URDF's gz_ros2_control plugin
    names (``<parameters>``), those files come first, under the node's own:
    their controllers, their sections and -- unless the node was given one --
    their ``update_rate`` count, so a Gazebo launch file whose spawn step
    sim_node replaces keeps its controllers.  One the plugin names but that
    cannot be found is skipped with a warning.
    """
    try:
        plugin_files = plugin_controllers_files(description)
    except ConfigurationError as err:
        node.get_logger().warning(f'{err}: skipped')
        plugin_files = ()
    arguments = dataclasses.replace(
        arguments, params_files=(*plugin_files, *arguments.params_files))
    manager = node_parameters(plugin_files, node.get_name())
    fields = {name: value for name, value in _flat_items(manager)
              if ControllerManagerServices.is_controller_field(name)}
    fields.update(settings.controller_fields)
    rate = settings.update_rate
    if rate is None:
        given = manager.get(UPDATE_RATE_FIELD)
        rate = given if isinstance(given, int) and given > 0 else int(DEFAULT_UPDATE_RATE)
    controllers = controller_manager_config(
        fields, lambda name: shared_parameters(node, arguments, name),
        update_rate=float(rate),
        source=' + '.join([*(str(path) for path in plugin_files),
                           f'the parameters of {node.get_fully_qualified_name()}']))
    return controllers, arguments


def shared_parameters(node: Node, arguments: RosArguments, controller: str) -> dict[str, Any]:
    """Return what the node's own arguments give ``controller``'s node, as ros2_control does.

    The controller's sections of the node's ``--params-file`` files (its
    own and the wildcards that match it) and the ``-p`` values for it --
    without sim_node's own parameters (``real_time_factor``, ``world``, the
    controllers' types...), declared yet or not, which wildcards and ``-p``
    give every node but no controller has; ``update_rate`` and
    ``use_sim_time`` stay.
    """
    params = node_parameters(arguments.params_files, controller)
    merge_parameters(params, unflatten(arguments.parameters_for(controller)))
    return {key: value for key, value in params.items()
            if key in SHARED_WITH_CONTROLLERS or not (
                key in DECLARED_AFTER_CONTROLLERS or node.has_parameter(key)
                or node.get_parameters_by_prefix(key))}


def wait_for_description(node: Node, build: Callable[[RobotDescription], None]) -> Any:
    """Subscribe to ``robot_description``; ``build`` the simulation from the first message.

    One info line says what the node waits for; nothing polls.  A later
    description is ignored with a warning; one that cannot be simulated
    raises (the program ends with its one-line error, as for a file).
    Returns the subscription.
    """
    logger = node.get_logger()
    built = False

    def received(message: String) -> None:
        nonlocal built
        if built:
            logger.warning(
                'The simulation has already loaded a robot description: ignoring a new one on '
                f"'{subscription.topic_name}' (restart sim_node to simulate another robot)")
            return
        built = True
        logger.info(f"Received robot description from topic '{subscription.topic_name}'.")
        build(description_from_text(message.data, subscription.topic_name))

    subscription = node.create_subscription(String, DESCRIPTION_TOPIC, received, DESCRIPTION_QOS)
    logger.info(
        f"Waiting for the robot description on '{subscription.topic_name}' (robot_description_file "
        'is not set): the simulation starts when robot_state_publisher publishes it')
    return subscription


def _flat(nested: Mapping[str, Any]) -> list[str]:
    """Return the dotted names of the leaves of nested parameters."""
    return [name for name, _value in _flat_items(nested)]


def _flat_items(nested: Mapping[str, Any], prefix: str = '') -> list[tuple[str, Any]]:
    """Return (dotted name, value) of the leaves of nested parameters."""
    items = []
    for key, value in nested.items():
        name = f'{prefix}{key}'
        if isinstance(value, Mapping) and value:
            items.extend(_flat_items(value, f'{name}.'))
        else:
            items.append((name, value))
    return items
