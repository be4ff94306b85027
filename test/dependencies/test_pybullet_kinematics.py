"""PyBullet's forward kinematics agrees with the robot model's (URDF origins, axes, rpy).

A failure here means PyBullet's link frames changed (or the model's maths).
"""

import pathlib

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from robot_fixtures import ARM_URDF

from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.model.urdf import parse_urdf
from pan_tilt_sim.sim.bullet import pybullet
from pan_tilt_sim.sim.physics import Physics


def close_rotation(a, b, tolerance=1e-6):
    """Whether quaternions ``a`` and ``b`` are the same rotation (q and -q are)."""
    dot = abs(sum(x * y for x, y in zip(a, b, strict=True)))
    return dot == pytest.approx(1.0, abs=tolerance)


def arm_model():
    return parse_urdf(ARM_URDF, pathlib.Path('arm.urdf'))


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
