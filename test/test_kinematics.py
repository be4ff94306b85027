"""The kinematic tree from a URDF matches what PyBullet computes, without ROS."""

import math
import pathlib

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.model.transforms import (
    Transform,
    quaternion_from_axis_angle,
    quaternion_from_matrix,
    quaternion_from_rpy,
    rotate,
    rotation_matrix,
)
from pan_tilt_sim.model.urdf import parse_urdf
from pan_tilt_sim.share import DEFAULT_DESCRIPTION, package_share
from pan_tilt_sim.sim.bullet import pybullet
from pan_tilt_sim.sim.physics import Physics

# A chain with every joint kind the tree handles, offsets and rotated origins.
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


def close_rotation(a, b, tolerance=1e-6):
    """Whether quaternions ``a`` and ``b`` are the same rotation (q and -q are)."""
    dot = abs(sum(x * y for x, y in zip(a, b, strict=True)))
    return dot == pytest.approx(1.0, abs=tolerance)


def test_rpy_is_urdf_fixed_axis_roll_then_pitch_then_yaw():
    q = quaternion_from_rpy(0.3, -0.2, 1.1)
    expected = rotation_matrix(quaternion_from_axis_angle((0, 0, 1), 1.1))
    for axis, angle in (((0, 1, 0), -0.2), ((1, 0, 0), 0.3)):
        step = rotation_matrix(quaternion_from_axis_angle(axis, angle))
        expected = tuple(tuple(sum(expected[r][k] * step[k][c] for k in range(3))
                               for c in range(3)) for r in range(3))
    for got, want in zip(rotation_matrix(q), expected, strict=True):
        assert got == pytest.approx(want, abs=1e-12)


@given(st.floats(-math.pi, math.pi), st.floats(-1.5, 1.5), st.floats(-math.pi, math.pi))
def test_a_quaternion_survives_the_round_trip_through_its_matrix(roll, pitch, yaw):
    q = quaternion_from_rpy(roll, pitch, yaw)
    rows = rotation_matrix(q)
    columns = tuple(tuple(rows[r][c] for r in range(3)) for c in range(3))
    assert close_rotation(quaternion_from_matrix(columns), q)


def test_a_transform_composes_rotation_then_translation():
    quarter_turn = Transform((1.0, 0.0, 0.0), quaternion_from_axis_angle((0, 0, 1), math.pi / 2))
    assert quarter_turn.apply((1.0, 0.0, 0.0)) == pytest.approx((1.0, 1.0, 0.0))
    twice = quarter_turn.then(quarter_turn)
    # (1,0,0) -> inner: (0,1,0) + (1,0,0) = (1,1,0) -> outer: (-1,1,0) + (1,0,0)
    assert twice.apply((1.0, 0.0, 0.0)) == pytest.approx((0.0, 1.0, 0.0), abs=1e-12)


def seed_model():
    return load_description(package_share() / DEFAULT_DESCRIPTION).model


def arm_model():
    return parse_urdf(ARM_URDF, pathlib.Path('arm.urdf'))


def test_the_seed_has_two_moving_joints_and_no_fixed_ones():
    tree = seed_model()
    assert tree.root == 'base_link'
    assert [joint.name for joint in tree.moving_joints] == ['pan_joint', 'tilt_joint']
    assert tree.fixed_joints == ()


def test_the_seed_tilt_link_is_0_3_m_up_and_turned_by_the_tilt():
    tree = seed_model()
    pose = tree.link_poses({'pan_joint': 0.0, 'tilt_joint': -math.pi / 2})['tilt_link']
    assert pose.translation == pytest.approx((0.0, 0.0, 0.3))
    assert rotate(pose.rotation, (0, 0, 1)) == pytest.approx((-1.0, 0.0, 0.0), abs=1e-12)


def test_link_reach_is_the_far_end_of_the_visual_along_z():
    seed, arm = seed_model(), arm_model()
    assert seed.link('tilt_link').reach() == pytest.approx(0.2)  # 0.4 m cylinder, centred
    assert seed.link('pan_link').reach() == pytest.approx(0.29)  # offset 0.09 + 0.2
    assert arm.link('upper').reach() == pytest.approx(0.5)  # box from 0 to 0.5
    assert arm.link('base').reach() == 0.0  # no visual


@pytest.fixture
def arm_physics(tmp_path):
    """Return a PyBullet world holding ARM_URDF."""
    path = tmp_path / 'arm.urdf'
    path.write_text(ARM_URDF)
    physics = Physics(load_description(path), 0.001)
    yield physics
    physics.close()


def pybullet_link_poses(physics):
    """Return every link's URDF frame pose as PyBullet computes it."""
    client, body = physics.client_id, physics.body_id
    poses = {}
    for index in range(pybullet.getNumJoints(body, physicsClientId=client)):
        name = pybullet.getJointInfo(body, index, physicsClientId=client)[12].decode()
        state = pybullet.getLinkState(body, index, computeForwardKinematics=True,
                                      physicsClientId=client)
        poses[name] = (state[4], state[5])
    return poses


@settings(max_examples=25, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])  # reset per example
@given(yaw=st.floats(-3.0, 3.0), pitch=st.floats(-2.0, 2.0), extend=st.floats(-0.3, 0.3))
def test_link_poses_agree_with_pybullet(arm_physics, yaw, pitch, extend):
    positions = {'yaw': yaw, 'pitch': pitch, 'extend': extend}
    arm_physics.reset_joints([positions[joint.name] for joint in arm_physics.joints])
    ours = arm_model().link_poses(positions)
    for link, (position, orientation) in pybullet_link_poses(arm_physics).items():
        assert ours[link].translation == pytest.approx(position, abs=1e-5), link
        assert close_rotation(ours[link].rotation, orientation, 1e-5), link
