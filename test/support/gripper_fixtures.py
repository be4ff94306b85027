"""A small arm with a parallel gripper, and a box to grasp, written for the tests.

:func:`gripper_urdf` -- a fixed base; ``lift_joint`` (prismatic along z,
0..0.3 m) carries a massive carriage, which carries two fingers, each a
prismatic joint sliding along y: ``left_finger_joint`` is commanded and
``right_finger_joint`` mimics it (multiplier 1, axis -y), as Franka's hand
does.  A finger's position is the distance of its inner face from the
middle, so a box of width ``w`` stops both at ``w / 2``.  The fingers reach
down to :data:`FINGER_BOTTOM` above the ground, and their surfaces say
``<mu1>``/``<mu2>`` (:data:`FINGER_MU`) in ``<gazebo reference>`` blocks.
The ``<ros2_control>`` block gives the left finger ``position``, ``effort``
and ``max_effort`` command interfaces.

:func:`controllers_yaml` -- a broadcaster, a position controller on the
lift and one gripper controller of the given type and parameters.
:func:`grasp_box_urdf` -- the box, with surface friction tags if asked for.
"""

from __future__ import annotations

import pathlib
from typing import Any

import yaml

FINGER_JOINT = 'left_finger_joint'
MIMIC_JOINT = 'right_finger_joint'
LIFT_JOINT = 'lift_joint'
FINGER_OPEN = 0.05  # m: the upper limit of each finger
FINGER_EFFORT_LIMIT = 40.0  # N
FINGER_VELOCITY_LIMIT = 0.2  # m/s
FINGER_MU = 2.0
FINGER_BOTTOM = 0.005  # m above the ground at lift 0
FINGER_HEIGHT = 0.06
CARRIAGE_HEIGHT = FINGER_BOTTOM + FINGER_HEIGHT  # the carriage origin's z at lift 0
BOX_SIZE = 0.04  # m: a cube
BOX_MASS = 0.2  # kg


def _finger(name: str, side: float) -> str:
    """A finger link whose inner face is at its joint's origin, ``side`` saying which way is out."""
    return f"""
  <link name="{name}">
    <inertial><origin xyz="0 {side * 0.005} {-FINGER_HEIGHT / 2}"/><mass value="0.05"/>
      <inertia ixx="2e-5" ixy="0" ixz="0" iyy="2e-5" iyz="0" izz="2e-6"/></inertial>
    <collision><origin xyz="0 {side * 0.005} {-FINGER_HEIGHT / 2}"/>
      <geometry><box size="0.03 0.01 {FINGER_HEIGHT}"/></geometry></collision>
  </link>
  <gazebo reference="{name}"><mu1>{FINGER_MU}</mu1><mu2>{FINGER_MU}</mu2></gazebo>"""


def gripper_urdf(*, finger_mu: bool = True) -> str:
    """Return the arm's URDF (``finger_mu`` False: the fingers' friction tags left out)."""
    fingers = _finger('left_finger', 1.0) + _finger('right_finger', -1.0)
    if not finger_mu:
        fingers = '\n'.join(line for line in fingers.splitlines() if '<gazebo' not in line)
    return f"""<?xml version="1.0"?>
<robot name="gripper_arm">
  <link name="base_link"><inertial><mass value="10"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="carriage"><inertial><mass value="1.0"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
  <joint name="{LIFT_JOINT}" type="prismatic">
    <parent link="base_link"/><child link="carriage"/>
    <origin xyz="0 0 {CARRIAGE_HEIGHT}"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0.3" effort="200" velocity="0.2"/>
  </joint>
  {fingers}
  <joint name="{FINGER_JOINT}" type="prismatic">
    <parent link="carriage"/><child link="left_finger"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="{FINGER_OPEN}" effort="{FINGER_EFFORT_LIMIT}"
           velocity="{FINGER_VELOCITY_LIMIT}"/>
  </joint>
  <joint name="{MIMIC_JOINT}" type="prismatic">
    <parent link="carriage"/><child link="right_finger"/><axis xyz="0 -1 0"/>
    <limit lower="0" upper="{FINGER_OPEN}" effort="{FINGER_EFFORT_LIMIT}"
           velocity="{FINGER_VELOCITY_LIMIT}"/>
    <mimic joint="{FINGER_JOINT}" multiplier="1" offset="0"/>
  </joint>
  <ros2_control name="GripperArm" type="system">
    <hardware><plugin>gz_ros2_control/GazeboSimSystem</plugin></hardware>
    <joint name="{LIFT_JOINT}">
      <command_interface name="position"/>
      <state_interface name="position"/><state_interface name="velocity"/>
    </joint>
    <joint name="{FINGER_JOINT}">
      <command_interface name="position"/>
      <command_interface name="effort"/>
      <command_interface name="max_effort"/>
      <state_interface name="position"/><state_interface name="velocity"/>
    </joint>
  </ros2_control>
</robot>
"""


def controllers_yaml(gripper_type: str = 'position_controllers/GripperActionController',
                     **gripper: Any) -> str:
    """Return a ros2_control YAML: broadcaster, ``lift_controller``, ``gripper_controller``."""
    return yaml.safe_dump({
        'controller_manager': {'ros__parameters': {
            'update_rate': 100,
            'joint_state_broadcaster': {'type': 'joint_state_broadcaster/JointStateBroadcaster'},
            'lift_controller': {'type': 'position_controllers/JointPositionController'},
            'gripper_controller': {'type': gripper_type}}},
        'lift_controller': {'ros__parameters': {'joint': LIFT_JOINT}},
        'gripper_controller': {'ros__parameters': {'joint': FINGER_JOINT, **gripper}},
    }, sort_keys=False)


def write_gripper_arm(folder: pathlib.Path, gripper_type: str = (
        'position_controllers/GripperActionController'), *, finger_mu: bool = True,
        **gripper: Any) -> tuple[pathlib.Path, pathlib.Path]:
    """Write the arm's URDF and controllers file into ``folder``; return both paths."""
    urdf = folder / 'gripper_arm.urdf'
    urdf.write_text(gripper_urdf(finger_mu=finger_mu), encoding='utf-8')
    controllers = folder / 'gripper_controllers.yaml'
    controllers.write_text(controllers_yaml(gripper_type, **gripper), encoding='utf-8')
    return urdf, controllers


def grasp_box_urdf(*, mass: float = BOX_MASS, mu: float | None = None,
                   size: float = BOX_SIZE) -> str:
    """Return a cube of side ``size`` (m), with ``<mu1>``/``<mu2>`` ``mu`` unless None."""
    inertia = mass * size * size / 6.0
    friction = ('' if mu is None else
                f'<gazebo reference="box_link"><mu1>{mu}</mu1><mu2>{mu}</mu2></gazebo>')
    return f"""<?xml version="1.0"?>
<robot name="box">
  <link name="box_link">
    <inertial><mass value="{mass}"/>
      <inertia ixx="{inertia}" ixy="0" ixz="0" iyy="{inertia}" iyz="0" izz="{inertia}"/>
    </inertial>
    <collision><geometry><box size="{size} {size} {size}"/></geometry></collision>
  </link>
  {friction}
</robot>
"""
