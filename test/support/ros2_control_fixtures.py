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
* :func:`three_dof_urdf` and :data:`THREE_DOF_YAML` -- ros2_control_demos
  example 13's ThreeDofBot in small: three joints whose mock hardware
  declares ``position`` and ``pid_gain`` command and state interfaces, and
  its controllers -- a global broadcaster under the controller_manager, the
  others typed in their own sections (jazzy's way): a local broadcaster of
  ``position`` and ``pid_gain``, a position group and a ``pid_gain`` group.
  :func:`three_dof_launch` -- its launch file's shape, sim_node as the
  control node and the ``--inactive`` spawner of
  ``generate_controllers_spawner_launch_description``.
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


THREE_DOF_JOINTS = ('threedofbot_joint1', 'threedofbot_joint2', 'threedofbot_joint3')
PID_GAIN_CONTROLLER = 'threedofbot_pid_gain_controller'
THREE_DOF_ACTIVE = ('joint_state_broadcaster', 'threedofbot_joint_state_broadcaster',
                    'threedofbot_position_controller')


def three_dof_urdf(pid_gain_joints: tuple[str, ...] = THREE_DOF_JOINTS) -> str:
    """Return the three-joint robot; ``pid_gain_joints`` declare the ``pid_gain`` interfaces."""
    from robot_fixtures import JointDef, star_robot_urdf

    entries = ''.join(
        f'<joint name="{joint}"><command_interface name="position">'
        '<param name="min">-1</param><param name="max">1</param></command_interface>'
        '<state_interface name="position"/>'
        + ('<command_interface name="pid_gain"/><state_interface name="pid_gain"/>'
           if joint in pid_gain_joints else '')
        + '</joint>' for joint in THREE_DOF_JOINTS)
    block = ('<ros2_control name="FakeThreeDofBot" type="system"><hardware>'
             f'<plugin>mock_components/GenericSystem</plugin></hardware>{entries}</ros2_control>')
    urdf = star_robot_urdf([JointDef(joint) for joint in THREE_DOF_JOINTS], 'threedofbot')
    return urdf.replace('</robot>', f'{block}</robot>')


def _group(interface: str) -> str:
    return ('    type: forward_command_controller/ForwardCommandController\n    joints:\n'
            + ''.join(f'      - {joint}\n' for joint in THREE_DOF_JOINTS)
            + f'    interface_name: {interface}\n')


THREE_DOF_YAML = (
    'controller_manager:\n  ros__parameters:\n    update_rate: 100\n'
    '    joint_state_broadcaster:\n      type: joint_state_broadcaster/JointStateBroadcaster\n'
    '\nthreedofbot_joint_state_broadcaster:\n  ros__parameters:\n'
    '    type: joint_state_broadcaster/JointStateBroadcaster\n    use_local_topics: True\n'
    '    joints:\n' + ''.join(f'      - {joint}\n' for joint in THREE_DOF_JOINTS)
    + '    interfaces:\n      - position\n      - pid_gain\n'
    '\nthreedofbot_position_controller:\n  ros__parameters:\n' + _group('position')
    + f'\n{PID_GAIN_CONTROLLER}:\n  ros__parameters:\n' + _group('pid_gain'))


def three_dof_launch(urdf: pathlib.Path, controllers: pathlib.Path) -> str:
    """Return the launch file's text: its control node, robot_state_publisher, two spawners."""
    return textwrap.dedent(f"""\
        from launch import LaunchDescription
        from launch.substitutions import Command
        from launch_ros.actions import Node
        from controller_manager.launch_utils import (
            generate_controllers_spawner_launch_description)


        def generate_launch_description():
            return LaunchDescription([
                Node(package='pan_tilt_sim', executable='sim_node', name='controller_manager',
                     parameters=['{controllers}', {{'real_time_factor': 0.0}}]),
                Node(package='robot_state_publisher', executable='robot_state_publisher',
                     parameters=[{{'robot_description': Command(['xacro ', '{urdf}'])}}]),
                generate_controllers_spawner_launch_description(
                    ['joint_state_broadcaster'], controller_params_files=['{controllers}']),
                generate_controllers_spawner_launch_description(
                    ['threedofbot_joint_state_broadcaster', 'threedofbot_position_controller',
                     '{PID_GAIN_CONTROLLER}'],
                    controller_params_files=['{controllers}'],
                    extra_spawner_args=['--inactive']),
            ])
        """)
