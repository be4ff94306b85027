"""URDF objects for spawning tests, written on the fly."""

from __future__ import annotations

import pathlib

BOX_RGBA = (0.9, 0.1, 0.9, 1.0)  # magenta: no target, the ground or the pan/tilt is this colour


def box_urdf(name: str = 'box', size: tuple[float, float, float] = (0.2, 0.2, 0.2),
             mass: float = 1.0, rgba: tuple[float, float, float, float] = BOX_RGBA, *,
             static: bool = False, com: tuple[float, float, float] = (0.0, 0.0, 0.0),
             mesh: str | None = None, mu: float | None = None) -> str:
    """Return the URDF of a one-link box (a solid box's inertia about ``com``).

    ``mesh`` replaces the visual geometry with a mesh file name; ``mu`` gives
    the box ``<mu1>``/``<mu2>`` (without it, PyBullet's 0.5).
    """
    x, y, z = size
    colour = ' '.join(str(c) for c in rgba)
    geometry = f'<geometry><box size="{x} {y} {z}"/></geometry>'
    visual = f'<geometry><mesh filename="{mesh}"/></geometry>' if mesh else geometry
    gazebo = '<gazebo><static>true</static></gazebo>' if static else ''
    if mu is not None:
        gazebo += f'<gazebo reference="{name}_link"><mu1>{mu}</mu1><mu2>{mu}</mu2></gazebo>'
    return f"""<?xml version="1.0"?>
<robot name="{name}">
  <link name="{name}_link">
    <inertial>
      <origin xyz="{com[0]} {com[1]} {com[2]}"/>
      <mass value="{mass}"/>
      <inertia ixx="{mass * (y * y + z * z) / 12}" ixy="0" ixz="0"
               iyy="{mass * (x * x + z * z) / 12}" iyz="0" izz="{mass * (x * x + y * y) / 12}"/>
    </inertial>
    <visual>{visual}<material name="{name}_colour"><color rgba="{colour}"/></material></visual>
    <collision>{geometry}</collision>
  </link>
  {gazebo}
</robot>
"""


def write_box(folder: pathlib.Path, file_name: str = 'box.urdf', **kwargs) -> pathlib.Path:
    """Write :func:`box_urdf` to ``folder/file_name`` and return the path."""
    path = folder / file_name
    path.write_text(box_urdf(**kwargs), encoding='utf-8')
    return path


# A fixed rig: a wheel half in the ground (continuous about y, its axle at z = 0.05)
# and a plunger (a 0.1 m box on a joint sliding along z) hanging 0.3 m up.
RIG_URDF = """<?xml version="1.0"?>
<robot name="rig">
  <link name="base"><inertial><mass value="10"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="wheel"><inertial><mass value="1"/>
    <inertia ixx="0.005" iyy="0.005" izz="0.005" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin rpy="1.5708 0 0"/>
      <geometry><cylinder radius="0.1" length="0.05"/></geometry></collision></link>
  <joint name="spin" type="continuous"><parent link="base"/><child link="wheel"/>
    <origin xyz="0 0 0.05"/><axis xyz="0 1 0"/><limit effort="10" velocity="100"/></joint>
  <link name="plunger"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <joint name="lift" type="prismatic"><parent link="base"/><child link="plunger"/>
    <origin xyz="1 0 0.3"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="100" velocity="5"/></joint>
</robot>
"""
RIG_CONTROLLERS = """rig:
  spin_effort: {type: effort_controllers/JointEffortController, joint: spin}
  lift_effort: {type: effort_controllers/JointEffortController, joint: lift}
"""


def _part(name: str) -> str:
    return (f'<link name="{name}"><inertial><mass value="0.5"/><inertia ixx="0.001" ixy="0" '
            'ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>'
            '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>')


def _hinge(name: str, parent: str, child: str) -> str:
    return (f'<joint name="{name}" type="revolute"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>'
            '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')


def _thing(*parts: str) -> str:
    return '<?xml version="1.0"?>\n<robot name="thing">\n' + '\n'.join(parts) + '\n</robot>\n'


# Objects PyBullet crashes on (segmentation fault or double free), with a part of the one
# line the parser refuses each with instead.
UNSPAWNABLE = {
    'a name of 2000 characters': (
        _thing(_part('a'), _part('b'), _hinge('j' * 2000, 'a', 'b')),
        'the name is 2000 bytes long'),
    'two joints with one child': (
        _thing(_part('a'), _part('b'), _part('c'), _hinge('j1', 'a', 'b'), _hinge('j2', 'a', 'c'),
               _hinge('j3', 'b', 'c')),
        "link 'c' is the child of two joints, 'j2' and 'j3'"),
    'a cycle off the root': (
        _thing(_part('a'), _part('b'), _part('c'), _hinge('j1', 'a', 'b'), _hinge('j2', 'b', 'c'),
               _hinge('j3', 'c', 'b')),
        "link 'b' is the child of two joints, 'j1' and 'j3'"),
    'a cycle through the root and an orphan link': (
        _thing(_part('a'), _part('b'), _part('c'), _hinge('j1', 'a', 'b'), _hinge('j2', 'b', 'a')),
        "joints 'j2', 'j1' form a cycle"),
    'a joint whose parent is its child': (
        _thing(_part('a'), _part('b'), _hinge('j1', 'a', 'b'), _hinge('j2', 'b', 'b')),
        "joint 'j2': link 'b' is both its parent and its child"),
    'the same joint twice': (
        _thing(_part('a'), _part('b'), _part('c'), _hinge('j1', 'a', 'b'), _hinge('j1', 'b', 'c')),
        "joint 'j1' is declared twice"),
}


def flail_urdf(reach: float) -> str:
    """Return an object of two links on a hinge, the second's centre of mass ``reach`` m out."""
    flail = (f'<link name="flail"><inertial><origin xyz="0 0 {reach!r}"/><mass value="1"/>'
             '<inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>')
    return _thing(_part('handle'), flail, _hinge('hinge', 'handle', 'flail'))


def chain_urdf(joints: int, joint_type: str = 'revolute', name: str = 'chain') -> str:
    """Return a serial chain of ``joints`` joints (``joints + 1`` links of 0.1 kg, 0.1 m long)."""
    links = [f'<link name="{name}_{index}"><inertial><mass value="0.1"/>'
             '<inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial>'
             '<collision><origin xyz="0 0 0.05"/><geometry><box size="0.02 0.02 0.1"/>'
             '</geometry></collision></link>' for index in range(joints + 1)]
    limit = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
    chain = [f'<joint name="{name}_joint_{index}" type="{joint_type}">'
             f'<parent link="{name}_{index}"/><child link="{name}_{index + 1}"/>'
             f'<origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>{limit}</joint>'
             for index in range(joints)]
    return f'<robot name="{name}">\n' + '\n'.join(links + chain) + '\n</robot>\n'
