"""The parser refuses, before PyBullet sees it, every URDF that PyBullet crashes on or poisons.

One line each, naming the element: the tree (one root, no cycle, one parent
per link, no joint that is its own parent), unique names, name lengths,
joint types, axes, masses and inertias.  What PyBullet does with each is
pinned in test/dependencies/test_pybullet_limits.py.
"""

import math
import pathlib

import pytest

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.urdf import (
    MAX_INERTIA,
    MAX_MASS,
    MAX_NAME_BYTES,
    MIN_AXIS_LENGTH,
    parse_urdf,
)

SOURCE = pathlib.Path('robot.urdf')


def link(name, mass='1', inertia='0.01', off_diagonal='0'):
    return (f'<link name="{name}"><inertial><mass value="{mass}"/>'
            f'<inertia ixx="{inertia}" ixy="{off_diagonal}" ixz="0" iyy="{inertia}" iyz="0" '
            f'izz="{inertia}"/></inertial></link>')


def joint(name, parent, child, kind='revolute', axis='0 0 1'):
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
            f'<child link="{child}"/><axis xyz="{axis}"/>'
            '<limit lower="-1" upper="1" effort="10" velocity="1"/></joint>')


def robot(*parts, name='r'):
    return f'<robot name="{name}">' + ''.join(parts) + '</robot>'


def refusal(urdf):
    """Return the one-line message parsing ``urdf`` is refused with."""
    with pytest.raises(DescriptionError) as refused:
        parse_urdf(urdf, SOURCE)
    message = str(refused.value)
    assert '\n' not in message
    assert message.startswith(f'{SOURCE}: ')
    return message


TWO = (link('a'), link('b'))

# (id, URDF, parts of the message)
REFUSED = [
    ('two joints with the same child',
     robot(*TWO, link('c'), joint('j1', 'a', 'b'), joint('j2', 'a', 'c'), joint('j3', 'b', 'c')),
     ["link 'c'", "'j2'", "'j3'", 'one parent']),
    ('a cycle not through the root',
     robot(*TWO, link('c'), link('d'), joint('j1', 'a', 'b'), joint('j2', 'c', 'd'),
           joint('j3', 'd', 'c')),
     ["'j3', 'j2' form a cycle (d -> c -> d)"]),
    ('a cycle the root leads into',
     robot(*TWO, link('c'), joint('j1', 'a', 'b'), joint('j2', 'b', 'c'), joint('j3', 'c', 'b')),
     ["link 'b'", "'j1'", "'j3'", 'one parent']),
    ('a cycle through the root and an orphan link',
     robot(*TWO, link('c'), joint('j1', 'a', 'b'), joint('j2', 'b', 'a')),
     ["'j1'", "'j2'", 'cycle']),
    ('every link in a cycle', robot(*TWO, joint('j1', 'a', 'b'), joint('j2', 'b', 'a')),
     ["'j1'", "'j2'", 'cycle']),
    ('a joint whose parent is its child',
     robot(*TWO, joint('j1', 'a', 'b'), joint('j2', 'b', 'b')),
     ["joint 'j2'", "link 'b'", 'parent and its child']),
    ('the same joint twice', robot(*TWO, link('c'), joint('j1', 'a', 'b'), joint('j1', 'b', 'c')),
     ["joint 'j1'", 'twice']),
    ('the same link twice', robot(*TWO, link('b'), joint('j1', 'a', 'b')),
     ["link 'b'", 'twice']),
    ('mimic joints following each other round',
     robot(*TWO, link('c'), link('d'), joint('j1', 'a', 'b'),
           joint('j2', 'b', 'c').replace('</joint>', '<mimic joint="j3"/></joint>'),
           joint('j3', 'c', 'd').replace('</joint>', '<mimic joint="j2"/></joint>')),
     ['mimic joints form a cycle: j2 -> j3 -> j2']),
    ('a planar joint', robot(*TWO, joint('j1', 'a', 'b', kind='planar')),
     ["joint 'j1'", 'planar', 'not simulated']),
    ('a floating joint', robot(*TWO, joint('j1', 'a', 'b', kind='floating')),
     ["joint 'j1'", 'floating', 'not simulated', 'fixed']),
    ('a zero axis', robot(*TWO, joint('j1', 'a', 'b', axis='0 0 0')),
     ["joint 'j1'", '<axis xyz="0 0 0">', 'no direction']),
    ('a near-zero axis', robot(*TWO, joint('j1', 'a', 'b', axis='0 0 1e-300')),
     ["joint 'j1'", '<axis xyz="0 0 1e-300">', 'no direction']),
    ('a zero prismatic axis', robot(*TWO, joint('j1', 'a', 'b', 'prismatic', axis='0 0 0')),
     ["joint 'j1'", 'no direction']),
    ('a negative mass', robot(link('a'), link('b', mass='-1'), joint('j1', 'a', 'b')),
     ["link 'b'", '<mass value="-1">', '>= 0']),
    ('a mass beyond the bound', robot(link('a'), link('b', mass='1e308'), joint('j1', 'a', 'b')),
     ["link 'b'", '<mass value="1e308">', f'{MAX_MASS:g} kg']),
    ('an inertia beyond the bound',
     robot(link('a'), link('b', inertia='1e300'), joint('j1', 'a', 'b')),
     ["link 'b'", 'ixx="1e300"', f'{MAX_INERTIA:g} kg*m^2']),
    ('an off-diagonal inertia beyond the bound',
     robot(link('a'), link('b', off_diagonal='-1e12'), joint('j1', 'a', 'b')),
     ["link 'b'", 'ixy="-1e12"']),
]


@pytest.mark.parametrize(('urdf', 'expected'), [
    pytest.param(urdf, expected, id=case) for case, urdf, expected in REFUSED])
def test_a_description_pybullet_cannot_take_is_refused_in_one_line_naming_it(urdf, expected):
    message = refusal(urdf)
    for part in expected:
        assert part in message


@pytest.mark.parametrize('role', ['joint', 'link', 'root link', 'robot'])
def test_a_name_of_more_bytes_than_pybullet_holds_is_refused_and_one_less_is_not(role):
    def urdf(length):
        name = 'n' * length
        names = {'joint': 'j', 'link': 'b', 'root link': 'a', 'robot': 'r'}
        names[role] = name
        return robot(link(names['root link']), link(names['link']),
                     joint(names['joint'], names['root link'], names['link']),
                     name=names['robot'])

    longest = parse_urdf(urdf(MAX_NAME_BYTES), SOURCE)
    assert MAX_NAME_BYTES in {len(longest.name), *map(len, longest.joint_names),
                              *map(len, longest.link_names)}
    for length in (MAX_NAME_BYTES + 1, 2000):
        message = refusal(urdf(length))
        assert f'{length} bytes' in message
        assert f'at most {MAX_NAME_BYTES}' in message
        assert len(message) < 300  # the name is shortened, not printed whole


def test_a_name_is_measured_in_utf8_bytes_as_pybullet_stores_it():
    two_byte = 'é' * (MAX_NAME_BYTES // 2)  # 1022 bytes
    assert parse_urdf(robot(*TWO, joint(two_byte, 'a', 'b')), SOURCE).joint_names == (two_byte,)
    message = refusal(robot(*TWO, joint(two_byte + 'é', 'a', 'b')))
    assert f'{MAX_NAME_BYTES + 1} bytes' in message


def test_an_axis_is_a_direction_normalized_and_one_just_long_enough_is_kept():
    model = parse_urdf(robot(*TWO, link('c'), joint('j1', 'a', 'b', axis='0 3 4'),
                             joint('j2', 'b', 'c', 'prismatic', axis=f'{2 * MIN_AXIS_LENGTH} 0 0')),
                       SOURCE)
    assert model.joint('j1').axis == pytest.approx((0.0, 0.6, 0.8))
    assert model.joint('j2').axis == (1.0, 0.0, 0.0)
    assert math.hypot(*model.joint('j1').axis) == pytest.approx(1.0)


def test_a_fixed_joint_needs_no_axis_direction():
    model = parse_urdf(robot(*TWO, joint('weld', 'a', 'b', 'fixed', axis='0 0 0')), SOURCE)
    assert model.joint('weld').axis == (0.0, 0.0, 0.0)


@pytest.mark.parametrize(('mass', 'inertia'), [
    ('0', '0'),  # a massless frame
    (repr(MAX_MASS), repr(MAX_INERTIA)),
    ('1e-12', '1e-15'),
])
def test_masses_and_inertias_within_the_bounds_are_read(mass, inertia):
    model = parse_urdf(robot(link('a'), link('b', mass, inertia), joint('j1', 'a', 'b')), SOURCE)
    inertial = model.link('b').inertial
    assert (inertial.mass, inertial.ixx) == (float(mass), float(inertia))


def test_a_tree_with_branches_is_accepted():
    model = parse_urdf(robot(*TWO, link('c'), link('d'), joint('j1', 'a', 'b'),
                             joint('j2', 'a', 'c'), joint('j3', 'c', 'd')), SOURCE)
    assert model.root == 'a'
    assert [j.name for j in model.tree_joints] == ['j1', 'j2', 'j3']
