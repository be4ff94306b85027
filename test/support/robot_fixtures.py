"""Small URDF robots for engine and node tests, written on the fly.

:func:`star_robot_urdf` hangs one box link per joint directly off a fixed
base, each at its own place, so the joints move independently of each
other: a test can reason about one joint at a time.  Revolute and
continuous joints turn about z and prismatic joints slide along x, so
gravity loads none of them.
"""

from __future__ import annotations

import dataclasses
import pathlib
import textwrap
from collections.abc import Sequence

LINK_MASS = 2.0  # kg
LINK_LENGTH = 0.2  # m, along x from the joint
LINK_WIDTH = 0.02  # m
JOINT_SPACING = 0.3  # m between joints along y


@dataclasses.dataclass(frozen=True)
class JointDef:
    """One joint of a star robot (a limit of None is left out of the URDF)."""

    name: str
    kind: str = 'revolute'
    lower: float | None = -1.5
    upper: float | None = 1.5
    effort: float = 50.0
    velocity: float = 2.0
    damping: float = 0.5
    friction: float = 0.0
    mimic: tuple[str, float, float] | None = None  # (leader, multiplier, offset)

    @property
    def axis(self) -> str:
        return '1 0 0' if self.kind == 'prismatic' else '0 0 1'


def _box_inertia(mass: float, x: float, y: float, z: float) -> str:
    # About the link's centre of mass (URDF inertia is given at the inertial origin).
    return (f'<inertia ixx="{mass * (y * y + z * z) / 12}" ixy="0" ixz="0" '
            f'iyy="{mass * (x * x + z * z) / 12}" iyz="0" izz="{mass * (x * x + y * y) / 12}"/>')


def star_robot_urdf(joints: Sequence[JointDef], name: str = 'star') -> str:
    """Return a URDF with a fixed base and one link per joint, hung off the base."""
    parts = [f'<?xml version="1.0"?>\n<robot name="{name}">',
             '<link name="base_link"><inertial><mass value="10"/>'
             '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>']
    half = LINK_LENGTH / 2
    for number, joint in enumerate(joints):
        link = f'{joint.name}_link'
        limit = [f'effort="{joint.effort}"', f'velocity="{joint.velocity}"']
        if joint.lower is not None:
            limit.append(f'lower="{joint.lower}"')
        if joint.upper is not None:
            limit.append(f'upper="{joint.upper}"')
        mimic = ''
        if joint.mimic is not None:
            leader, multiplier, offset = joint.mimic
            mimic = f'<mimic joint="{leader}" multiplier="{multiplier}" offset="{offset}"/>'
        geometry = f'<geometry><box size="{LINK_LENGTH} {LINK_WIDTH} {LINK_WIDTH}"/></geometry>'
        parts.append(textwrap.dedent(f"""
            <joint name="{joint.name}" type="{joint.kind}">
              <parent link="base_link"/><child link="{link}"/>
              <origin xyz="0 {number * JOINT_SPACING} 0.1" rpy="0 0 0"/>
              <axis xyz="{joint.axis}"/>
              <limit {' '.join(limit)}/>
              <dynamics damping="{joint.damping}" friction="{joint.friction}"/>
              {mimic}
            </joint>
            <link name="{link}">
              <visual><origin xyz="{half} 0 0"/>{geometry}</visual>
              <collision><origin xyz="{half} 0 0"/>{geometry}</collision>
              <inertial><origin xyz="{half} 0 0"/><mass value="{LINK_MASS}"/>
                {_box_inertia(LINK_MASS, LINK_LENGTH, LINK_WIDTH, LINK_WIDTH)}
              </inertial>
            </link>"""))
    parts.append('</robot>\n')
    return '\n'.join(parts)


def write_star_robot(folder: pathlib.Path, joints: Sequence[JointDef],
                     name: str = 'star') -> pathlib.Path:
    """Write :func:`star_robot_urdf` to ``folder/<name>.urdf`` and return the path."""
    path = folder / f'{name}.urdf'
    path.write_text(star_robot_urdf(joints, name), encoding='utf-8')
    return path


def write_text(folder: pathlib.Path, name: str, text: str) -> pathlib.Path:
    """Write dedented ``text`` to ``folder/name`` and return the path."""
    path = folder / name
    path.write_text(textwrap.dedent(text), encoding='utf-8')
    return path


# A chain with every joint kind the kinematic tree handles, offsets and rotated origins;
# its tip link hangs on a fixed joint.
ARM_URDF = """<robot name="arm">
  <link name="base"/>
  <link name="shoulder"><inertial><mass value="1"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="upper"><inertial><mass value="1"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><origin xyz="0 0 0.25" rpy="0 0 0"/><geometry><box size="0.1 0.1 0.5"/></geometry>
    </visual></link>
  <link name="slider"><inertial><mass value="1"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tool"><inertial><mass value="1"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="yaw" type="continuous"><parent link="base"/><child link="shoulder"/>
    <origin xyz="0.1 0 0.2" rpy="0 0 0.3"/><axis xyz="0 0 1"/></joint>
  <joint name="pitch" type="revolute"><parent link="shoulder"/><child link="upper"/>
    <origin xyz="0 0.05 0.1" rpy="0.2 -0.4 0.1"/><axis xyz="0 1 1"/>
    <limit lower="-2" upper="2" effort="10" velocity="1"/></joint>
  <joint name="extend" type="prismatic"><parent link="upper"/><child link="slider"/>
    <origin xyz="0 0 0.5" rpy="0 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-0.3" upper="0.3" effort="10" velocity="1"/></joint>
  <joint name="flange" type="fixed"><parent link="slider"/><child link="tool"/>
    <origin xyz="0.02 0 0.07" rpy="1.5707963 0 0"/></joint>
</robot>"""


# A two-link arm in the x-z plane, both joints about y, so gravity loads them;
# horizontal along +x at q = 0.  Each link is a rod of the given mass and length
# (centre of mass at its middle); the tip frame ``tool0`` has no <inertial>.
def two_link_arm_urdf(masses=(2.0, 1.0), length=0.5, effort=100.0, velocity=2.0,
                      damping=0.0, friction=0.0, tip_frame=True) -> str:
    links = []
    for number, mass in enumerate(masses, start=1):
        inertia = mass * length * length / 12.0
        links.append(
            f'<link name="link{number}"><inertial><origin xyz="{length / 2} 0 0"/>'
            f'<mass value="{mass}"/><inertia ixx="1e-6" iyy="{inertia}" izz="{inertia}" '
            'ixy="0" ixz="0" iyz="0"/></inertial></link>')
    joints = []
    for number, (parent, origin) in enumerate(
            (('base_link', '0 0 1'), ('link1', f'{length} 0 0')), start=1):
        joints.append(
            f'<joint name="joint{number}" type="revolute"><parent link="{parent}"/>'
            f'<child link="link{number}"/><origin xyz="{origin}"/><axis xyz="0 1 0"/>'
            f'<limit lower="-3" upper="3" effort="{effort}" velocity="{velocity}"/>'
            f'<dynamics damping="{damping}" friction="{friction}"/></joint>')
    tip = (f'<link name="tool0"/><joint name="flange" type="fixed"><parent link="link2"/>'
           f'<child link="tool0"/><origin xyz="{length} 0 0"/></joint>') if tip_frame else ''
    return ('<?xml version="1.0"?>\n<robot name="two_link_arm">\n<link name="base_link"/>\n'
            + '\n'.join(links + joints) + '\n' + tip + '\n</robot>\n')


def arm_holding_torques(q1: float, q2: float, masses=(2.0, 1.0), length=0.5,
                        gravity=9.81) -> tuple[float, float]:
    """Return the efforts that hold :func:`two_link_arm_urdf` still at (q1, q2).

    A positive angle about +y turns +x toward -z, so gravity pulls each
    joint toward positive angles and holding takes negative efforts.
    """
    import math

    m1, m2 = masses
    second = m2 * gravity * length / 2.0 * math.cos(q1 + q2)
    first = (m1 * gravity * length / 2.0 * math.cos(q1)
             + m2 * gravity * length * math.cos(q1)) + second
    return (-first, -second)


def ros2_control_yaml(controllers: dict, update_rate: int = 100) -> str:
    """Return a ros2_control-style YAML: {name: (type, {parameters})} plus a broadcaster."""
    lines = ['controller_manager:', '  ros__parameters:', f'    update_rate: {update_rate}',
             '    joint_state_broadcaster:',
             '      type: joint_state_broadcaster/JointStateBroadcaster']
    for name, (type_name, _params) in controllers.items():
        lines += [f'    {name}:', f'      type: {type_name}']
    for name, (_type, params) in controllers.items():
        lines += [f'{name}:', '  ros__parameters:']
        lines += [f'    {key}: {value}' for key, value in params.items()]
    return '\n'.join(lines) + '\n'


class Log:
    """A logger for the simulation that collects what it says."""

    def __init__(self) -> None:
        self.infos: list[str] = []
        self.warnings: list[str] = []

    def info(self, message: str) -> None:
        self.infos.append(message)

    def warning(self, message: str) -> None:
        self.warnings.append(message)
