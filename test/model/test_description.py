"""The description layer: the original example's xacro and ours give the same robot facts."""

import math

import pytest
from ros2_control_fixtures import ARM_XACRO, write, write_arm

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.description import load_description, parse_xacro_args
from pan_tilt_sim.model.robot import JointKind


def _facts(description):
    return {joint.name: joint for joint in description.joints}


def test_our_pan_tilt_xacro_has_the_pan_tilt_examples_joints_limits_and_dynamics(repo_root):
    description = load_description(repo_root / 'urdf' / 'pan_tilt.xacro')
    assert description.name == 'ex_urdf_pan_tilt'
    assert description.plugin_namespace == '/ex_urdf_pan_tilt'
    pan, tilt = description.model.joint('pan_joint'), description.model.joint('tilt_joint')
    assert (pan.kind, pan.lower, pan.upper) == (JointKind.REVOLUTE, -3.14, 3.14)
    assert (tilt.lower, tilt.upper) == (-4.71239, -1.570796)
    for joint in (pan, tilt):
        assert (joint.effort_limit, joint.velocity_limit) == (300.0, 0.1)
        assert (joint.damping, joint.friction) == (50.0, 1.0)


def test_the_original_examples_xacro_loads_unchanged_and_matches_ours(original_examples, repo_root):
    original = load_description(original_examples / 'pan_tilt.xacro')
    ours = load_description(repo_root / 'urdf' / 'pan_tilt.xacro')
    assert _facts(original) == _facts(ours)
    assert original.plugin_namespace == ours.plugin_namespace == '/ex_urdf_pan_tilt'


def test_our_xacro_keeps_the_original_links_geometry_and_inertia(original_examples, repo_root):
    import xml.etree.ElementTree as ElementTree

    def links(path):
        root = ElementTree.fromstring(load_description(path).urdf_xml)
        result = {}
        for link in root.iter('link'):
            result[link.get('name')] = (
                [dict(c.attrib) for c in link.iter('cylinder')],
                [dict(c.attrib) for c in link.iter('color')],
                [dict(o.attrib) for o in link.iter('origin')],
                dict(link.find('inertial/mass').attrib),
                {k: float(v) for k, v in link.find('inertial/inertia').attrib.items()},
            )
        return result

    def numeric(value):
        cylinders, colours, origins, mass, inertia = value
        return ([{k: float(v) for k, v in c.items()} for c in cylinders], colours, origins,
                float(mass['value']), inertia)

    original = links(original_examples / 'pan_tilt.xacro')
    ours = links(repo_root / 'urdf' / 'pan_tilt.xacro')
    assert original.keys() == ours.keys() == {'base_link', 'pan_link', 'tilt_link'}
    for name in original:
        assert numeric(original[name]) == numeric(ours[name]), name


def test_initial_position_is_zero_or_the_nearest_limit(repo_root):
    description = load_description(repo_root / 'urdf' / 'pan_tilt.xacro')
    assert description.model.joint('pan_joint').initial_position == 0.0
    assert description.model.joint('tilt_joint').initial_position == -1.570796


def test_xacro_args_are_mappings(tmp_path):
    path = tmp_path / 'arm.xacro'
    path.write_text(
        '<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:arg name="reach" default="1.0"/>'
        '<link name="a"/><link name="b"/>'
        '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
        '<limit lower="0" upper="$(arg reach)" effort="1" velocity="1"/></joint></robot>')
    assert load_description(path).model.joint('j').upper == 1.0
    assert load_description(path, ['reach:=2.5']).model.joint('j').upper == 2.5


def test_a_continuous_joint_has_no_position_limits(tmp_path):
    path = tmp_path / 'wheel.urdf'
    path.write_text(
        '<robot name="w"><link name="a"/><link name="b"/>'
        '<joint name="wheel" type="continuous"><parent link="a"/><child link="b"/>'
        '<limit effort="5" velocity="2"/></joint></robot>')
    wheel = load_description(path).model.joint('wheel')
    assert not wheel.has_position_limits
    assert (wheel.lower, wheel.upper) == (-math.inf, math.inf)
    assert wheel.clamp_position(100.0) == 100.0


@pytest.mark.parametrize('args', [['reach'], [':=1']])
def test_malformed_xacro_args_are_refused(args):
    with pytest.raises(DescriptionError, match='name:=value'):
        parse_xacro_args(args)


def test_a_missing_file_names_the_file(tmp_path):
    with pytest.raises(DescriptionError, match='nope.urdf: no such file'):
        load_description(tmp_path / 'nope.urdf')


# --- xacro's own warnings -------------------------------------------------------------------

def test_xacro_warnings_are_kept_for_the_caller_not_printed(tmp_path, capfd):
    xacro = write_arm(tmp_path)
    description = load_description(xacro)
    assert capfd.readouterr().err == ''
    assert description.warnings == (
        f'{xacro}: xacro: warning: redefining global symbol: pi',)


def test_a_xacro_error_prints_nothing_beside_the_one_error(tmp_path, capfd):
    xacro = write(tmp_path, 'broken.urdf.xacro', ARM_XACRO.replace(
        '<link name="world"/>', '<link name="${no_such_property}"/>'))
    with pytest.raises(DescriptionError, match='no_such_property'):
        load_description(xacro)
    assert capfd.readouterr().err == ''


def test_a_plain_urdf_has_no_warnings(repo_root):
    assert load_description(repo_root / 'urdf' / 'pan_tilt.xacro').warnings == ()


def test_a_description_from_a_topic_is_read_and_named_after_it(tmp_path):
    from pan_tilt_sim.model.description import description_from_text

    urdf = load_description(write_arm(tmp_path)).urdf_xml
    description = description_from_text(urdf, '/rrbot/robot_description')
    assert description.name == 'two_link_arm'
    assert str(description.source) == '/rrbot/robot_description'
    assert description.urdf_xml == urdf
    with pytest.raises(DescriptionError, match='^/robot_description:1: not well-formed XML'):
        description_from_text('<robot', '/robot_description')


def test_package_meshes_in_a_description_from_a_topic_resolve_as_from_a_file(tmp_path,
                                                                            monkeypatch):
    from mesh_fixtures import binary_stl_bytes, make_ament_prefix

    from pan_tilt_sim.model.description import description_from_text

    prefix = make_ament_prefix(tmp_path, 'arm_description',
                               {'meshes/link.stl': binary_stl_bytes((0.1, 0.1, 0.1))})
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(prefix))
    urdf = load_description(write_arm(tmp_path)).urdf_xml.replace(
        '<box size="0.4 0.04 0.04"/>', '<mesh filename="package://arm_description/meshes/link.stl"/>')
    description = description_from_text(urdf, '/robot_description')
    assert 'package://' in description.urdf_xml  # as published
    assert 'package://' not in description.physics_urdf
    assert str(prefix / 'share' / 'arm_description' / 'meshes' / 'link.stl') in (
        description.physics_urdf)
