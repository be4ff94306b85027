"""The physics layer: own client ids, fixed base, torque-driven joints."""

import pytest

from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.sim.physics import Physics, pybullet


@pytest.fixture
def description(repo_root):
    return load_description(repo_root / 'urdf' / 'pan_tilt.xacro')


def test_each_physics_owns_its_own_client(description):
    with Physics(description, 0.001) as first, Physics(description, 0.001) as second:
        assert first.client_id != second.client_id
        first.step([50.0, 0.0])
        assert second.read_states()[0][1] == 0.0
    assert not pybullet.isConnected(first.client_id)


def test_the_base_is_fixed_and_gravity_points_down(description):
    with Physics(description, 0.001) as physics:
        assert pybullet.getPhysicsEngineParameters(
            physicsClientId=physics.client_id)['gravityAccelerationZ'] == pytest.approx(-9.81)
        for _ in range(500):
            physics.step([0.0, 0.0])
        position, _orientation = pybullet.getBasePositionAndOrientation(
            physics.body_id, physicsClientId=physics.client_id)
        assert position == pytest.approx((0.0, 0.0, 0.0))


def test_without_torque_no_motor_drives_the_joints(description):
    with Physics(description, 0.001) as physics:
        physics.reset_joints([0.5, -2.0])
        for _ in range(200):
            states = physics.step([0.0, 0.0])
        # Only gravity acts: the horizontal-axis tilt may sag, the vertical pan cannot move.
        assert states[0][0] == pytest.approx(0.5, abs=1e-6)


def test_friction_holds_a_joint_against_a_torque_below_it(description):
    with Physics(description, 0.001) as physics:
        for _ in range(500):
            states = physics.step([0.9, 0.0])
        assert states[0][1] == pytest.approx(0.0, abs=1e-6)


def test_the_stepper_applies_the_torques_the_keyword_call_applies(description):
    # The stepper passes PyBullet's arguments by position (target and gain
    # slots filled with zeros): the motion must be that of forces=... alone.
    efforts = [50.0, -20.0]
    with Physics(description, 0.001) as fast, Physics(description, 0.001) as reference:
        step = fast.stepper()
        indices = [reference.joint_index(joint.name) for joint in reference.joints]
        for _ in range(300):
            states = step(efforts)
            pybullet.setJointMotorControlArray(
                reference.body_id, indices, pybullet.TORQUE_CONTROL, forces=efforts,
                physicsClientId=reference.client_id)
            pybullet.stepSimulation(physicsClientId=reference.client_id)
        assert states == reference.read_states()
        assert states[0][1] > 0.5  # the pan turns under its 50 N*m
