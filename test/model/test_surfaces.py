"""Contact surfaces from ``<gazebo reference="LINK">``: mu1, mu2, kp, kd, and Gazebo's defaults."""

from __future__ import annotations

import pathlib

import pytest

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.surfaces import DEFAULT_KD, DEFAULT_MU, Surface
from pan_tilt_sim.model.urdf import parse_urdf

SOURCE = pathlib.Path('robot.urdf')


def model(gazebo: str, root: str = 'base'):
    """Return the model of a two-link robot with the given ``<gazebo>`` elements."""
    return parse_urdf(f'''<robot name="r"><link name="{root}"/><link name="wheel"/>
        <joint name="axle" type="continuous"><parent link="{root}"/><child link="wheel"/></joint>
        {gazebo}</robot>''', SOURCE)


def test_a_link_without_tags_has_gazebos_defaults():
    surface = model('').surface('wheel')
    assert (surface.mu1, surface.mu2, surface.kp, surface.kd) == (DEFAULT_MU, DEFAULT_MU,
                                                                  None, None)
    assert surface.friction == 1.0 and surface.spring is None


def test_the_tags_of_a_link_are_read_and_several_blocks_add_up():
    surface = model('<gazebo reference="wheel"><mu1>0.7</mu1><mu2>0.9</mu2></gazebo>'
                    '<gazebo reference="wheel"><kp>1e6</kp></gazebo>').surface('wheel')
    assert surface == Surface('wheel', mu1=0.7, mu2=0.9, kp=1e6)
    assert surface.friction == 0.7 and not surface.isotropic
    assert surface.spring == (1e6, DEFAULT_KD)


def test_a_value_attribute_is_read_as_gazebos_urdf_parser_reads_it():
    surface = model('<gazebo reference="wheel"><mu1 value="200.0"/><mu2 value="100.0"/>'
                    '<kp value="10000000.0"/><kd>1.0</kd></gazebo>').surface('wheel')
    assert surface == Surface('wheel', mu1=200.0, mu2=100.0, kp=1e7, kd=1.0)


def test_gazebo_blocks_without_surface_tags_or_for_no_link_are_not_surfaces():
    robot = model('<gazebo reference="axle"><mu1>0.3</mu1></gazebo>'
                  '<gazebo reference="wheel"><material>Gazebo/Black</material></gazebo>')
    assert robot.surfaces == ()


@pytest.mark.parametrize('tag, text, rule', [
    ('mu1', 'grippy', '>= 0'), ('mu2', '-1', '>= 0'), ('kp', '0', '> 0'), ('kd', 'nan', '>= 0')])
def test_a_value_that_is_not_a_number_in_range_names_the_file_link_and_tag(tag, text, rule):
    with pytest.raises(DescriptionError, match=rf'^robot\.urdf: <gazebo reference="wheel">: '
                                               rf"<{tag}> '{text}' must be a number {rule}"):
        model(f'<gazebo reference="wheel"><{tag}>{text}</{tag}></gazebo>')


def test_a_robot_hung_on_a_world_link_by_a_fixed_joint_is_welded():
    welded = parse_urdf('<robot name="r"><link name="world"/><link name="base"/>'
                        '<joint name="fix" type="fixed"><parent link="world"/>'
                        '<child link="base"/></joint></robot>', SOURCE)
    assert welded.welded_to_world
    assert not model('').welded_to_world
    assert not model('', root='world').welded_to_world  # joined by a moving joint


def caster_robot(link: str, joint_type: str, geometry: str, gazebo: str = ''):
    """Return a base and ``link`` on a ``joint_type`` joint, colliding as ``geometry``."""
    return parse_urdf(f'''<robot name="r"><link name="base"/>
        <link name="{link}"><collision><geometry>{geometry}</geometry></collision></link>
        <joint name="mount" type="{joint_type}"><parent link="base"/><child link="{link}"/>
        <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
        {gazebo}</robot>''', SOURCE)


SPHERE = '<sphere radius="0.015"/>'


def test_a_fixed_sphere_named_caster_rolls_freely_as_the_ball_it_models():
    robot = caster_robot('caster_frontal_wheel', 'fixed', SPHERE)
    assert robot.is_ball_caster('caster_frontal_wheel')
    assert robot.surface('caster_frontal_wheel').friction == 0.0


def test_a_casters_own_gazebo_friction_wins():
    robot = caster_robot('caster_frontal_wheel', 'fixed', SPHERE,
                         '<gazebo reference="caster_frontal_wheel"><mu1>0.5</mu1>'
                         '<mu2>0.5</mu2></gazebo>')
    assert robot.surface('caster_frontal_wheel').friction == 0.5


@pytest.mark.parametrize(('link', 'joint_type', 'geometry'), [
    ('ball', 'fixed', SPHERE),                                  # not named a caster
    ('caster_wheel', 'continuous', SPHERE),                     # a wheel that turns
    ('caster_wheel', 'fixed', '<cylinder radius="0.02" length="0.01"/>'),  # not a ball
])
def test_anything_else_keeps_gazebos_default_friction(link, joint_type, geometry):
    robot = caster_robot(link, joint_type, geometry)
    assert not robot.is_ball_caster(link)
    assert robot.surface(link).friction == DEFAULT_MU
