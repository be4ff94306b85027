"""PyBullet's copy of the URDF: links without <inertial> are massless, as the URDF spec says."""

import xml.etree.ElementTree as ElementTree

import pytest
from robot_fixtures import write_text

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.model.inertials import (
    MOVABLE_INERTIA,
    MOVABLE_MASS,
    frozen_joints,
    with_massive_root,
)
from pan_tilt_sim.model.urdf import parse_urdf

INERTIAL = ('<inertial><mass value="{m}"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" '
            'ixz="0" iyz="0"/></inertial>')


def robot(tmp_path, body: str):
    return load_description(write_text(tmp_path, 'robot.urdf', f'<robot name="r">{body}</robot>'))


def physics_inertials(description):
    """Return {link: (mass, ixx)} of PyBullet's copy (None: no <inertial>)."""
    root = ElementTree.fromstring(description.physics_urdf)
    result = {}
    for link in root.findall('link'):
        inertial = link.find('inertial')
        result[link.get('name')] = None if inertial is None else (
            float(inertial.find('mass').get('value')),
            float(inertial.find('inertia').get('ixx')))
    return result


ARM = (f'<link name="base"/><link name="upper">{INERTIAL.format(m=2)}</link>'
       '<link name="tool0"/>'
       '<joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>'
       '<limit lower="-1" upper="1" effort="10" velocity="1"/></joint>'
       '<joint name="flange" type="fixed"><parent link="upper"/><child link="tool0"/></joint>')


def test_links_without_inertial_are_massless_in_pybullets_copy_only(tmp_path):
    description = robot(tmp_path, ARM)
    assert physics_inertials(description) == {
        'base': (0.0, 0.0), 'upper': (2.0, 0.1), 'tool0': (0.0, 0.0)}
    # The model and the URDF as written (robot_description) keep what the user wrote.
    assert description.model.link('tool0').inertial is None
    assert '<link name="tool0"/>' in description.urdf_xml.replace(' />', '/>')
    assert description.warnings == ()


def test_a_joint_that_moves_only_massless_links_gets_a_negligible_mass_and_a_warning(tmp_path):
    body = ARM + ('<link name="camera"/><link name="optical"/>'
                  '<joint name="cam_pan" type="continuous"><parent link="upper"/>'
                  '<child link="camera"/></joint>'
                  '<joint name="cam_optical" type="fixed"><parent link="camera"/>'
                  '<child link="optical"/></joint>')
    description = robot(tmp_path, body)
    inertials = physics_inertials(description)
    assert inertials['camera'] == (MOVABLE_MASS, MOVABLE_INERTIA)
    assert inertials['optical'] == (0.0, 0.0)
    warning, = description.warnings
    assert "joint 'cam_pan' moves only massless links (camera, optical)" in warning
    assert "'camera' gets 1e-06 kg" in warning


def test_a_massless_virtual_leader_weighs_as_its_heaviest_mimic_follower(tmp_path):
    # ros2_control_demos' carlikebot: a massless virtual wheel the controller turns, real
    # wheels following it by <mimic>; a 1e-6 kg leader cannot turn them through the gears.
    body = ARM + ('<link name="virtual_wheel"/>'
                  '<joint name="virtual_joint" type="continuous"><parent link="upper"/>'
                  '<child link="virtual_wheel"/></joint>'
                  f'<link name="wheel_a">{INERTIAL.format(m=0.5)}</link>'
                  f'<link name="wheel_b">{INERTIAL.format(m=0.3)}</link>'
                  + ''.join(f'<joint name="{wheel}_joint" type="continuous"><parent link="upper"/>'
                            f'<child link="{wheel}"/><mimic joint="virtual_joint"/></joint>'
                            for wheel in ('wheel_a', 'wheel_b')))
    description = robot(tmp_path, body)
    assert physics_inertials(description)['virtual_wheel'] == (0.5, 0.1)
    warning, = description.warnings
    assert "'virtual_wheel' gets 0.5 kg and 0.1 kg*m^2 as its heaviest <mimic> follower" in (
        warning)


def test_a_massless_subtree_with_mass_zero_written_out_counts_as_massless(tmp_path):
    body = ARM + (f'<link name="pad">{INERTIAL.format(m=0)}</link>'
                  '<joint name="slide" type="prismatic"><parent link="upper"/><child link="pad"/>'
                  '<limit lower="0" upper="0.1" effort="1" velocity="1"/></joint>')
    description = robot(tmp_path, body)
    assert physics_inertials(description)['pad'] == (MOVABLE_MASS, MOVABLE_INERTIA)
    assert len(description.warnings) == 1


def test_pybullets_copy_has_one_element_per_line(tmp_path):
    # PyBullet's XML reader fails on long one-line files ("Cannot load URDF file."):
    # a minified URDF must still reach it with line breaks.
    description = robot(tmp_path, ARM)
    assert '\n' not in ARM
    assert max(len(line) for line in description.physics_urdf.splitlines()) < 200


def test_a_urdf_with_two_root_links_is_refused_by_name(tmp_path):
    # urdfdom refuses it; PyBullet would crash (segmentation fault) loading it.
    with pytest.raises(DescriptionError, match=r"links 'base', 'stray' are each the child of "
                                               'no joint'):
        robot(tmp_path, ARM + '<link name="stray"/>')


def test_a_free_bases_massless_root_gets_a_negligible_mass_and_a_massive_one_is_kept(tmp_path):
    description = robot(tmp_path, ARM)
    freed = ElementTree.fromstring(with_massive_root(description.physics_urdf, description.model))
    base = next(link for link in freed.findall('link') if link.get('name') == 'base')
    assert float(base.find('inertial/mass').get('value')) == MOVABLE_MASS
    assert float(base.find('inertial/inertia').get('izz')) == MOVABLE_INERTIA
    massive = robot(tmp_path, f'<link name="base">{INERTIAL.format(m=3)}</link>'
                              '<link name="wheel">' + INERTIAL.format(m=1) + '</link>'
                              '<joint name="axle" type="continuous"><parent link="base"/>'
                              '<child link="wheel"/></joint>')
    assert with_massive_root(massive.physics_urdf, massive.model) == massive.physics_urdf


def test_nested_and_branching_massless_subtrees_each_list_every_link_below_their_joint(tmp_path):
    # base (massive) - a - b - c, and b - d: every joint moves only massless links.
    joints = [('ja', 'base', 'a'), ('jb', 'a', 'b'), ('jc', 'b', 'c'), ('jd', 'b', 'd')]
    body = f'<link name="base">{INERTIAL.format(m=1)}</link>' + ''.join(
        f'<link name="{name}"/>' for name in 'abcd') + ''.join(
        f'<joint name="{joint}" type="continuous"><parent link="{parent}"/>'
        f'<child link="{child}"/></joint>' for joint, parent, child in joints)
    model = parse_urdf(f'<robot name="r">{body}</robot>', tmp_path / 'r.urdf')
    frozen = {joint: set(links) for joint, links in frozen_joints(model).items()}
    assert frozen == {'ja': set('abcd'), 'jb': set('bcd'), 'jc': {'c'}, 'jd': {'d'}}
    assert frozen_joints(model)['ja'][0] == 'a'  # the joint's own child first
    heavy = body.replace('<link name="d"/>', f'<link name="d">{INERTIAL.format(m=1)}</link>')
    model = parse_urdf(f'<robot name="r">{heavy}</robot>', tmp_path / 'r.urdf')
    assert set(frozen_joints(model)) == {'jc'}  # d's mass moves with ja, jb and jd
