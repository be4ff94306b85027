"""What launch/pan_tilt.launch.py computes, without the ``launch`` package.

The launch file starts sim_node and, where its package is installed,
robot_state_publisher (and, with ``spawners:=true``, a ros2_control spawner
for the controllers to activate); this module reads the model and controllers once, as
sim_node will, to hand robot_state_publisher the processed URDF and the
joint_states topic in the robot's namespace, and turns the launch arguments
(strings) into sim_node's parameters.  Kept apart so it can be tested where
``launch`` is not installed.

sim_node is started with :data:`~pan_tilt_sim.ros.runner.PARENT_PID_VARIABLE`
set to the launch process's pid: it then stops when that process dies,
however it dies, so a failed or killed launch never leaves it running as an
orphan.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Sequence
from typing import Any

from pan_tilt_sim.model import naming, yaml_input
from pan_tilt_sim.model.controller_config import (
    controllers_files_for,
    load_controllers_config,
    parse_controllers_args,
)
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.model.robot import DEFAULT_CONTROLLER_MANAGER
from pan_tilt_sim.model.topic_based import topic_based_system
from pan_tilt_sim.plugins.registry import runs_by_plugins
from pan_tilt_sim.ros.runner import PARENT_PID_VARIABLE

ROOT_NAMESPACE = '/'
ROBOT_STATE_PUBLISHER = 'robot_state_publisher'
CONTROLLER_MANAGER_PACKAGE = 'controller_manager'  # ros2_control's: it has the spawner
SPAWNER = 'spawner'
TRUE_WORDS = ('true', '1', 'yes', 'on')


@dataclasses.dataclass(frozen=True)
class RobotSetup:
    """The processed URDF, the namespace of the robot's topics and its manager's node name."""

    urdf_xml: str
    namespace: str
    # The control plugin's <controller_manager_name>, as sim_node names its manager.
    manager: str = DEFAULT_CONTROLLER_MANAGER

    def topic(self, *names: str) -> str:
        """Absolute name of a topic of the robot."""
        return naming.join(self.namespace, *names)


def list_argument(text: str) -> list[str]:
    """Read a list-valued launch argument.

    Either a YAML list, as ``-p`` takes it (``"['ur_type:=ur5e', 'name:=ur5e']"``,
    ``[joint_state_broadcaster, joint_trajectory_controller]``), or items
    separated by spaces or commas (``"ur_type:=ur5e name:=ur5e"``).  Empty: [].
    """
    text = text.strip()
    if text.startswith('['):
        try:
            items = yaml_input.load(text)
        except yaml_input.YamlInputError:
            items = None
        if isinstance(items, list):
            return [str(item) for item in items]
    return text.replace(',', ' ').split()


def bool_argument(text: str) -> bool:
    """Read a boolean launch argument (true/1/yes/on, any case)."""
    return text.strip().lower() in TRUE_WORDS


def has_package(name: str) -> bool:
    """Whether the ament index knows package ``name`` (so ``launch_ros`` can start it)."""
    from ament_index_python.packages import PackageNotFoundError, get_package_prefix

    try:
        get_package_prefix(name)
    except (PackageNotFoundError, ValueError, LookupError, OSError):
        return False
    return True


def robot_setup(model: str, controllers: str = '', xacro_args: Sequence[str] = (),
                robot_namespace: str = '',
                controllers_args: Sequence[str] = ()) -> RobotSetup:
    """Load the model and controllers as sim_node does (in the root namespace)."""
    description = load_description(model, xacro_args)
    manager = description.model.controller_manager_name
    controllers_namespace = None
    if topic_based_system(description.model) is None:  # topic-based hardware runs no YAML
        files = controllers_files_for(controllers, description,
                                      given_as="the launch argument 'controllers'",
                                      runs_by_plugins=runs_by_plugins(description.model))
        config = load_controllers_config(
            files, parse_controllers_args(controllers_args, "launch argument 'controllers_args'"),
            args_name="the launch argument 'controllers_args'", manager=manager)
        controllers_namespace = config.namespace
    namespace = naming.resolve_robot_namespace(
        ROOT_NAMESPACE, robot_namespace, controllers_namespace, description.plugin_namespace)
    return RobotSetup(description.urdf_xml, namespace, manager)


def sim_node_parameters(model: str, controllers: str, *, real_time_factor: float,
                        world: str, gui: bool, xacro_args: Sequence[str] = (),
                        controllers_args: Sequence[str] = (),
                        active_controllers: Sequence[str] = (),
                        time_step: float | None = None, robot_namespace: str = '',
                        publish_tf: bool = False, spawners: bool = False,
                        paused: bool = False, fixed_base: str = 'auto',
                        initial_pose: Sequence[str] = ()) -> dict[str, Any]:
    """Return sim_node's parameters.

    With robot_state_publisher beside it (``publish_tf`` False), that node
    turns joint_states into TF and sim_node publishes none; without it
    sim_node publishes TF itself.  sim_node keeps use_sim_time off: it is
    the clock (it publishes /clock).  Empty lists and an empty controllers
    file are left out (sim_node's defaults: none, and the file the URDF names).
    With ``spawners`` no controller starts: ros2_control's spawners load and
    activate them (``autostart_controllers`` false; ``active_controllers`` are
    then the spawners' business, see :func:`spawner_arguments`).
    ``fixed_base`` other than ``auto`` and an ``initial_pose`` (four numbers,
    as text: x y z yaw) are passed on; sim_node checks them.
    """
    parameters: dict[str, Any] = {
        'robot_description_file': model,
        'real_time_factor': real_time_factor,
        'world': world,
        'gui': gui,
        'publish_tf': publish_tf,
    }
    if spawners:
        parameters['autostart_controllers'] = False
        active_controllers = ()
    if controllers:
        parameters['controllers_file'] = controllers
    for name, values in (('xacro_args', xacro_args), ('controllers_args', controllers_args),
                         ('active_controllers', active_controllers)):
        if values:
            parameters[name] = list(values)
    if time_step is not None:
        parameters['time_step'] = time_step
    if robot_namespace:
        parameters['robot_namespace'] = robot_namespace
    if paused:  # start paused (STOPPED): spawners and tests connect before time moves
        parameters['paused'] = True
    if fixed_base != 'auto':
        parameters['fixed_base'] = fixed_base
    if initial_pose:
        try:
            parameters['initial_pose'] = [float(value) for value in initial_pose]
        except ValueError:
            raise ValueError(f"launch argument 'initial_pose': {' '.join(initial_pose)!r} is "
                             'not four numbers x y z yaw') from None
    return parameters


def controller_manager_name(setup: RobotSetup) -> str:
    """Return sim_node's controller_manager in the robot's namespace.

    Named as gz_ros2_control names it: the plugin's ``<controller_manager_name>``,
    else ``controller_manager``.
    """
    return setup.topic(setup.manager)


def spawner_arguments(setup: RobotSetup, controllers: Sequence[str]) -> list[str]:
    """Return the arguments of one ros2_control spawner that activates ``controllers`` in order.

    The controller_manager is named absolutely, so the spawner needs no namespace.
    """
    return [*controllers, '--controller-manager', controller_manager_name(setup)]


def sim_node_environment() -> dict[str, str]:
    """Return what sim_node's environment adds: this (the launch) process's pid as its parent."""
    return {PARENT_PID_VARIABLE: str(os.getpid())}


def robot_state_publisher_parameters(setup: RobotSetup) -> dict[str, Any]:
    """Return robot_state_publisher's parameters: the URDF, on sim time."""
    return {'robot_description': setup.urdf_xml, 'use_sim_time': True}
