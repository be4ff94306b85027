"""The physics layer: own client ids, fixed base, massless frames, PyBullet's messages."""

import dataclasses
import math
import re

import pytest
from robot_fixtures import (
    JointDef,
    arm_holding_torques,
    star_robot_urdf,
    two_link_arm_urdf,
    write_text,
)

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.model.physics_plan import plan_physics
from pan_tilt_sim.model.physics_settings import DEFAULT_PHYSICS, PhysicsSettings
from pan_tilt_sim.sim.bullet import message_lines
from pan_tilt_sim.sim.physics import Physics, engine_parameters, pybullet


@pytest.fixture
def description(repo_root):
    return load_description(repo_root / 'urdf' / 'pan_tilt.xacro')


def test_each_physics_owns_its_own_client(description):
    with Physics(description, 0.001) as first, Physics(description, 0.001) as second:
        assert first.client_id != second.client_id
        first.step([50.0, 0.0])
        assert second.read_states()[0][1] == 0.0
    assert not pybullet.isConnected(first.client_id)


def test_a_physics_builds_what_its_plan_says(description):
    plan = plan_physics(description, initial_positions=[0.3, -0.2])
    with Physics.from_plan(plan, 0.001) as physics:
        assert physics.plan is plan
        assert physics.initial_positions == [0.3, -0.2]
        assert [state[0] for state in physics.read_states()] == pytest.approx([0.3, -0.2])
        assert physics.velocity_cap == plan.velocity_cap
        assert physics.fixed_base


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


def test_the_stepper_applies_the_torques_the_keyword_call_applies(tmp_path):
    # The stepper passes PyBullet's arguments by position (target and gain
    # slots filled with zeros): the motion must be that of forces=... alone.
    # (A joint without damping or friction has no motor row: torque only.)
    efforts = [3.0]
    description = one_arm(tmp_path, '0 1 0')
    with Physics(description, 0.001) as fast, Physics(description, 0.001) as reference:
        step = fast.stepper()
        indices = [reference.joint_index(joint.name) for joint in reference.joints]
        for _ in range(300):
            states = step(efforts, ())
            pybullet.setJointMotorControlArray(
                reference.body_id, indices, pybullet.TORQUE_CONTROL, forces=efforts,
                physicsClientId=reference.client_id)
            pybullet.stepSimulation(physicsClientId=reference.client_id)
        assert states == reference.read_states()
        assert states[0][1] != 0.0


# --- links without <inertial>, PyBullet's own drag and speed cap --------------------------

def two_link_arm(tmp_path, **options):
    return load_description(write_text(tmp_path, 'arm.urdf', two_link_arm_urdf(**options)))


def test_a_massless_tip_frame_adds_nothing_the_arm_holds_with_the_analytic_torque(tmp_path):
    # tool0 has no <inertial>: massless, as the URDF spec says (PyBullet alone
    # would give it 1 kg and the arm would fall with these torques).
    holding = arm_holding_torques(0.0, 0.0)
    assert holding == pytest.approx((-12.2625, -2.4525))
    with Physics(two_link_arm(tmp_path), 0.001) as physics:
        assert physics.gravity_torques() == pytest.approx(holding, abs=1e-9)
        for _ in range(1000):  # an unstable equilibrium: any wrong torque shows as drift
            states = physics.step(list(holding))
    assert [state[0] for state in states] == pytest.approx([0.0, 0.0], abs=1e-6)


def test_pybullets_hidden_drag_is_off(tmp_path):
    # A vertical hinge, no damping: after a kick the arm turns at a constant
    # speed.  PyBullet's default linear/angular damping 0.04 would slow it ~8 %.
    with Physics(one_arm(tmp_path, '0 0 1'), 0.001) as physics:
        for _ in range(100):
            (kicked,) = physics.step([1.0])
        for _ in range(2000):
            (coasting,) = physics.step([0.0])
    assert coasting[1] == pytest.approx(kicked[1], rel=1e-9)


def test_a_joint_may_reach_its_velocity_limit_beyond_pybullets_default_cap(tmp_path):
    # One arm allowed 150 rad/s (limit="100" in one_arm): an ideal velocity motor gets there.
    text = one_arm(tmp_path, '0 0 1').source.read_text().replace('velocity="100"',
                                                                 'velocity="150"')
    description = load_description(write_text(tmp_path, 'fast.urdf', text))
    with Physics(description, 0.001) as physics:
        physics.set_drives([True])
        for _ in range(1500):  # 100 N*m on 0.5 kg*m^2: 0.75 s to get there
            (state,) = physics.step([], [150.0])
    assert state[1] == pytest.approx(150.0)


# --- what PyBullet says while loading ------------------------------------------------------

BAD_INERTIA = """<robot name="bad"><link name="base"/>
  <link name="flat"><inertial><mass value="1"/>
    <inertia ixx="0.1" iyy="0.1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="continuous"><parent link="base"/><child link="flat"/>
    <axis xyz="0 0 1"/></joint></robot>"""


def test_pybullets_load_messages_reach_the_log_once_each(tmp_path):
    # Principal moments 0.1 + 0.1 < 1 break the triangle inequality: PyBullet
    # zeroes the inertia (and prints it three times).
    messages = []
    description = load_description(write_text(tmp_path, 'bad.urdf', BAD_INERTIA))
    with Physics(description, 0.001, warn=messages.append):
        pass
    assert messages == ['PyBullet, loading bad.urdf: Bad inertia tensor properties, setting '
                        'inertia to zero for link: flat']


def test_a_load_failure_says_what_pybullet_said(tmp_path):
    # PyBullet's XML reader cannot read this file written on one line (the
    # description layer indents its copy; here it is handed over as it is).
    text = star_robot_urdf([JointDef(f'j{number}') for number in range(20)])
    description = dataclasses.replace(
        load_description(write_text(tmp_path, 'star.urdf', text)),
        physics_urdf=re.sub(r'>\s+<', '><', text).replace('\n', ' '))
    with pytest.raises(DescriptionError) as raised:
        Physics(description, 0.001)
    assert str(raised.value) == (
        f'{description.source}: PyBullet cannot load the robot: Cannot load URDF file. '
        '(Error=XML_ERROR_PARSING_ELEMENT ErrorID=7 (0x7) Line number=1)')


def test_message_lines_merge_split_messages_and_drop_repeats_and_the_banner():
    text = ('pybullet build time: Jan 29 2025\nb3Warning[a.cpp,1]:\nNo inertial data for link, '
            'using mass=1\nb3Warning[a.cpp,2]:\ntool0\nb3Warning[b.cpp,3]:\nBad inertia\n'
            'b3Warning[b.cpp,3]:\nBad inertia\nb3Error[c.cpp,4]:\nboom\n')
    assert message_lines(text) == [
        "link 'tool0': No inertial data for link, using mass=1", 'Bad inertia', 'boom']


BALL_PENDULUM_SDF = '''<sdf version="1.9"><model name="pendulum">
  <link name="base"><inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy>
    <izz>0.01</izz></inertia></inertial></link>
  <link name="bob"><pose>0.3 0 1 0 0 0</pose><inertial><mass>1</mass><inertia><ixx>0.001</ixx>
    <iyy>0.001</iyy><izz>0.001</izz></inertia></inertial></link>
  <link name="arm"><inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy>
    <izz>0.01</izz></inertia></inertial></link>
  <joint name="ball" type="ball"><parent>base</parent><child>bob</child>
    <pose>-0.3 0 0 0 0 0</pose></joint>
  <joint name="turn" type="revolute"><parent>base</parent><child>arm</child>
    <axis><xyz>0 0 1</xyz><limit><lower>-1</lower><upper>1</upper></limit></axis></joint>
</model></sdf>'''


def test_an_sdf_ball_joint_swings_freely_in_three_degrees_of_freedom(tmp_path):
    path = tmp_path / 'pendulum.sdf'
    path.write_text(BALL_PENDULUM_SDF)
    with Physics(load_description(path), 0.001) as physics:
        client, body = physics.client_id, physics.body_id
        start = pybullet.getLinkState(body, physics.link_index('bob'),
                                      physicsClientId=client)[0]
        assert start == pytest.approx((0.3, 0.0, 1.0), abs=1e-6)
        for _ in range(300):
            pybullet.stepSimulation(physicsClientId=client)
        # Held out sideways from its pivot, the bob falls: a welded or motor-held ball stays.
        x, _y, z = pybullet.getLinkState(body, physics.link_index('bob'),
                                         physicsClientId=client)[0]
        assert z < 0.85 and math.hypot(x + 0.0, z - 1.0) == pytest.approx(0.3, abs=1e-3)
        # The revolute joint's column comes after the ball's three: its arm's own 0.01 kg m^2.
        assert physics.effective_inertias() == pytest.approx([0.01])
        physics.reset_joints()
        assert pybullet.getLinkState(body, physics.link_index('bob'), physicsClientId=client)[
            0] == pytest.approx((0.3, 0.0, 1.0), abs=1e-6)


# --- PyBullet's solver settings -----------------------------------------------------------

def contact_and_constraint_scene(settings: PhysicsSettings | None) -> list:
    """Run a box pushed along the ground, one hung on a point constraint, a pendulum held by
    its joint limit; return their poses and the pendulum's joint state at every step.

    ``settings`` None: PyBullet as it starts; else those settings given to it first.
    """
    client = pybullet.connect(pybullet.DIRECT)
    try:
        pybullet.setGravity(0.0, 0.0, -9.81, physicsClientId=client)
        pybullet.setTimeStep(0.001, physicsClientId=client)
        if settings is not None:
            pybullet.setPhysicsEngineParameter(**engine_parameters(settings),
                                               physicsClientId=client)
        pybullet.createMultiBody(0.0, pybullet.createCollisionShape(
            pybullet.GEOM_PLANE, physicsClientId=client), physicsClientId=client)
        shape = pybullet.createCollisionShape(pybullet.GEOM_BOX, halfExtents=[0.1] * 3,
                                              physicsClientId=client)
        pushed = pybullet.createMultiBody(1.0, shape, basePosition=[0, 0, 0.09],
                                          physicsClientId=client)  # 1 cm into the ground
        anchor = pybullet.createMultiBody(0.0, shape, basePosition=[2, 0, 1.3],
                                          physicsClientId=client)
        hung = pybullet.createMultiBody(1.0, shape, basePosition=[2.05, 0, 1.0],
                                        physicsClientId=client)
        pybullet.setCollisionFilterPair(anchor, hung, -1, -1, 0, physicsClientId=client)
        pybullet.createConstraint(anchor, -1, hung, -1, pybullet.JOINT_POINT2POINT, [0, 0, 0],
                                  [0, 0, -0.15], [0, 0, 0.15], physicsClientId=client)
        # A pendulum starting 0.2 rad beyond its joint limit.
        ball = pybullet.createCollisionShape(pybullet.GEOM_SPHERE, radius=0.05,
                                             physicsClientId=client)
        pendulum = pybullet.createMultiBody(
            0.0, -1, basePosition=[-2, 0, 1], linkMasses=[1.0], linkCollisionShapeIndices=[ball],
            linkVisualShapeIndices=[-1], linkPositions=[[0, 0, -0.5]],
            linkOrientations=[[0, 0, 0, 1]], linkInertialFramePositions=[[0, 0, 0]],
            linkInertialFrameOrientations=[[0, 0, 0, 1]], linkParentIndices=[0],
            linkJointTypes=[pybullet.JOINT_REVOLUTE], linkJointAxis=[[0, 1, 0]],
            physicsClientId=client)
        pybullet.changeDynamics(pendulum, 0, jointLowerLimit=-0.1, jointUpperLimit=0.1,
                                physicsClientId=client)
        pybullet.resetJointState(pendulum, 0, 0.3, physicsClientId=client)
        pybullet.setJointMotorControl2(pendulum, 0, pybullet.VELOCITY_CONTROL, force=0.0,
                                       physicsClientId=client)
        poses = []
        for _ in range(300):
            pybullet.applyExternalForce(pushed, -1, [3, 0, 0], [0, 0.05, 0.1],
                                        pybullet.WORLD_FRAME, physicsClientId=client)
            pybullet.stepSimulation(physicsClientId=client)
            poses.append([pybullet.getBasePositionAndOrientation(body, physicsClientId=client)
                          for body in (pushed, hung)]
                         + [pybullet.getJointState(pendulum, 0, physicsClientId=client)[:2]])
        return poses
    finally:
        pybullet.disconnect(client)


def test_the_default_settings_are_pybullets_own_giving_them_changes_nothing():
    assert contact_and_constraint_scene(DEFAULT_PHYSICS) == contact_and_constraint_scene(None)


@pytest.mark.parametrize('change', [
    {'solver_iterations': 5}, {'erp': 0.8}, {'contact_erp': 0.2}, {'cfm': 1e-6},
    {'contact_slop': 0.0}, {'split_impulse': False}])
def test_each_setting_reaches_pybullet(change):
    changed = dataclasses.replace(DEFAULT_PHYSICS, **change)
    assert contact_and_constraint_scene(changed) != contact_and_constraint_scene(None)


def test_a_physics_takes_its_settings_at_start_and_when_changed(description):
    def iterations(physics):
        return pybullet.getPhysicsEngineParameters(
            physicsClientId=physics._client)['numSolverIterations']

    with Physics(description, 0.001, settings=PhysicsSettings(solver_iterations=7)) as physics:
        assert iterations(physics) == 7
        assert physics.settings == PhysicsSettings(solver_iterations=7)
        physics.apply_settings(PhysicsSettings(solver_iterations=12, contact_slop=0.0))
        assert iterations(physics) == 12
        assert physics.settings.contact_slop == 0.0
    with Physics(description, 0.001) as physics:
        assert iterations(physics) == 50 and physics.settings == DEFAULT_PHYSICS
