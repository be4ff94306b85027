"""sim_node's start-up steps, each readable and testable alone.

:meth:`pan_tilt_sim.ros.sim_node.SimNode._build` runs them in order and says
which orders the data they pass does not show.  A step takes what it uses
and returns what it makes; a step that declares parameters or makes topics
takes the node for that.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

from rclpy.context import Context
from rclpy.node import Node

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model import naming
from pan_tilt_sim.model.controller_config import (
    CONTROLLERS_ARGS,
    NO_CONTROLLERS_FILE,
    ControllersConfig,
    controllers_files_for,
    load_controllers_config,
    parse_controllers_args,
)
from pan_tilt_sim.model.description import RobotDescription
from pan_tilt_sim.model.robot import RobotModel
from pan_tilt_sim.model.ros_arguments import RosArguments
from pan_tilt_sim.plugins.registry import runs_by_plugins
from pan_tilt_sim.ros import command_reader, drop_in, optional_interfaces, topic_hardware
from pan_tilt_sim.ros.command_reader import CommandReader
from pan_tilt_sim.ros.controller_bindings import ControllerBindings
from pan_tilt_sim.ros.features import NodeFeatures
from pan_tilt_sim.ros.gain_parameters import GainParameters
from pan_tilt_sim.ros.parameters import SimParameters
from pan_tilt_sim.ros.physics_thread import Turns
from pan_tilt_sim.ros.recording import Recorder
from pan_tilt_sim.sim.engine import Simulation


@dataclasses.dataclass(frozen=True)
class ControllersChoice:
    """The controllers to run and where they came from."""

    config: ControllersConfig
    # Topic-based hardware (topic_based_ros2_control): its settings; None when off.
    topic_settings: topic_hardware.TopicHardwareSettings | None
    # The process's arguments, with the files a drop-in controller_manager read added.
    arguments: RosArguments


def choose_controllers(node: Node, description: RobotDescription, settings: SimParameters,
                       manager_settings: drop_in.ManagerSettings | None,
                       arguments: RosArguments) -> ControllersChoice:
    """Return the controllers from the first source that applies.

    Topic-based hardware runs its own (no YAML controllers); a node in
    ros2_control_node's place (``manager_settings`` given) runs those of its
    parameters and its plugin's files; else those of ``controllers_file``
    (or the files the URDF's plugins name).  Declares ``topic_based.*``.
    """
    topic_settings = topic_hardware.declare(node, description)
    if topic_settings is not None:
        return ControllersChoice(topic_hardware.controllers_config(topic_settings),
                                 topic_settings, arguments)
    if manager_settings is not None:
        config, arguments = drop_in.manager_controllers(node, manager_settings, arguments,
                                                        description)
        return ControllersChoice(config, None, arguments)
    config = load_controllers_config(
        controllers_files_for(settings.controllers_file, description,
                              runs_by_plugins=runs_by_plugins(description.model)),
        parse_controllers_args(settings.controllers_args, f"parameter '{CONTROLLERS_ARGS}'"),
        manager=description.model.controller_manager_name)
    return ControllersChoice(config, None, arguments)


def robot_namespace(node_namespace: str, parameter: str, controllers_namespace: str | None,
                    plugin_namespace: str | None, *, is_controller_manager: bool) -> str:
    """Return the namespace of the robot's topics ('' for the root).

    In ros2_control_node's place the controllers live in the node's own
    namespace and nowhere else; otherwise the first of the node's namespace,
    ``robot_namespace`` (``parameter``), the controllers file's and the
    URDF plugin's.
    """
    if is_controller_manager:
        return naming.normalize(node_namespace)
    return naming.resolve_robot_namespace(node_namespace, parameter, controllers_namespace,
                                          plugin_namespace)


def make_simulation(description: RobotDescription, controllers: ControllersConfig,
                    settings: SimParameters, *, topic_mode: bool, logger,
                    world: Simulation | None = None) -> Simulation:
    """Load the robot into PyBullet with its controllers (topic-based hardware: all active).

    ``world``: a robot's simulation whose world this one joins, and whose
    time step it takes (its GUI and solver settings are that world's).
    """
    return Simulation(
        description, controllers, settings.time_step if world is None else world.time_step,
        gui=settings.gui, world=world,
        active_controllers=None if topic_mode else settings.active_controllers,
        initial_positions=settings.initial_positions, logger=logger,
        autostart_controllers=topic_mode or settings.autostart_controllers,
        fixed_base=settings.fixed_base, initial_pose=settings.initial_pose,
        physics_settings=settings.physics_settings)


def make_recorder(settings: SimParameters, simulation: Simulation,
                  warn: Callable[[str], None]) -> Recorder | None:
    """Return the bag that ``record`` asks for, stamped with sim time; None if not asked."""
    if not settings.record:
        return None
    return Recorder(settings.record, clock=lambda: simulation.time,
                    sensors=settings.record_sensors, warn=warn)


def make_command_reader(context: Context, turns: Turns | None, logger) -> CommandReader | None:
    """With a physics thread, a reader thread for the command topics where this rclpy allows.

    None without a physics thread, or where the executor must read them (in their turn).
    """
    if turns is None:
        return None
    if command_reader.available(context):
        return CommandReader(context, turns)
    logger.info("command topics are read by the executor: this rclpy's private wait set "
                'is not the one pan_tilt_sim.ros.command_reader knows')
    return None


def bind_controllers(node: Node, simulation: Simulation,
                     topic_settings: topic_hardware.TopicHardwareSettings | None,
                     gain_parameters: GainParameters, reader: CommandReader | None,
                     namespace: str) -> ControllerBindings:
    """Give each controller its topics, action and gain parameters under ``namespace``.

    With topic-based hardware, no command topics: the hardware's own take the commands.
    """
    def topic(*names: str) -> str:
        return naming.join(namespace, *names)

    topic_mode = topic_settings is not None
    return ControllerBindings(
        node, simulation,
        topic_hardware.topics(topic_settings, topic) if topic_mode else topic,
        gain_parameters,
        actions=not topic_mode and optional_interfaces.available('control_msgs'),
        command_topics=not topic_mode, reader=reader, namespace=namespace)


def make_features(node: Node, simulation: Simulation, namespace: str, settings: SimParameters,
                  *, world, from_topic: bool, is_controller_manager: bool) -> NodeFeatures:
    """Make the robot's state, sensors, camera and world entities (NodeFeatures).

    Sensors follow an explicit namespace (the node's, or ``robot_namespace``)
    the way Gazebo's spawn -robot_namespace moves every plugin; else their
    plugins'.  A description that came on a topic is not published again.
    """
    return NodeFeatures(
        node, simulation, namespace, gui=settings.gui,
        sensor_namespace=naming.normalize(node.get_namespace())
        or naming.normalize(settings.robot_namespace),
        publish_description=not from_topic, world=world,
        publish_tf_default=not is_controller_manager)


def has_controller_manager(model: RobotModel, controllers: ControllersConfig, *,
                           is_controller_manager: bool) -> bool:
    """Return whether the robot has a controller manager, as upstream would make one.

    sim_node in ros2_control_node's place is one; a gz_ros2_control /
    gazebo_ros2_control plugin beside a ``<ros2_control>`` block makes one; so
    do controllers read from a file (the user's ``controllers_file``, the
    plugin's ``<parameters>``, the pan/tilt example's).  A robot that only its
    Gazebo plugins run (diff drive, joint state publisher; no controllers
    file) has none, as in Gazebo: no ``controller_manager`` node for it.
    """
    return (is_controller_manager or controllers.source != NO_CONTROLLERS_FILE
            or bool(model.ros2_control and model.control_plugins))


def serve_controller_manager(node: Node, bindings: ControllerBindings, simulation: Simulation,
                             controllers: ControllersConfig, settings: SimParameters,
                             arguments: RosArguments, namespace: str, *, topic_mode: bool,
                             is_controller_manager: bool,
                             manager_node: Node | None = None) -> Node | None:
    """Offer ros2_control's controller_manager services; return the node that serves them.

    ``node`` itself in ros2_control_node's place, else a node of its own the
    caller spins and destroys with ``node`` (``manager_node``, a
    :class:`ControllerManagerNode` made beforehand, or a new one); None on
    topic-based hardware (the user's own controller_manager runs) or without
    controller_manager_msgs, or for a robot that has none
    (:func:`has_controller_manager`).
    """
    if topic_mode:
        return None
    if not optional_interfaces.available('controller_manager_msgs'):
        if not settings.autostart_controllers:
            raise ParameterError(
                "parameter 'autostart_controllers' is false, but controller_manager_msgs "
                'is not installed: no spawner could load a controller '
                '(scripts/build_interfaces.sh builds it)')
        return None
    if not has_controller_manager(simulation.description.model, controllers,
                                  is_controller_manager=is_controller_manager):
        return None
    from pan_tilt_sim.ros.controller_manager import (
        ControllerManagerNode,
        ControllerManagerServices,
    )

    substitutions = parse_controllers_args(settings.controllers_args)
    if is_controller_manager:  # this node is the controller_manager
        ControllerManagerServices(
            node, bindings, simulation.manager, simulation.description.model,
            substitutions=substitutions, source=controllers.label,
            update_rate=round(controllers.update_rate),
            shared_parameters=lambda name: drop_in.shared_parameters(node, arguments, name))
        return node
    if manager_node is None:
        manager_node = ControllerManagerNode(simulation.description.model, namespace,
                                             context=node.context)
    manager_node.serve(bindings, simulation.manager, substitutions=substitutions,
                       source=controllers.label)
    return manager_node
