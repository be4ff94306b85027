"""A small differential-drive robot for the mobile-base tests, written on the fly.

:func:`rover_urdf` is a box base on two driven wheels (continuous joints
about y, at ``WHEEL_SEPARATION`` apart, radius ``WHEEL_RADIUS``) and one
frictionless caster ball behind them (its ``<gazebo reference>`` sets
``mu1``/``mu2`` to 0, so it only carries weight).  The wheels' and the
caster's lowest points are ``REST_HEIGHT`` below the base frame: resting on
the ground, the base frame is at z = ``REST_HEIGHT``.  :func:`rover_controllers`
is a ros2_control-style controllers file with a joint_state_broadcaster and
a ``diff_drive_controller/DiffDriveController`` named ``base_controller``.
:func:`plugin_rover_urdf` is the same rover driven by a
``libgazebo_ros_diff_drive.so`` plugin instead (no ros2_control, no
controllers file), with a planar lidar (``<sensor type="ray">`` on a
``lidar_link`` above the base) publishing a LaserScan on ``/scan`` and a
``libgazebo_ros_p3d.so`` publishing the base's true pose on ``/ground_truth``
and a ``libgazebo_ros_joint_state_publisher.so`` of the wheels.
"""

from __future__ import annotations

import pathlib
import textwrap
from collections.abc import Mapping
from typing import Any

import yaml

WHEEL_RADIUS = 0.05  # m
WHEEL_SEPARATION = 0.3  # m between the wheels' mid-planes
AXLE_DROP = 0.025  # m: the axle below the base frame
REST_HEIGHT = AXLE_DROP + WHEEL_RADIUS  # m: the base frame above the ground at rest
CASTER_RADIUS = 0.025  # m
CONTROLLER = 'base_controller'
DIFF_DRIVE = 'diff_drive_controller/DiffDriveController'


def _wheel(side: str, y: float) -> str:
    return f'''
      <joint name="{side}_wheel_joint" type="continuous">
        <parent link="base_link"/><child link="{side}_wheel"/>
        <origin xyz="0.05 {y} -{AXLE_DROP}"/><axis xyz="0 1 0"/>
        <limit effort="20" velocity="30"/>
      </joint>
      <link name="{side}_wheel">
        <inertial><mass value="0.3"/>
          <inertia ixx="0.0002" ixy="0" ixz="0" iyy="0.0004" iyz="0" izz="0.0002"/></inertial>
        <collision><origin rpy="1.5707963267948966 0 0"/>
          <geometry><cylinder radius="{WHEEL_RADIUS}" length="0.03"/></geometry></collision>
      </link>'''


def caster(name: str, x: float, y: float, rest_height: float) -> str:
    """Return a frictionless caster ball ``name`` on ``base_link`` at (``x``, ``y``).

    Its joint is ``<name>_joint``; its lowest point is ``rest_height`` below
    ``base_link`` (on the ground at rest); ``mu1``/``mu2`` 0: it only carries weight.
    """
    return f'''
      <joint name="{name}_joint" type="fixed">
        <parent link="base_link"/><child link="{name}"/>
        <origin xyz="{x} {y} -{rest_height - CASTER_RADIUS}"/>
      </joint>
      <link name="{name}">
        <inertial><mass value="0.1"/>
          <inertia ixx="0.00003" ixy="0" ixz="0" iyy="0.00003" iyz="0" izz="0.00003"/>
        </inertial>
        <collision><geometry><sphere radius="{CASTER_RADIUS}"/></geometry></collision>
      </link>
      <gazebo reference="{name}"><mu1>0.0</mu1><mu2>0.0</mu2></gazebo>'''


ROS2_DIFF_DRIVE = f'''
  <plugin name="diff_drive" filename="libgazebo_ros_diff_drive.so">
    <left_joint>left_wheel_joint</left_joint><right_joint>right_wheel_joint</right_joint>
    <wheel_separation>{WHEEL_SEPARATION}</wheel_separation>
    <wheel_diameter>{2 * WHEEL_RADIUS}</wheel_diameter>
    <max_wheel_torque>20</max_wheel_torque>
    <max_wheel_acceleration>1.0</max_wheel_acceleration>
    <publish_odom>true</publish_odom><publish_odom_tf>true</publish_odom_tf>
    <odometry_frame>odom</odometry_frame><robot_base_frame>base_link</robot_base_frame>
    <odometry_source>0</odometry_source>
  </plugin>'''
ROS1_DIFF_DRIVE = f'''
  <plugin name="differential_drive_controller" filename="libgazebo_ros_diff_drive.so">
    <leftJoint>left_wheel_joint</leftJoint><rightJoint>right_wheel_joint</rightJoint>
    <wheelSeparation>{WHEEL_SEPARATION}</wheelSeparation>
    <wheelDiameter>{2 * WHEEL_RADIUS}</wheelDiameter>
    <wheelTorque>20</wheelTorque>
    <commandTopic>cmd_vel</commandTopic><odometryTopic>odom</odometryTopic>
    <odometryFrame>odom</odometryFrame><robotBaseFrame>base_link</robotBaseFrame>
    <odometrySource>encoder</odometrySource>
  </plugin>'''
P3D = '''
  <plugin name="ground_truth" filename="libgazebo_ros_p3d.so">
    <ros><remapping>odom:=ground_truth</remapping></ros>
    <body_name>base_link</body_name><frame_name>world</frame_name>
    <update_rate>50</update_rate>
  </plugin>'''
JOINT_STATES = '''
  <plugin name="joint_states" filename="libgazebo_ros_joint_state_publisher.so">
    <joint_name>left_wheel_joint</joint_name><joint_name>right_wheel_joint</joint_name>
    <update_rate>50</update_rate>
  </plugin>'''
PLANAR_MOVE = '''
  <plugin name="planar_move" filename="libgazebo_ros_planar_move.so">
    <update_rate>100</update_rate><publish_rate>100</publish_rate>
    <odometry_frame>odom</odometry_frame><robot_base_frame>base_link</robot_base_frame>
  </plugin>'''
GZ_DIFF_DRIVE = f'''
  <plugin filename="gz-sim-diff-drive-system" name="gz::sim::systems::DiffDrive">
    <left_joint>left_wheel_joint</left_joint><right_joint>right_wheel_joint</right_joint>
    <wheel_separation>{WHEEL_SEPARATION}</wheel_separation>
    <wheel_radius>{WHEEL_RADIUS}</wheel_radius>
    <odom_publish_frequency>100</odom_publish_frequency>
    <max_linear_acceleration>1.0</max_linear_acceleration>
    <min_linear_acceleration>-1.0</min_linear_acceleration>
  </plugin>'''
GZ_ODOMETRY = '''
  <plugin filename="gz-sim-odometry-publisher-system"
          name="gz::sim::systems::OdometryPublisher">
    <odom_frame>odom</odom_frame><robot_base_frame>base_link</robot_base_frame>
    <odom_topic>ground_truth</odom_topic><odom_publish_frequency>50</odom_publish_frequency>
  </plugin>'''
GZ_JOINT_STATES = '''
  <plugin filename="gz-sim-joint-state-publisher-system"
          name="gz::sim::systems::JointStatePublisher">
    <topic>joint_states</topic>
  </plugin>'''
LIDAR = '''
  <joint name="lidar_joint" type="fixed">
    <parent link="base_link"/><child link="lidar_link"/><origin xyz="0.1 0 0.05"/>
  </joint>
  <link name="lidar_link">
    <inertial><mass value="0.05"/>
      <inertia ixx="0.00001" ixy="0" ixz="0" iyy="0.00001" iyz="0" izz="0.00001"/></inertial>
  </link>
  <gazebo reference="lidar_link">
    <sensor type="ray" name="lidar">
      <update_rate>10</update_rate>
      <ray><scan><horizontal><samples>90</samples><resolution>1</resolution>
        <min_angle>-1.5708</min_angle><max_angle>1.5708</max_angle></horizontal></scan>
        <range><min>0.05</min><max>8.0</max></range></ray>
      <plugin name="scan" filename="libgazebo_ros_ray_sensor.so">
        <ros><remapping>~/out:=scan</remapping></ros>
        <output_type>sensor_msgs/LaserScan</output_type>
      </plugin>
    </sensor>
  </gazebo>'''


def plugin_rover_urdf(plugin: str = ROS2_DIFF_DRIVE, name: str = 'rover', *,
                      ground_truth: str = P3D, joint_states: str = JOINT_STATES) -> str:
    """Return the rover driven by a Gazebo diff drive ``plugin`` (no ros2_control), a lidar.

    ``ground_truth`` (a p3d plugin on ``/ground_truth`` by default) and
    ``joint_states`` (a joint state publisher of both wheels on ``/joint_states``)
    go beside the drive.
    """
    return rover_urdf(name, ros2_control=False,
                      extra=f'<gazebo>{plugin}{ground_truth}{joint_states}</gazebo>{LIDAR}')


def rover_urdf(name: str = 'rover', *, world_joint: bool = False,
               footprint: bool = False, ros2_control: bool = True, extra: str = '') -> str:
    """Return the rover's URDF.

    ``world_joint`` hangs it on a ``world`` link by a fixed joint; ``footprint``
    on a massless ``base_footprint`` root on the ground, ``REST_HEIGHT`` below
    ``base_link``.  ``ros2_control`` False leaves out the ``<ros2_control>``
    block; ``extra`` is inserted before the end of the robot.
    """
    world = ('<link name="world"/><joint name="world_joint" type="fixed">'
             '<parent link="world"/><child link="base_link"/></joint>') if world_joint else ''
    if footprint:
        world += ('<link name="base_footprint"/><joint name="footprint_joint" type="fixed">'
                  '<parent link="base_footprint"/><child link="base_link"/>'
                  f'<origin xyz="0 0 {REST_HEIGHT}"/></joint>')
    half = WHEEL_SEPARATION / 2
    return textwrap.dedent(f'''\
        <?xml version="1.0"?>
        <robot name="{name}">
          {world}
          <link name="base_link">
            <inertial><mass value="3.0"/>
              <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial>
            <collision><geometry><box size="0.3 0.2 0.04"/></geometry></collision>
          </link>
          {_wheel('left', half)}
          {_wheel('right', -half)}
          {caster('caster', -0.1, 0, REST_HEIGHT)}
          <gazebo reference="left_wheel"><mu1>1.0</mu1><mu2>1.0</mu2></gazebo>
          {_ROS2_CONTROL if ros2_control else ''}
          {extra}
        </robot>
        ''').lstrip()


_ROS2_CONTROL = '''<ros2_control name="rover" type="system">
            <hardware><plugin>gz_ros2_control/GazeboSimSystem</plugin></hardware>
            <joint name="left_wheel_joint"><command_interface name="velocity"/>
              <state_interface name="position"/><state_interface name="velocity"/></joint>
            <joint name="right_wheel_joint"><command_interface name="velocity"/>
              <state_interface name="position"/><state_interface name="velocity"/></joint>
          </ros2_control>'''


def drive_parameters(**overrides: Any) -> dict[str, Any]:
    """Return the diff drive controller's parameters for the rover, with ``overrides``."""
    params: dict[str, Any] = {
        'left_wheel_names': ['left_wheel_joint'], 'right_wheel_names': ['right_wheel_joint'],
        'wheel_separation': WHEEL_SEPARATION, 'wheel_radius': WHEEL_RADIUS}
    params.update(overrides)
    return params


def rover_controllers(drive: Mapping[str, Any] | None = None, update_rate: int = 100) -> str:
    """Return a ros2_control-style controllers file: broadcaster and ``base_controller``."""
    return yaml.safe_dump({
        'controller_manager': {'ros__parameters': {
            'update_rate': update_rate,
            'joint_state_broadcaster': {'type': 'joint_state_broadcaster/JointStateBroadcaster'},
            CONTROLLER: {'type': DIFF_DRIVE}}},
        CONTROLLER: {'ros__parameters': dict(drive if drive is not None else drive_parameters())},
    })


def write_rover(directory: pathlib.Path, drive: Mapping[str, Any] | None = None,
                **urdf: Any) -> tuple[pathlib.Path, pathlib.Path]:
    """Write the rover's URDF and controllers file into ``directory``; return both paths."""
    description = directory / 'rover.urdf'
    description.write_text(rover_urdf(**urdf), encoding='utf-8')
    controllers = directory / 'rover_controllers.yaml'
    controllers.write_text(rover_controllers(drive), encoding='utf-8')
    return description, controllers
