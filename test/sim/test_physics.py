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


# A 2 kg point-like mass 0.5 m from its hinge: I = 2 * 0.5^2 + 0.001 kg m^2.
ARM_MASS, ARM_LENGTH, ARM_OWN_INERTIA = 2.0, 0.5, 0.001
ARM_INERTIA = ARM_MASS * ARM_LENGTH ** 2 + ARM_OWN_INERTIA


def one_arm(tmp_path, axis: str, friction: float = 0.0):
    """Return the description of one arm on a hinge about ``axis``, with URDF friction."""
    path = tmp_path / 'arm.urdf'
    path.write_text(f"""<robot name="arm"><link name="base"/>
      <link name="arm"><inertial><origin xyz="{ARM_LENGTH} 0 0"/><mass value="{ARM_MASS}"/>
        <inertia ixx="{ARM_OWN_INERTIA}" iyy="{ARM_OWN_INERTIA}" izz="{ARM_OWN_INERTIA}"
                 ixy="0" ixz="0" iyz="0"/></inertial></link>
      <joint name="hinge" type="continuous"><parent link="base"/><child link="arm"/>
        <axis xyz="{axis}"/><limit effort="100" velocity="100"/>
        <dynamics friction="{friction}"/></joint></robot>""")
    return load_description(path)


def test_without_torque_the_arm_falls_freely_no_motor_holds_it(tmp_path):
    # PyBullet's default velocity motors would hold the arm still: they are off.
    with Physics(one_arm(tmp_path, '0 1 0'), 0.001) as physics:
        for _ in range(50):
            (state,) = physics.step([0.0])
    # Horizontal at the start: angular acceleration m g L / I (gravity pulls it down).
    expected = ARM_MASS * 9.81 * ARM_LENGTH / ARM_INERTIA * 0.05
    assert state[1] == pytest.approx(expected, rel=0.01)


def test_friction_holds_below_its_value_and_only_resists_above_it(tmp_path):
    # A vertical hinge: no gravity torque.  URDF friction 1 N*m.
    with Physics(one_arm(tmp_path, '0 0 1', friction=1.0), 0.001) as physics:
        for _ in range(200):
            (held,) = physics.step([0.9])
        for _ in range(100):
            (moving,) = physics.step([3.0])
    assert held[1] == pytest.approx(0.0, abs=1e-6)
    # (3 - 1) N*m over I for 0.1 s: friction resists, nothing else does.
    assert moving[1] == pytest.approx((3.0 - 1.0) / ARM_INERTIA * 0.1, rel=0.01)


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
