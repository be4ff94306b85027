"""Robots spawned into a world that has one already: each with its plugins, sensors, manager.

:class:`SpawnedRobot` is one more robot on sim_node: its own
:class:`~pan_tilt_sim.sim.engine.Simulation` in the first robot's PyBullet world
(stepped with it), its Gazebo plugins' and controllers' topics under its
namespace, its sensors, and a controller manager of its own where its
description has ``<ros2_control>`` and a gz_ros2_control plugin.  Deleting it
takes all of that away.  docs/launch-files.md#several-robots is the reference.
"""

from __future__ import annotations

import dataclasses

from rclpy.node import Node

from pan_tilt_sim.controllers.framework.surface import PRIVATE, CommandTopic, StateTopic
from pan_tilt_sim.errors import ConfigurationError
from pan_tilt_sim.model import naming
from pan_tilt_sim.model.base_pose import BasePose
from pan_tilt_sim.model.controller_config import (
    ControllersConfig,
    controllers_files_for,
    load_controllers_config,
)
from pan_tilt_sim.model.description import RobotDescription
from pan_tilt_sim.model.ros_arguments import RosArguments
from pan_tilt_sim.model.sensors import sensor_interface
from pan_tilt_sim.plugins.registry import create_plugins, runs_by_plugins
from pan_tilt_sim.ros import optional_interfaces, startup
from pan_tilt_sim.ros.controller_bindings import ControllerBindings
from pan_tilt_sim.ros.features import require_ground, robot_sensors
from pan_tilt_sim.ros.gain_parameters import GainParameters
from pan_tilt_sim.ros.parameters import SimParameters
from pan_tilt_sim.ros.sensor_publishers import SensorSet
from pan_tilt_sim.sim.engine import Simulation


def is_robot(description: RobotDescription) -> bool:
    """Return whether a spawned description is a robot (plugins, sensors, ros2_control)."""
    model = description.model
    return bool(model.plugins or model.sensors or model.ros2_control or model.control_plugins)


def controllers_of(description: RobotDescription) -> ControllersConfig:
    """Return the controllers its gz_ros2_control plugin's ``<parameters>`` name (or none)."""
    return load_controllers_config(controllers_files_for(
        '', description, runs_by_plugins=runs_by_plugins(description.model)), {},
        manager=description.model.controller_manager_name)


def later_robot_settings(settings: SimParameters, initial_pose: BasePose) -> SimParameters:
    """Return sim_node's settings as a later robot takes them, placed at ``initial_pose``.

    Not the ones that name the first robot's controllers and joints
    (``active_controllers``, ``initial_positions``, ``controllers_args``).
    """
    return dataclasses.replace(settings, initial_pose=initial_pose, active_controllers=None,
                               initial_positions={}, controllers_args=())
def own_topics(description: RobotDescription, namespace: str) -> set[str]:
    """Return the topics its plugins and sensors will have, before any bridge renames them.

    ``namespace`` is the spawn request's (as :class:`SpawnedRobot` takes it).  Names
    only: nothing is created.  A description that cannot be read has none here (its
    build says what is wrong).
    """
    try:
        controllers = controllers_of(description)
        plugins = create_plugins(description.model)
    except ConfigurationError:
        return set()
    robot = naming.resolve_robot_namespace('', namespace, controllers.namespace,
                                           description.plugin_namespace)
    topics = set()
    for plugin in plugins:
        plugin.node_namespace = naming.join(robot)  # as ControllerBindings sets it
        for endpoint in plugin.ros_surface():
            if not isinstance(endpoint, (CommandTopic, StateTopic)):
                continue
            name = endpoint.name
            if name.startswith(PRIVATE):
                topics.add(naming.join(robot, plugin.name, name[len(PRIVATE):]))
            else:
                topics.add(name if name.startswith('/') else naming.join(robot, name))
    model = description.model
    for sensor in model.sensors:
        topics.update(sensor_interface(sensor, model.name, namespace).topics.values())
    return topics


class SpawnedRobot:
    """One more robot on ``node``, in ``host``'s world, its topics under ``namespace``.

    ``settings`` are sim_node's (``fixed_base``, ``autostart_controllers``);
    the robot stands at ``initial_pose``.
    """

    def __init__(self, node: Node, host: Simulation, description: RobotDescription, *,
                 namespace: str, controllers: ControllersConfig, settings: SimParameters,
                 initial_pose: BasePose, world: str, reader=None,
                 seed: int | None = None) -> None:
        self.name = description.name
        self.namespace = startup.robot_namespace(
            '', namespace, controllers.namespace, description.plugin_namespace,
            is_controller_manager=False)
        self._node = node
        self._host = host
        settings = later_robot_settings(settings, initial_pose)
        self.simulation = startup.make_simulation(
            description, controllers, settings, topic_mode=False, logger=node.get_logger(),
            world=host)
        self.controller_manager: Node | None = None
        self.bindings: ControllerBindings | None = None
        self.sensors: SensorSet | None = None
        try:
            require_ground(self.simulation, world)
            # Its controllers' gains are parameters of its own controller manager node.
            manager_node = self._manager_node(description, controllers)
            self.bindings = startup.bind_controllers(
                node, self.simulation, None,
                GainParameters(manager_node if manager_node is not None else node), reader,
                self.namespace)
            if manager_node is not None:
                startup.serve_controller_manager(
                    node, self.bindings, self.simulation, controllers, settings, RosArguments(),
                    self.namespace, topic_mode=False, is_controller_manager=False,
                    manager_node=manager_node)
                if node.executor is not None:
                    node.executor.add_node(manager_node)
            self.sensors = robot_sensors(node, self.simulation, world, namespace, seed)
        except BaseException:
            self.destroy()
            raise
        host.add_guest(self.simulation)

    def topic(self, *names: str) -> str:
        """Absolute name of a topic of this robot."""
        return naming.join(self.namespace, *names)

    def _manager_node(self, description: RobotDescription,
                      controllers: ControllersConfig) -> Node | None:
        if not startup.has_controller_manager(
                description.model, controllers, is_controller_manager=False) or (
                not optional_interfaces.available('controller_manager_msgs')):
            return None
        from pan_tilt_sim.ros.controller_manager import ControllerManagerNode

        # gz_ros2_control's <controller_manager_name>, else controller_manager.
        self.controller_manager = ControllerManagerNode(
            description.model, self.namespace, context=self._node.context)
        return self.controller_manager

    # --- what sim_node's batches call ------------------------------------------------------

    def flush_joint_states(self) -> None:
        """Publish the samples its state topics took."""
        self.bindings.flush_joint_states()

    def after_steps(self) -> None:
        """Publish what its sensors have due."""
        self.sensors.update()

    def after_batch(self) -> None:
        """After a batch: its controllers' notices and goals."""
        self.bindings.after_steps()

    def steps_until_due(self, step: int) -> int | None:
        """Return how many steps after ``step`` a watched sensor is due (None: none)."""
        due = self.sensors.next_step(step)
        return None if due is None else due - step

    def refresh_readers(self) -> None:
        """Let its controllers sample only what is read."""
        self.bindings.refresh_readers()

    def reset(self) -> None:
        """Start its sensors' schedules again."""
        self.sensors.reset()

    def destroy(self, *, release_topics: bool = True) -> None:
        """Take its topics, services and controller manager away, and its body from the world.

        ``release_topics`` False: sim_node itself is going, and its topics with it.
        """
        node = self._node
        if self.bindings is not None:
            if release_topics:
                self.bindings.release()
            else:
                self.bindings.destroy()
        if self.sensors is not None and release_topics:
            self.sensors.destroy(node)
        if self.controller_manager is not None:
            if self.controller_manager.executor is not None:
                self.controller_manager.executor.remove_node(self.controller_manager)
            self.controller_manager.destroy_node()
            self.controller_manager = None
        if self.simulation in self._host.guests:
            self._host.remove_guest(self.simulation)
        else:
            self.simulation.close()
