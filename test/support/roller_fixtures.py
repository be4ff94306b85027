"""Small mecanum and omni bases for the roller-wheel tests, written on the fly.

:func:`mecanum_urdf` is a box base on four mecanum wheels (continuous
joints about y, at x = +-``MECANUM_LX``, y = +-``MECANUM_LY``, radius
``WHEEL_RADIUS``, sphere collisions); :func:`mecanum_controllers` a
controllers file with a joint_state_broadcaster and a
``mecanum_drive_controller/MecanumDriveController`` named ``base_controller``.
:func:`omni_urdf` is a round base on ``OMNI_WHEELS`` omni wheels, wheel
``i`` at angle ``2 pi i / n`` from x, ``OMNI_RADIUS`` from the centre,
its axis pointing away from the centre; :func:`omni_controllers` drives it
with an ``omni_wheel_drive_controller/OmniWheelDriveController``.
Resting on the ground, both base frames are ``REST_HEIGHT`` above it.
"""

from __future__ import annotations

import math
import pathlib
import textwrap
from collections.abc import Mapping
from typing import Any

import yaml

WHEEL_RADIUS = 0.05  # m
AXLE_DROP = 0.03  # m: the axles below the base frame
REST_HEIGHT = AXLE_DROP + WHEEL_RADIUS
MECANUM_LX, MECANUM_LY = 0.15, 0.17  # m: the wheels' centres from the base's centre
MECANUM_WHEELS = ('front_left', 'front_right', 'rear_right', 'rear_left')
OMNI_WHEELS = 3
OMNI_RADIUS = 0.15  # m
CONTROLLER = 'base_controller'
MECANUM = 'mecanum_drive_controller/MecanumDriveController'
OMNI = 'omni_wheel_drive_controller/OmniWheelDriveController'


def _wheel(name: str, x: float, y: float, yaw: float) -> str:
    return f'''
      <joint name="{name}_joint" type="continuous">
        <parent link="base_link"/><child link="{name}"/>
        <origin xyz="{x!r} {y!r} -{AXLE_DROP}" rpy="0 0 {yaw!r}"/><axis xyz="0 1 0"/>
        <limit effort="20" velocity="40"/>
      </joint>
      <link name="{name}">
        <inertial><mass value="0.3"/>
          <inertia ixx="0.0002" ixy="0" ixz="0" iyy="0.0004" iyz="0" izz="0.0002"/></inertial>
        <collision><geometry><sphere radius="{WHEEL_RADIUS}"/></geometry></collision>
      </link>'''


def _ros2_control(joints: list[str]) -> str:
    entries = ''.join(f'<joint name="{joint}"><command_interface name="velocity"/>'
                      '<state_interface name="position"/><state_interface name="velocity"/>'
                      '</joint>' for joint in joints)
    return ('<ros2_control name="base" type="system"><hardware>'
            f'<plugin>gz_ros2_control/GazeboSimSystem</plugin></hardware>{entries}'
            '</ros2_control>')


def _robot(name: str, body: str, wheels: str, joints: list[str], extra: str = '') -> str:
    return textwrap.dedent(f'''\
        <?xml version="1.0"?>
        <robot name="{name}">
          <link name="base_link">
            <inertial><mass value="6.0"/>
              <inertia ixx="0.05" ixy="0" ixz="0" iyy="0.08" iyz="0" izz="0.12"/></inertial>
            <collision><geometry>{body}</geometry></collision>
          </link>
          {wheels}
          {_ros2_control(joints)}
          {extra}
        </robot>
        ''').lstrip()


def mecanum_joints() -> list[str]:
    """Return the mecanum wheels' joints: front left, front right, rear right, rear left."""
    return [f'{wheel}_wheel_joint' for wheel in MECANUM_WHEELS]


def mecanum_urdf(name: str = 'mecanum', friction: float | None = None) -> str:
    """Return the four-wheel mecanum base (every axis along the base's y).

    ``friction``: the wheels' ``<mu1>``/``<mu2>`` (None: none given, Gazebo's 1).
    """
    places = {'front_left': (MECANUM_LX, MECANUM_LY), 'front_right': (MECANUM_LX, -MECANUM_LY),
              'rear_right': (-MECANUM_LX, -MECANUM_LY), 'rear_left': (-MECANUM_LX, MECANUM_LY)}
    wheels = ''.join(_wheel(f'{wheel}_wheel', x, y, 0.0) for wheel, (x, y) in places.items())
    surfaces = '' if friction is None else ''.join(
        f'<gazebo reference="{wheel}_wheel"><mu1>{friction}</mu1><mu2>{friction}</mu2></gazebo>'
        for wheel in MECANUM_WHEELS)
    return _robot(name, '<box size="0.4 0.3 0.04"/>', wheels, mecanum_joints(), surfaces)


def mecanum_parameters(**overrides: Any) -> dict[str, Any]:
    """Return the mecanum controller's parameters for :func:`mecanum_urdf`, with ``overrides``."""
    params: dict[str, Any] = {
        f'{wheel}_wheel_command_joint_name': f'{wheel}_wheel_joint' for wheel in MECANUM_WHEELS}
    params['kinematics'] = {'wheels_radius': WHEEL_RADIUS,
                            'sum_of_robot_center_projection_on_X_Y_axis': MECANUM_LX + MECANUM_LY}
    params['reference_timeout'] = 0.5
    params.update(overrides)
    return params


def omni_joints() -> list[str]:
    """Return the omni wheels' joints, anticlockwise from the one on the x axis."""
    return [f'wheel_{index}_joint' for index in range(OMNI_WHEELS)]


def omni_urdf(name: str = 'omni') -> str:
    """Return the omni base: wheel i at angle 2 pi i / n, its axis pointing outwards."""
    wheels = ''
    for index in range(OMNI_WHEELS):
        angle = 2.0 * math.pi * index / OMNI_WHEELS
        # The joint's y axis turned to point outwards: yaw = angle - pi / 2.
        wheels += _wheel(f'wheel_{index}', OMNI_RADIUS * math.cos(angle),
                         OMNI_RADIUS * math.sin(angle), angle - math.pi / 2.0)
    return _robot(name, f'<cylinder radius="{OMNI_RADIUS - 0.03}" length="0.04"/>', wheels,
                  omni_joints())


def omni_parameters(**overrides: Any) -> dict[str, Any]:
    """Return the omni controller's parameters for :func:`omni_urdf`, with ``overrides``."""
    params: dict[str, Any] = {'wheel_names': omni_joints(), 'robot_radius': OMNI_RADIUS,
                              'wheel_radius': WHEEL_RADIUS, 'wheel_offset': 0.0}
    params.update(overrides)
    return params


def controllers_file(kind: str, drive: Mapping[str, Any], update_rate: int = 100) -> str:
    """Return a controllers file: broadcaster and ``base_controller`` of type ``kind``."""
    return yaml.safe_dump({
        'controller_manager': {'ros__parameters': {
            'update_rate': update_rate,
            'joint_state_broadcaster': {'type': 'joint_state_broadcaster/JointStateBroadcaster'},
            CONTROLLER: {'type': kind}}},
        CONTROLLER: {'ros__parameters': dict(drive)},
    })


def write_mecanum(directory: pathlib.Path, drive: Mapping[str, Any] | None = None,
                  friction: float | None = None) -> tuple[pathlib.Path, pathlib.Path]:
    """Write the mecanum base's URDF and controllers file into ``directory``; return both."""
    description = directory / 'mecanum.urdf'
    description.write_text(mecanum_urdf(friction=friction), encoding='utf-8')
    controllers = directory / 'mecanum_controllers.yaml'
    controllers.write_text(controllers_file(
        MECANUM, drive if drive is not None else mecanum_parameters()), encoding='utf-8')
    return description, controllers


def write_omni(directory: pathlib.Path,
               drive: Mapping[str, Any] | None = None) -> tuple[pathlib.Path, pathlib.Path]:
    """Write the omni base's URDF and controllers file into ``directory``; return both."""
    description = directory / 'omni.urdf'
    description.write_text(omni_urdf(), encoding='utf-8')
    controllers = directory / 'omni_controllers.yaml'
    controllers.write_text(controllers_file(
        OMNI, drive if drive is not None else omni_parameters()), encoding='utf-8')
    return description, controllers
