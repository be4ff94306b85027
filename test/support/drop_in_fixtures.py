"""sim_node in ros2_control_node's place, in-process: the files of a ros2_control_demos-style robot.

* :data:`SPAWNER_YAML` -- example 1's ``rrbot_controllers.yaml`` shape: each
  controller's own section with its ``type``, for spawners' ``--param-file``.
* :data:`MANAGER_YAML` -- the controller manager's own layout (example 15's
  shape): types under ``controller_manager``, parameters in each
  controller's section, given to the control node as ``parameters=[...]``.
* :func:`drop_in_node` -- a SimNode named ``controller_manager`` (as launch's
  ``name='controller_manager'`` names it) on a harness, real_time_factor 0.
"""

from __future__ import annotations

import contextlib
import pathlib
from collections.abc import Iterator

from node_harness import NodeHarness
from rclpy.parameter import Parameter
from ros2_control_fixtures import write, write_arm

from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.ros.sim_node import SimNode

JSB, FORWARD = 'joint_state_broadcaster', 'forward_position_controller'
FORWARD_TYPE = 'forward_command_controller/ForwardCommandController'
JOINTS = ['joint1', 'joint2']

SPAWNER_YAML = f"""\
{JSB}:
  ros__parameters:
    type: joint_state_broadcaster/JointStateBroadcaster
    update_rate: 50  # Hz

{FORWARD}:
  ros__parameters:
    type: {FORWARD_TYPE}
    joints:
      - joint1
      - joint2
    interface_name: position
"""

MANAGER_YAML = f"""\
controller_manager:
  ros__parameters:
    update_rate: 50  # Hz
    {JSB}:
      type: joint_state_broadcaster/JointStateBroadcaster
    {FORWARD}:
      type: {FORWARD_TYPE}

{FORWARD}:
  ros__parameters:
    joints:
      - joint1
      - joint2
    interface_name: position
"""

# Forward command controllers' parameters without the type (a params_file's content).
FORWARD_PARAMETERS_YAML = f"""\
{FORWARD}:
  ros__parameters:
    joints: [joint2]
    interface_name: position
"""


def arm_urdf(folder: pathlib.Path) -> str:
    """Return the two-link arm's URDF as robot_state_publisher gets it: xacro's output."""
    return load_description(write_arm(folder)).urdf_xml


def write_yaml(folder: pathlib.Path, name: str, text: str) -> pathlib.Path:
    """Write a parameter file; return its path."""
    return write(folder, name, text)


@contextlib.contextmanager
def drop_in_node(*ros_args: str, namespace: str | None = None,
                 **parameters) -> Iterator[tuple[NodeHarness, SimNode]]:
    """Run a SimNode named controller_manager with ``ros_args`` (its --ros-args) on a harness."""
    parameters.setdefault('real_time_factor', 0.0)
    harness = NodeHarness()
    try:
        node = harness.add(SimNode(
            context=harness.context, namespace=namespace,
            cli_args=['--ros-args', '-r', '__node:=controller_manager', *ros_args],
            parameter_overrides=[Parameter(name, value=value)
                                 for name, value in parameters.items()]))
        yield harness, node
    finally:
        harness.close()
