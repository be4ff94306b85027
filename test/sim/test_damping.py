"""URDF damping and friction on effort-driven and passive joints: stable at any time step.

PyBullet applies URDF damping explicitly, which diverges once damping *
time_step exceeds twice the joint's inertia (a light wheel then runs at
PyBullet's speed cap).  The physics applies it implicitly instead, with
Coulomb friction; these tests hold at the default 1 ms step and at 10 ms.
"""

import math

import pytest
from robot_fixtures import write_text

from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.sim.physics import Physics

# A 50 g disc of radius 3 cm on a vertical axle: I = m r^2 / 2 = 2.25e-5 kg m^2.
WHEEL_MASS, WHEEL_RADIUS = 0.05, 0.03
WHEEL_INERTIA = WHEEL_MASS * WHEEL_RADIUS ** 2 / 2


def wheel(tmp_path, damping, friction=0.0):
    inertia = WHEEL_INERTIA
    return load_description(write_text(tmp_path, 'wheel.urdf', f"""
        <robot name="wheel"><link name="base"/>
          <link name="wheel"><inertial><mass value="{WHEEL_MASS}"/>
            <inertia ixx="{inertia}" iyy="{inertia}" izz="{inertia}" ixy="0" ixz="0" iyz="0"/>
          </inertial></link>
          <joint name="axle" type="continuous"><parent link="base"/><child link="wheel"/>
            <axis xyz="0 0 1"/><limit effort="10" velocity="1000"/>
            <dynamics damping="{damping}" friction="{friction}"/></joint></robot>"""))


def spin(description, effort, seconds, time_step):
    with Physics(description, time_step) as physics:
        speeds = [physics.step([effort])[0][1] for _ in range(round(seconds / time_step))]
    return speeds


@pytest.mark.parametrize('time_step', [0.001, 0.01])
def test_a_50_gram_wheel_turns_at_effort_over_damping(tmp_path, time_step):
    # damping * time_step = 1e-4 > 2 * I = 4.5e-5: PyBullet's explicit damping diverges.
    speeds = spin(wheel(tmp_path, damping=0.1), effort=0.01, seconds=1.0, time_step=time_step)
    assert speeds[-1] == pytest.approx(0.01 / 0.1, rel=0.01)
    assert max(speeds) <= 0.1 * 1.01  # approached from below, no ringing


@pytest.mark.parametrize('time_step', [0.001, 0.01])
def test_friction_takes_its_share_and_holds_below_it(tmp_path, time_step):
    moving = spin(wheel(tmp_path, damping=0.1, friction=0.005), 0.01, 1.0, time_step)
    assert moving[-1] == pytest.approx((0.01 - 0.005) / 0.1, rel=0.01)
    held = spin(wheel(tmp_path, damping=0.1, friction=0.02), 0.01, 1.0, time_step)
    assert max(map(abs, held)) < 1e-12  # static friction: effort below it moves nothing


def test_light_damping_still_lets_the_wheel_reach_effort_over_damping(tmp_path):
    speeds = spin(wheel(tmp_path, damping=0.001), effort=0.01, seconds=0.3, time_step=0.001)
    # Still speeding up after 0.3 s (time constant I / d = 22.5 ms ... of 10 rad/s: exact lag).
    assert speeds[-1] == pytest.approx(10.0 * (1 - math.exp(-0.001 * 0.3 / WHEEL_INERTIA)),
                                       rel=0.01)


@pytest.mark.parametrize('time_step', [0.001, 0.01])
def test_the_pan_tilt_examples_pan_under_50_newton_metres_turns_at_0_98(repo_root, time_step):
    # damping 50, friction 1: (50 - 1) / 50 rad/s, as before and in Gazebo.
    description = load_description(repo_root / 'urdf' / 'pan_tilt.xacro')
    with Physics(description, time_step) as physics:
        for _ in range(round(1.0 / time_step)):
            pan, _tilt = physics.step([50.0, 0.0])
    assert pan[1] == pytest.approx(0.98, rel=1e-3)


@pytest.mark.parametrize('friction', [0.0, 0.03])
def test_a_heavily_damped_passive_pendulum_creeps_down_at_10_ms(tmp_path, friction):
    # 0.1 kg, 0.1 m, damping 1: d * dt = 0.01 >> 2 J = 0.002 at 10 ms.  Inertia is
    # negligible (J / d = 1 ms), so it creeps: d q' = m g L cos(q) - f while that is > 0.
    # Gravity must enter the implicit step (with friction, through last step's torque).
    description = load_description(write_text(tmp_path, 'pendulum.urdf', f"""
        <robot name="pendulum"><link name="base"/>
          <link name="bob"><inertial><origin xyz="0.1 0 0"/><mass value="0.1"/>
            <inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial></link>
          <joint name="hinge" type="revolute"><parent link="base"/><child link="bob"/>
            <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="10"/>
            <dynamics damping="1.0" friction="{friction}"/></joint></robot>"""))
    weight = 0.1 * 9.81 * 0.1
    with Physics(description, 0.01) as physics:
        states = [physics.step([0.0])[0] for _ in range(300)]
    expected, fine = 0.0, 1e-4
    for _ in range(round(3.0 / fine)):
        expected += fine * max(0.0, weight * math.cos(expected) - friction) / 1.0
    assert max(abs(state[1]) for state in states) <= (weight - friction) * 1.01
    assert states[-1][0] == pytest.approx(expected, rel=0.02)
    assert all(b[0] >= a[0] for a, b in zip(states, states[1:], strict=False))


def test_explicit_damping_is_kept_only_far_inside_its_stability_bound(tmp_path, repo_root):
    # The pan_tilt: damping 50 * 1 ms = 0.05 against >= 1 kg m^2: PyBullet's own, free per step.
    pan_tilt = load_description(repo_root / 'urdf' / 'pan_tilt.xacro')
    with Physics(pan_tilt, 0.001) as physics:
        assert physics.implicit_damping == ()
    with Physics(pan_tilt, 0.1) as physics:  # 5 against ~1: implicit
        assert physics.implicit_damping == ('pan_joint', 'tilt_joint')
    with Physics(wheel(tmp_path, damping=0.1), 0.001) as physics:
        assert physics.implicit_damping == ('axle',)
    with Physics(wheel(tmp_path, damping=0.001), 0.001) as physics:
        assert physics.implicit_damping == ()  # 1e-6 <= 0.1 * 2.25e-5
    with Physics(wheel(tmp_path, damping=0.1), 0.001) as physics:
        physics.set_drives([True])  # an ideal actuator ignores the joint's damping
        assert physics.implicit_damping == ()


@pytest.mark.parametrize('friction', [0.0, 0.005])
def test_a_guest_robots_wheel_is_damped_implicitly_as_its_hosts_is(tmp_path, friction):
    # A robot spawned into another's world (a guest) steps with it: its damping rows are
    # sent before the world step and read back after it, as the host's own are.
    description = wheel(tmp_path, damping=0.1, friction=friction)
    with Physics(description, 0.001) as host:
        guest = Physics(description, 0.001, world=host)
        assert guest.implicit_damping == host.implicit_damping == ('axle',)
        guest_speeds, host_speeds = [], []
        for _ in range(1000):
            guest.step([0.01])
            host_speeds.append(host.step([0.01])[0][1])
            guest_speeds.append(guest.take_states()[0][1])
        guest.close()
    assert guest_speeds[-1] == pytest.approx((0.01 - friction) / 0.1, rel=0.01)
    assert guest_speeds == pytest.approx(host_speeds, rel=1e-6, abs=1e-9)
