"""Small steered robots for the steering controller tests, written on the fly.

:func:`steered_urdf` builds a box base whose frame ``base_link`` sits above
the middle of the rear axle (the point upstream's steering odometry tracks),
``WHEELBASE`` behind the front axle:

* ``front='pair'``: two steering joints (revolute about z, +-``STEER_LIMIT``),
  ``front_right_steering_joint`` and ``front_left_steering_joint``, ``TRACK``
  apart, each carrying a wheel on a continuous joint (``front_right_wheel_joint``...);
  ``front='single'``: one ``front_steering_joint`` on the centre line with its
  ``front_wheel_joint``;
* ``rear='pair'``: ``rear_right_wheel_joint`` and ``rear_left_wheel_joint`` on
  the rear axle, ``TRACK`` apart; ``rear='single'``: one ``rear_wheel_joint``
  on the centre line between two frictionless caster balls (``mu1``/``mu2``
  0: they only carry weight).

Every wheel is a cylinder of radius ``WHEEL_RADIUS`` touching the ground with
Gazebo's default friction; resting, ``base_link`` is ``REST_HEIGHT`` above
the ground.  The ``<ros2_control>`` block gives the steering joints a
``position`` command interface and the ``driven`` wheel joints ``velocity``;
the other wheels roll freely.  :func:`write_tricycle` writes the tricycle
whose single front wheel steers and drives (``tricycle_controller``'s robot),
its rear wheels rolling freely.
"""

from __future__ import annotations

import pathlib
import textwrap
from collections.abc import Mapping, Sequence
from typing import Any

import yaml
from mobile_fixtures import caster

WHEEL_RADIUS = 0.05  # m
WHEELBASE = 0.3  # m from the rear axle to the front axle
TRACK = 0.25  # m between the wheels of an axle
AXLE_DROP = 0.025  # m: the axles below the base frame
REST_HEIGHT = AXLE_DROP + WHEEL_RADIUS  # m: the base frame above the ground at rest
STEER_LIMIT = 0.6  # rad either way
CONTROLLER = 'steering_controller'
ACKERMANN = 'ackermann_steering_controller/AckermannSteeringController'
BICYCLE = 'bicycle_steering_controller/BicycleSteeringController'
TRICYCLE = 'tricycle_steering_controller/TricycleSteeringController'
TRICYCLE_CONTROLLER = 'tricycle_controller/TricycleController'
TRICYCLE_NAME = 'tricycle_controller'
INERTIA = '<inertia ixx="0.0002" ixy="0" ixz="0" iyy="0.0004" iyz="0" izz="0.0002"/>'


def _wheel(joint: str, link: str, parent: str, xyz: str) -> str:
    return f'''
      <joint name="{joint}" type="continuous">
        <parent link="{parent}"/><child link="{link}"/>
        <origin xyz="{xyz}"/><axis xyz="0 1 0"/>
        <limit effort="20" velocity="40"/>
      </joint>
      <link name="{link}">
        <inertial><mass value="0.3"/>{INERTIA}</inertial>
        <collision><origin rpy="1.5707963267948966 0 0"/>
          <geometry><cylinder radius="{WHEEL_RADIUS}" length="0.03"/></geometry></collision>
      </link>'''


def _steered_wheel(side: str, y: float) -> str:
    """A steering joint at (WHEELBASE, y) under the base, a knuckle, and its rolling wheel."""
    prefix = f'front_{side}_' if side else 'front_'
    return f'''
      <joint name="{prefix}steering_joint" type="revolute">
        <parent link="base_link"/><child link="{prefix}knuckle"/>
        <origin xyz="{WHEELBASE} {y} -{AXLE_DROP}"/><axis xyz="0 0 1"/>
        <limit lower="-{STEER_LIMIT}" upper="{STEER_LIMIT}" effort="20" velocity="3"/>
      </joint>
      <link name="{prefix}knuckle">
        <inertial><mass value="0.1"/>{INERTIA}</inertial>
      </link>''' + _wheel(f'{prefix}wheel_joint', f'{prefix}wheel', f'{prefix}knuckle', '0 0 0')


def front_steering_joints(front: str) -> list[str]:
    """Return the steering joints of a ``front`` arrangement (right, then left)."""
    return (['front_right_steering_joint', 'front_left_steering_joint'] if front == 'pair'
            else ['front_steering_joint'])


def rear_wheel_joints(rear: str) -> list[str]:
    """Return the rear wheel joints of a ``rear`` arrangement (right, then left)."""
    return (['rear_right_wheel_joint', 'rear_left_wheel_joint'] if rear == 'pair'
            else ['rear_wheel_joint'])


def steered_urdf(front: str = 'pair', rear: str = 'pair', driven: Sequence[str] | None = None,
                 name: str = 'car') -> str:
    """Return the robot's URDF (see the module); ``driven``: default the rear wheels."""
    half = TRACK / 2
    parts = []
    if front == 'pair':
        parts += [_steered_wheel('right', -half), _steered_wheel('left', half)]
    else:
        parts.append(_steered_wheel('', 0.0))
    if rear == 'pair':
        parts += [_wheel('rear_right_wheel_joint', 'rear_right_wheel', 'base_link',
                         f'0 {-half} -{AXLE_DROP}'),
                  _wheel('rear_left_wheel_joint', 'rear_left_wheel', 'base_link',
                         f'0 {half} -{AXLE_DROP}')]
    else:
        parts += [_wheel('rear_wheel_joint', 'rear_wheel', 'base_link', f'0 0 -{AXLE_DROP}'),
                  caster('right_caster', 0, -half, REST_HEIGHT),
                  caster('left_caster', 0, half, REST_HEIGHT)]
    driven = list(driven) if driven is not None else rear_wheel_joints(rear)
    control = ''.join(
        f'<joint name="{joint}"><command_interface name="position"/>'
        '<state_interface name="position"/></joint>' for joint in front_steering_joints(front))
    control += ''.join(
        f'<joint name="{joint}"><command_interface name="velocity"/>'
        '<state_interface name="position"/><state_interface name="velocity"/></joint>'
        for joint in driven)
    return textwrap.dedent(f'''\
        <?xml version="1.0"?>
        <robot name="{name}">
          <link name="base_link">
            <inertial><origin xyz="{WHEELBASE / 2} 0 0"/><mass value="3.0"/>
              <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.04"/></inertial>
            <collision><origin xyz="{WHEELBASE / 2} 0 0"/>
              <geometry><box size="0.3 0.18 0.04"/></geometry></collision>
          </link>
          {''.join(parts)}
          <ros2_control name="{name}" type="system">
            <hardware><plugin>gz_ros2_control/GazeboSimSystem</plugin></hardware>
            {control}
          </ros2_control>
        </robot>
        ''').lstrip()


def steering_parameters(type_name: str = ACKERMANN, **overrides: Any) -> dict[str, Any]:
    """Return the parameters of a ``type_name`` steering controller for its robot."""
    params: dict[str, Any]
    if type_name == ACKERMANN:
        params = {'traction_joints_names': rear_wheel_joints('pair'),
                  'steering_joints_names': front_steering_joints('pair'),
                  'traction_track_width': TRACK, 'traction_wheels_radius': WHEEL_RADIUS}
    elif type_name == TRICYCLE:
        params = {'traction_joints_names': rear_wheel_joints('pair'),
                  'steering_joints_names': front_steering_joints('single'),
                  'traction_track_width': TRACK, 'traction_wheels_radius': WHEEL_RADIUS}
    else:
        params = {'traction_joints_names': rear_wheel_joints('single'),
                  'steering_joints_names': front_steering_joints('single'),
                  'traction_wheel_radius': WHEEL_RADIUS}
    params['wheelbase'] = WHEELBASE
    params.update(overrides)
    return params


# The robot each steering type drives: (front, rear).
ARRANGEMENTS = {ACKERMANN: ('pair', 'pair'), TRICYCLE: ('single', 'pair'),
                BICYCLE: ('single', 'single')}


def steered_controllers(type_name: str, params: Mapping[str, Any],
                        update_rate: int = 100) -> str:
    """Return a ros2_control-style controllers file: broadcaster and ``steering_controller``."""
    return yaml.safe_dump({
        'controller_manager': {'ros__parameters': {
            'update_rate': update_rate,
            'joint_state_broadcaster': {'type': 'joint_state_broadcaster/JointStateBroadcaster'},
            CONTROLLER: {'type': type_name}}},
        CONTROLLER: {'ros__parameters': dict(params)},
    })


def tricycle_controllers(params: Mapping[str, Any] | None = None, update_rate: int = 100) -> str:
    """Return a controllers file: broadcaster and a ``tricycle_controller/TricycleController``."""
    given: dict[str, Any] = {'traction_joint_name': 'front_wheel_joint',
                             'steering_joint_name': 'front_steering_joint',
                             'wheelbase': WHEELBASE, 'wheel_radius': WHEEL_RADIUS}
    given.update(params or {})
    return yaml.safe_dump({
        'controller_manager': {'ros__parameters': {
            'update_rate': update_rate,
            'joint_state_broadcaster': {'type': 'joint_state_broadcaster/JointStateBroadcaster'},
            TRICYCLE_NAME: {'type': TRICYCLE_CONTROLLER}}},
        TRICYCLE_NAME: {'ros__parameters': given},
    })


def write_tricycle(directory: pathlib.Path,
                   params: Mapping[str, Any] | None = None) -> tuple[pathlib.Path, pathlib.Path]:
    """Write the tricycle (its front wheel steers and drives) and a tricycle_controller file."""
    description = directory / 'trike.urdf'
    description.write_text(steered_urdf('single', 'pair', driven=['front_wheel_joint'],
                                        name='trike'), encoding='utf-8')
    controllers = directory / 'trike_controllers.yaml'
    controllers.write_text(tricycle_controllers(params), encoding='utf-8')
    return description, controllers


def write_steered(directory: pathlib.Path, type_name: str = ACKERMANN,
                  params: Mapping[str, Any] | None = None) -> tuple[pathlib.Path, pathlib.Path]:
    """Write the robot ``type_name`` drives and its controllers file; return both paths."""
    front, rear = ARRANGEMENTS[type_name]
    description = directory / 'car.urdf'
    description.write_text(steered_urdf(front, rear), encoding='utf-8')
    controllers = directory / 'car_controllers.yaml'
    controllers.write_text(steered_controllers(
        type_name, params if params is not None else steering_parameters(type_name)),
        encoding='utf-8')
    return description, controllers
