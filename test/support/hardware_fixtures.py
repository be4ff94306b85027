"""A small arm whose ``<ros2_control>`` block has sensors and a gpio, written by the tests.

The arm stands on a fixed base: ``shoulder`` (revolute about y, at the base's
top, ``SHOULDER_Z`` up), the ``upper`` arm along +z, ``wrist`` (revolute about
z) at its end carrying the ``hand`` (``HAND_MASS``), a massless ``ft_link``
fixed on the hand and a ``PAYLOAD_MASS`` box fixed below it, its centre of
mass ``PAYLOAD_OFFSET`` along the ft_link's x.  Held at 0, every frame's axes
are the world's.  Its ``<ros2_control>`` block:

* ``ft_sensor`` -- force.x ... torque.z, ``<param name="frame_id">ft_link``:
  the payload's load on the fixed joint above ft_link;
* ``tcp_fts_sensor`` -- the same six interfaces and no frame (as Universal
  Robots declare theirs): the broadcaster's ``frame_id: hand`` places it;
* ``imu_sensor`` -- the ten IMU interfaces, on ``imu_link`` (frame_id);
* ``range_sensor`` -- ``range`` on ``range_link``, ``RANGE_HEIGHT`` above the
  ground and ``RANGE_X`` out on the base, its +x pointing straight down;
* ``tool_pose`` -- position and orientation of ``ft_link`` (frame_id);
* ``thermometer`` -- a ``temperature`` the simulator does not produce
  (initial_value ``TEMPERATURE``);
* gpio ``tool_io`` -- command ``vacuum`` (echoed into the state ``vacuum``,
  initial_value ``VACUUM_START``), and an input ``pressure`` without one.

:data:`CONTROLLERS_YAML` (ros2_control style, 100 Hz) holds each joint at 0
with a forward position group and declares one broadcaster per sensor kind
and a gpio controller.
"""

from __future__ import annotations

import pathlib
import textwrap

import yaml

SHOULDER_Z = 0.3  # m
UPPER_LENGTH = 0.4  # m
UPPER_MASS = 1.0  # kg
HAND_MASS = 0.5  # kg
PAYLOAD_MASS = 2.0  # kg
PAYLOAD_OFFSET = 0.1  # m along the ft_link's x
RANGE_HEIGHT = 0.25  # m above the ground
RANGE_X = 0.3  # m: the range_link along the base's x
TEMPERATURE = 21.5
VACUUM_START = 1.0
UPDATE_RATE = 100.0  # Hz
FT_HEIGHT = SHOULDER_Z + UPPER_LENGTH + 0.05  # m: the ft_link above the world, held at 0


def _inertial(mass: float, z: float = 0.0, x: float = 0.0) -> str:
    return (f'<inertial><origin xyz="{x} 0 {z}"/><mass value="{mass}"/>'
            '<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>')


def _interfaces(*names: str, initial: dict[str, float] | None = None) -> str:
    lines = []
    for name in names:
        value = (initial or {}).get(name)
        if value is None:
            lines.append(f'<state_interface name="{name}"/>')
        else:
            lines.append(f'<state_interface name="{name}"><param name="initial_value">'
                         f'{value}</param></state_interface>')
    return '\n'.join(lines)


WRENCH = ('force.x', 'force.y', 'force.z', 'torque.x', 'torque.y', 'torque.z')
IMU = ('orientation.x', 'orientation.y', 'orientation.z', 'orientation.w',
       'angular_velocity.x', 'angular_velocity.y', 'angular_velocity.z',
       'linear_acceleration.x', 'linear_acceleration.y', 'linear_acceleration.z')
POSE = ('position.x', 'position.y', 'position.z',
        'orientation.x', 'orientation.y', 'orientation.z', 'orientation.w')

ARM_URDF = f"""<?xml version="1.0"?>
<robot name="sensor_arm">
  <link name="world"/>
  <link name="base">{_inertial(5.0)}</link>
  <joint name="base_joint" type="fixed"><parent link="world"/><child link="base"/></joint>
  <link name="upper">{_inertial(UPPER_MASS, UPPER_LENGTH / 2)}</link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/><origin xyz="0 0 {SHOULDER_Z}"/>
    <axis xyz="0 1 0"/><limit lower="-1.5" upper="1.5" effort="200" velocity="2"/>
  </joint>
  <link name="hand">{_inertial(HAND_MASS, 0.02)}</link>
  <joint name="wrist" type="revolute">
    <parent link="upper"/><child link="hand"/><origin xyz="0 0 {UPPER_LENGTH}"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="50" velocity="2"/>
  </joint>
  <link name="ft_link"/>
  <joint name="ft_joint" type="fixed">
    <parent link="hand"/><child link="ft_link"/><origin xyz="0 0 0.05"/>
  </joint>
  <link name="payload">{_inertial(PAYLOAD_MASS, 0.05, PAYLOAD_OFFSET)}</link>
  <joint name="payload_joint" type="fixed">
    <parent link="ft_link"/><child link="payload"/>
  </joint>
  <link name="imu_link"/>
  <joint name="imu_joint" type="fixed">
    <parent link="upper"/><child link="imu_link"/><origin xyz="0 0 0.2"/>
  </joint>
  <link name="range_link"/>
  <joint name="range_joint" type="fixed">
    <parent link="base"/><child link="range_link"/>
    <origin xyz="{RANGE_X} 0 {RANGE_HEIGHT}" rpy="0 1.5707963267948966 0"/>
  </joint>

  <ros2_control name="SensorArm" type="system">
    <hardware><plugin>mock_components/GenericSystem</plugin></hardware>
    <joint name="shoulder">
      <command_interface name="position"/>
      <state_interface name="position"/><state_interface name="velocity"/>
    </joint>
    <joint name="wrist">
      <command_interface name="position"/>
      <state_interface name="position"/><state_interface name="velocity"/>
    </joint>
    <sensor name="ft_sensor">
      {_interfaces(*WRENCH)}
      <param name="frame_id">ft_link</param>
    </sensor>
    <sensor name="tcp_fts_sensor">
      {_interfaces(*WRENCH)}
    </sensor>
    <sensor name="imu_sensor">
      {_interfaces(*IMU)}
      <param name="frame_id">imu_link</param>
    </sensor>
    <sensor name="range_sensor">
      {_interfaces('range')}
      <param name="frame_id">range_link</param>
      <param name="max_range">2.0</param>
    </sensor>
    <sensor name="tool_pose">
      {_interfaces(*POSE)}
      <param name="frame_id">ft_link</param>
    </sensor>
    <sensor name="thermometer">
      {_interfaces('temperature', initial={'temperature': TEMPERATURE})}
    </sensor>
    <gpio name="tool_io">
      <command_interface name="vacuum"/>
      {_interfaces('vacuum', 'pressure', initial={'vacuum': VACUUM_START})}
    </gpio>
  </ros2_control>
</robot>
"""

CONTROLLERS_YAML = f"""\
controller_manager:
  ros__parameters:
    update_rate: {UPDATE_RATE:g}
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster
    arm_controller:
      type: forward_command_controller/ForwardCommandController
    ft_broadcaster:
      type: force_torque_sensor_broadcaster/ForceTorqueSensorBroadcaster
    tcp_broadcaster:
      type: force_torque_sensor_broadcaster/ForceTorqueSensorBroadcaster
    imu_broadcaster:
      type: imu_sensor_broadcaster/IMUSensorBroadcaster
    range_broadcaster:
      type: range_sensor_broadcaster/RangeSensorBroadcaster
    pose_broadcaster:
      type: pose_broadcaster/PoseBroadcaster
    gpio_controller:
      type: gpio_controllers/GpioCommandController

arm_controller:
  ros__parameters:
    joints: [shoulder, wrist]
    interface_name: position

ft_broadcaster:
  ros__parameters:
    sensor_name: ft_sensor
    frame_id: ft_link

tcp_broadcaster:
  ros__parameters:
    sensor_name: tcp_fts_sensor
    frame_id: hand

imu_broadcaster:
  ros__parameters:
    sensor_name: imu_sensor
    frame_id: imu_link

range_broadcaster:
  ros__parameters:
    sensor_name: range_sensor
    frame_id: range_link

pose_broadcaster:
  ros__parameters:
    pose_name: tool_pose
    frame_id: world

gpio_controller:
  ros__parameters:
    gpios: [tool_io]
    command_interfaces:
      tool_io:
        - interfaces: [vacuum]
"""


def write_sensor_arm(folder: pathlib.Path, urdf: str = ARM_URDF,
                     controllers: str = CONTROLLERS_YAML) -> tuple[pathlib.Path, pathlib.Path]:
    """Write the arm's URDF and controllers file into ``folder``; return their paths."""
    urdf_path = folder / 'sensor_arm.urdf'
    urdf_path.write_text(textwrap.dedent(urdf), encoding='utf-8')
    controllers_path = folder / 'sensor_arm_controllers.yaml'
    controllers_path.write_text(controllers, encoding='utf-8')
    return urdf_path, controllers_path


def controllers_without(*names: str) -> str:
    """Return :data:`CONTROLLERS_YAML` without the controllers ``names``."""
    document = yaml.safe_load(CONTROLLERS_YAML)
    for name in names:
        del document['controller_manager']['ros__parameters'][name]
        document.pop(name, None)
    return yaml.safe_dump(document, sort_keys=False)
