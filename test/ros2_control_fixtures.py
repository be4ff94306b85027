"""A ros2_control robot as its users ship it, in small: xacro, <ros2_control>, plugin, YAMLs.

The shapes are those of public robots (Universal Robots, ros2_control_demos,
urdf_sim_tutorial), written here from scratch:

* :data:`ARM_XACRO` -- a two-link arm on a fixed base, both joints turning
  about z (gravity loads neither), with a ``prefix`` xacro argument, a
  ``<ros2_control>`` block (``joint1``: position and velocity command
  interfaces; ``joint2``: position only) whose gz_ros2_control hardware
  sets ``position_proportional_gain``, and a ``gz_ros2_control-system``
  plugin naming its controllers file in ``<parameters>`` (relative to the
  xacro).  It redefines ``pi``, so xacro warns "redefining global symbol: pi".
* :data:`UR_STYLE_YAML` -- a controller_manager declaring a broadcaster,
  three controllers on the same two joints (a trajectory controller and
  forward velocity / position groups), two vendor controllers and a vendor
  broadcaster, the joints written ``$(var prefix)jointN``.
* :data:`HEAD_YAML` -- a ROS 1 file holding one controller and nothing else.
"""

from __future__ import annotations

import pathlib
import textwrap

CONTROLLERS_FILE = 'arm_controllers.yaml'
ARM_JOINTS = ('joint1', 'joint2')
LINK_LENGTH = 0.4

_LINK = """
  <link name="${{prefix}}{name}">
    <visual><origin xyz="0.2 0 0"/><geometry><box size="0.4 0.04 0.04"/></geometry></visual>
    <inertial><origin xyz="0.2 0 0"/><mass value="1.0"/>
      <inertia ixx="0.0003" ixy="0" ixz="0" iyy="0.0135" iyz="0" izz="0.0135"/></inertial>
  </link>"""

ARM_XACRO = f"""<?xml version="1.0"?>
<robot name="two_link_arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="prefix" default=""/>
  <xacro:arg name="controllers" default="{CONTROLLERS_FILE}"/>
  <xacro:property name="prefix" value="$(arg prefix)"/>
  <xacro:property name="pi" value="3.14159"/>

  <link name="world"/>
  <link name="${{prefix}}base">
    <inertial><mass value="5"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
  </link>
  <joint name="${{prefix}}base_joint" type="fixed">
    <parent link="world"/><child link="${{prefix}}base"/>
  </joint>
  {_LINK.format(name='link1')}
  {_LINK.format(name='link2')}
  <link name="${{prefix}}tool"/>
  <joint name="${{prefix}}joint1" type="revolute">
    <parent link="${{prefix}}base"/><child link="${{prefix}}link1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="${{-pi / 2}}" upper="${{pi / 2}}" effort="50" velocity="2"/>
    <dynamics damping="0.5"/>
  </joint>
  <joint name="${{prefix}}joint2" type="revolute">
    <parent link="${{prefix}}link1"/><child link="${{prefix}}link2"/>
    <origin xyz="{LINK_LENGTH} 0 0.05"/><axis xyz="0 0 1"/>
    <limit lower="${{-pi / 2}}" upper="${{pi / 2}}" effort="50" velocity="2"/>
    <dynamics damping="0.5"/>
  </joint>
  <joint name="${{prefix}}tool_joint" type="fixed">
    <parent link="${{prefix}}link2"/><child link="${{prefix}}tool"/>
    <origin xyz="{LINK_LENGTH} 0 0"/>
  </joint>

  <ros2_control name="TwoLinkArm" type="system">
    <hardware>
      <plugin>gz_ros2_control/GazeboSimSystem</plugin>
      <param name="position_proportional_gain">0.5</param>
    </hardware>
    <joint name="${{prefix}}joint1">
      <command_interface name="position"/>
      <command_interface name="velocity"/>
      <state_interface name="position"/>
      <state_interface name="velocity"/>
    </joint>
    <joint name="${{prefix}}joint2">
      <command_interface name="position"/>
      <state_interface name="position"/>
    </joint>
  </ros2_control>

  <gazebo>
    <plugin filename="gz_ros2_control-system" name="gz_ros2_control::GazeboSimROS2ControlPlugin">
      <parameters>$(arg controllers)</parameters>
    </plugin>
  </gazebo>
</robot>
"""

_GROUP_JOINTS = """
    joints:
      - $(var prefix)joint1
      - $(var prefix)joint2"""

UR_STYLE_YAML = f"""\
controller_manager:
  ros__parameters:
    update_rate: 500  # Hz

    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster

    io_and_status_controller:
      type: acme_controllers/GPIOController

    speed_scaling_state_broadcaster:
      type: acme_controllers/SpeedScalingStateBroadcaster

    joint_trajectory_controller:
      type: joint_trajectory_controller/JointTrajectoryController

    scaled_joint_trajectory_controller:
      type: acme_controllers/ScaledJointTrajectoryController

    forward_velocity_controller:
      type: velocity_controllers/JointGroupVelocityController

    forward_position_controller:
      type: position_controllers/JointGroupPositionController

speed_scaling_state_broadcaster:
  ros__parameters:
    state_publish_rate: 100.0

joint_trajectory_controller:
  ros__parameters:{_GROUP_JOINTS}
    command_interfaces:
      - position
    state_interfaces:
      - position
      - velocity
    state_publish_rate: 100.0
    allow_partial_joints_goal: false
    constraints:
      stopped_velocity_tolerance: 0.2
      goal_time: 0.0

scaled_joint_trajectory_controller:
  ros__parameters:{_GROUP_JOINTS}
    command_interfaces:
      - position

forward_velocity_controller:
  ros__parameters:{_GROUP_JOINTS}
    interface_name: velocity

forward_position_controller:
  ros__parameters:{_GROUP_JOINTS}
"""

# ROS 1 (urdf_sim_tutorial's head.yaml style): `rosparam load head.yaml ns=head`.
HEAD_YAML = """\
type: "position_controllers/JointPositionController"
joint: joint1
"""


def write(folder: pathlib.Path, name: str, text: str) -> pathlib.Path:
    """Write ``text`` to ``folder/name`` and return the path."""
    path = folder / name
    path.write_text(textwrap.dedent(text), encoding='utf-8')
    return path


def write_arm(folder: pathlib.Path, controllers: str = UR_STYLE_YAML) -> pathlib.Path:
    """Write the arm's xacro and, beside it, the controllers file it names; return the xacro."""
    write(folder, CONTROLLERS_FILE, controllers)
    return write(folder, 'two_link_arm.urdf.xacro', ARM_XACRO)
