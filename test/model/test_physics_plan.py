"""physics_plan: what the physics builds of a robot, decided from its description alone."""

import math
import xml.etree.ElementTree as ElementTree

import pytest
from mobile_fixtures import rover_urdf
from robot_fixtures import JointDef, star_robot_urdf, write_text

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.base_pose import BasePose
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.model.inertials import MOVABLE_MASS
from pan_tilt_sim.model.mimic import MimicCoupling
from pan_tilt_sim.model.physics_plan import (
    DEFAULT_VELOCITY_CAP,
    LinkSurface,
    check_poses,
    plan_physics,
    velocity_cap,
)
from pan_tilt_sim.model.robot import JointKind, JointSpec
from pan_tilt_sim.model.transforms import quaternion_from_rpy

LEADER = JointDef('leader', lower=-1.0, upper=1.0)
FOLLOWER = JointDef('follower', lower=-3.0, upper=3.0, mimic=('leader', -2.0, 0.5))
# The rover's right wheel with a contact spring and two frictions (the smaller applies).
SPRUNG_WHEEL = ('<gazebo reference="right_wheel"><mu1>0.8</mu1><mu2>0.6</mu2>'
                '<kp>100000</kp><kd>50</kd></gazebo>')


def star(tmp_path, *joints):
    return load_description(write_text(tmp_path, 'star.urdf', star_robot_urdf(joints)))


def rover(tmp_path, extra=''):
    return load_description(write_text(tmp_path, 'rover.urdf', rover_urdf(extra=extra)))


def footprint_mass(urdf):
    base = next(link for link in ElementTree.fromstring(urdf).findall('link')
                if link.get('name') == 'base_footprint')
    mass = base.find('inertial/mass')
    return None if mass is None else float(mass.get('value'))


def test_the_joints_are_the_actuated_ones_and_start_at_their_initial_positions(tmp_path):
    plan = plan_physics(star(tmp_path, JointDef('a'), JointDef('b', lower=0.2, upper=1.0)))
    assert [joint.name for joint in plan.joints] == ['a', 'b']
    # Each joint's own start: 0 inside its limits, else the nearer limit.
    assert plan.initial_positions == (0.0, 0.2)


def test_given_initial_positions_are_taken_and_mimic_followers_go_where_their_leaders_put_them(
        tmp_path):
    plan = plan_physics(star(tmp_path, LEADER, FOLLOWER), initial_positions=[0.25, 3.0])
    assert plan.mimics == (MimicCoupling('follower', 'leader', -2.0, 0.5),)
    assert plan.initial_positions == (0.25, -2.0 * 0.25 + 0.5)
    assert plan.with_mimics([-0.5, 9.0]) == [-0.5, 1.5]
    assert plan.coupled == {'leader', 'follower'}


def test_a_wrong_number_of_initial_positions_is_refused(tmp_path):
    with pytest.raises(ValueError, match='1 initial positions for 2 joints'):
        plan_physics(star(tmp_path, LEADER, FOLLOWER), initial_positions=[0.0])


def test_a_mimic_of_a_fixed_joint_is_refused_when_the_plan_is_made(tmp_path):
    description = star(tmp_path, JointDef('weld', kind='fixed'),
                       JointDef('a', mimic=('weld', 1.0, 0.0)))
    with pytest.raises(DescriptionError, match=r"star\.urdf: joint 'a' mimics 'weld', which is "
                                               'not a movable joint'):
        plan_physics(description)


def test_a_welded_base_loads_pybullets_copy_as_it_is_with_polygon_cylinders(tmp_path):
    description = rover(tmp_path)
    plan = plan_physics(description, fixed_base=True)
    assert plan.urdf == description.physics_urdf
    assert plan.fixed_base and not plan.implicit_cylinders
    assert plan.source == description.source


def test_a_free_base_gets_a_massive_root_and_exact_cylinders(tmp_path):
    # The rover on a massless base_footprint root link.
    description = load_description(write_text(tmp_path, 'rover.urdf', rover_urdf(footprint=True)))
    assert footprint_mass(description.physics_urdf) == 0.0  # massless, as the URDF says
    plan = plan_physics(description, fixed_base=False)
    assert footprint_mass(plan.urdf) == MOVABLE_MASS  # else PyBullet would weld it
    assert not plan.fixed_base and plan.implicit_cylinders


def test_the_speed_cap_is_twice_the_fastest_velocity_limit_and_never_below_100(tmp_path):
    def joint(limit):
        return JointSpec('j', JointKind.REVOLUTE, velocity_limit=limit)
    assert velocity_cap([joint(2.0), joint(math.inf)]) == DEFAULT_VELOCITY_CAP == 100.0
    assert velocity_cap([joint(2.0), joint(150.0)]) == 300.0
    fast = plan_physics(star(tmp_path, JointDef('a', velocity=70.0), JointDef('b')))
    assert fast.velocity_cap == 140.0


def test_the_check_poses_cover_the_range_and_free_joints():
    joints = [JointSpec('a', JointKind.REVOLUTE, -1.0, 3.0), JointSpec('b', JointKind.CONTINUOUS)]
    assert check_poses(joints, [0.5, 0.25]) == [
        [0.5, 0.25], [1.0, 0.0], [0.0, math.pi / 2], [2.0, -math.pi / 2]]


def test_inertias_are_checked_from_the_start_with_its_mimics_then_across_the_ranges(tmp_path):
    plan = plan_physics(star(tmp_path, LEADER, FOLLOWER), initial_positions=[0.25, 3.0])
    assert plan.inertia_poses == ((0.25, 0.0), (0.0, 0.0), (-0.5, -1.5), (0.5, 1.5))


def test_a_welded_robot_gets_only_the_urdfs_link_frictions_without_springs(tmp_path):
    plan = plan_physics(rover(tmp_path, SPRUNG_WHEEL), fixed_base=True)
    assert sorted(plan.surfaces, key=lambda surface: surface.link) == [
        LinkSurface('caster', 0.0), LinkSurface('left_wheel', 1.0),
        LinkSurface('right_wheel', 0.6)]


def test_a_free_robot_gives_every_link_its_surface_and_spring(tmp_path):
    plan = plan_physics(rover(tmp_path, SPRUNG_WHEEL), fixed_base=False)
    assert plan.surfaces == (
        LinkSurface('base_link', 1.0),  # Gazebo's default friction
        LinkSurface('left_wheel', 1.0),
        LinkSurface('right_wheel', 0.6, (100000.0, 50.0)),
        LinkSurface('caster', 0.0))


def test_a_welded_base_at_the_origin_stays_where_pybullet_loads_it(tmp_path):
    plan = plan_physics(rover(tmp_path), fixed_base=True)
    assert plan.base.as_loaded and not plan.base.on_ground


def test_a_welded_base_elsewhere_has_its_frame_at_the_pose(tmp_path):
    plan = plan_physics(rover(tmp_path), fixed_base=True,
                        initial_pose=BasePose(1.0, 2.0, 0.3, math.pi / 2))
    assert not plan.base.as_loaded and not plan.base.on_ground
    assert plan.base.frame.translation == (1.0, 2.0, 0.3)
    assert plan.base.frame.rotation == quaternion_from_rpy(0.0, 0.0, math.pi / 2)


def test_a_free_base_rests_on_the_ground_its_lowest_point_at_the_poses_height(tmp_path):
    plan = plan_physics(rover(tmp_path), fixed_base=False, initial_pose=BasePose(1.0, 2.0, 0.3))
    assert plan.base.on_ground and not plan.base.as_loaded
    assert plan.base.frame.translation == (1.0, 2.0, 0.3)
    at_origin = plan_physics(rover(tmp_path), fixed_base=False).base
    assert at_origin.on_ground and not at_origin.as_loaded  # it is put on the ground all the same
