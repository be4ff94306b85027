"""The physics against the textbook: each row of docs/accuracy.md, measured here.

Every case runs the package's own simulation (``make_simulation`` with a
small URDF written by the helpers below, objects through ``Entities``, the
controllers the package registers), at sim_node's default 1 ms step, so
that what is measured is what a user gets.  The analytic value of each case
is computed here, independently of the code under test.  Each test asserts
the error within the row's tolerance, and that docs/accuracy.md shows what
it measured (to the digits the table prints).
"""

from __future__ import annotations

import math
import pathlib
import re

import numpy
import pytest
from gripper_fixtures import (
    BOX_MASS,
    BOX_SIZE,
    FINGER_MU,
    FINGER_OPEN,
    grasp_box_urdf,
    write_gripper_arm,
)
from mobile_fixtures import CONTROLLER, WHEEL_RADIUS, write_rover

from pan_tilt_sim.controllers.framework.surface import StampedTwist
from pan_tilt_sim.controllers.grippers.gripper_action_controller import GripperRequest
from pan_tilt_sim.model.transforms import Transform
from pan_tilt_sim.sim.bullet import pybullet
from pan_tilt_sim.sim.engine import make_simulation
from pan_tilt_sim.sim.entities import Entities, EntityState
from pan_tilt_sim.sim.physics import STANDARD_GRAVITY

G = STANDARD_GRAVITY  # m/s^2: the package's gravity, Gazebo's default world's
TIME_STEP = 0.001  # s: sim_node's default
DOC = pathlib.Path(__file__).resolve().parents[2] / 'docs' / 'accuracy.md'
BROADCASTER_ONLY = """\
controller_manager:
  ros__parameters:
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster
"""
PYBULLET_DEFAULT_FRICTION = 0.5  # a surface without <mu1>/<mu2> (docs/robots.md)
CONTACT_NORMAL_FORCE = 9  # index in one of pybullet.getContactPoints' points


# --- the doc's table ------------------------------------------------------------------------

def doc_row(case: str) -> dict[str, str]:
    """Return the cells of the docs/accuracy.md table row whose case is ``case``."""
    lines = [line for line in DOC.read_text(encoding='utf-8').splitlines()
             if line.startswith('|')]
    header = [cell.strip() for cell in lines[0].strip('|').split('|')]
    for line in lines[2:]:
        cells = [cell.strip() for cell in line.strip('|').split('|')]
        if cells[0] == case:
            return dict(zip(header, cells, strict=True))
    raise AssertionError(f'docs/accuracy.md has no row {case!r}')


def printed(cell: str) -> tuple[float, float]:
    """Return the first number of a table cell and half a unit of its last printed digit."""
    match = re.search(r'-?\d+(?:\.(\d+))?', cell.replace('−', '-'))
    assert match, f'no number in {cell!r}'
    decimals = len(match[1] or '')
    return float(match[0]), 0.5 * 10.0 ** -decimals


def assert_documented(case: str, analytic: float, simulated: float) -> None:
    """The row shows ``analytic`` and ``simulated`` as measured, to its printed digits."""
    row = doc_row(case)
    for column, value in (('analytic', analytic), ('simulated', simulated)):
        shown, half_unit = printed(row[column])
        assert abs(shown - value) <= half_unit + 1e-12, (
            f'docs/accuracy.md, {case!r}: {column} shows {row[column]}, measured {value!r}')


def relative_error(analytic: float, simulated: float) -> float:
    return (simulated - analytic) / analytic


# --- a pendulum: a point-like bob on a massless arm, about a horizontal axis ---------------

ARM = 0.5  # m: pivot to the bob's centre of mass
BOB_MASS = 1.0  # kg
BOB_INERTIA = 0.001  # kg m^2 about its own centre of mass (each axis)


def pendulum_urdf() -> str:
    return f"""<?xml version="1.0"?>
<robot name="pendulum">
  <link name="base_link"><inertial><mass value="10"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="swing" type="continuous">
    <parent link="base_link"/><child link="bob"/>
    <origin xyz="0 0 2"/><axis xyz="0 1 0"/>
    <limit effort="100" velocity="100"/><dynamics damping="0" friction="0"/>
  </joint>
  <link name="bob">
    <inertial><origin xyz="0 0 {-ARM}"/><mass value="{BOB_MASS}"/>
      <inertia ixx="{BOB_INERTIA}" ixy="0" ixz="0" iyy="{BOB_INERTIA}" iyz="0"
               izz="{BOB_INERTIA}"/></inertial>
  </link>
</robot>
"""


def small_angle_period() -> float:
    """The compound pendulum's period: 2 pi sqrt(I_pivot / (m g d))."""
    pivot_inertia = BOB_INERTIA + BOB_MASS * ARM * ARM  # parallel axis
    return 2.0 * math.pi * math.sqrt(pivot_inertia / (BOB_MASS * G * ARM))


def agm(a: float, b: float) -> float:
    """The arithmetic-geometric mean of ``a`` and ``b``."""
    while abs(a - b) > 1e-15 * a:
        a, b = (a + b) / 2.0, math.sqrt(a * b)
    return a


def exact_period(amplitude: float) -> float:
    """The period at any amplitude: T0 * 2K(k) / pi = T0 / AGM(1, cos(amplitude / 2))."""
    return small_angle_period() / agm(1.0, math.cos(amplitude / 2.0))


def simulated_period(folder: pathlib.Path, amplitude: float, swings: int = 5) -> float:
    """Release the pendulum at rest at ``amplitude``; return its mean period over ``swings``."""
    urdf = folder / 'pendulum.urdf'
    urdf.write_text(pendulum_urdf(), encoding='utf-8')
    controllers = folder / 'broadcaster.yaml'
    controllers.write_text(BROADCASTER_ONLY, encoding='utf-8')
    with make_simulation(str(urdf), str(controllers), TIME_STEP,
                         initial_positions={'swing': amplitude}) as simulation:
        crossings = []  # times the pendulum passes down through the vertical, going one way
        previous = simulation.joint_positions()['swing']
        while len(crossings) < swings + 1:
            simulation.advance(1)
            angle = simulation.joint_positions()['swing']
            if previous > 0.0 >= angle:
                fraction = previous / (previous - angle)
                crossings.append(simulation.time - TIME_STEP + fraction * TIME_STEP)
            previous = angle
            assert simulation.time < 10.0 * swings * exact_period(amplitude), 'it never swung'
    return (crossings[-1] - crossings[0]) / swings


SMALL_AMPLITUDE = 0.01  # rad
LARGE_AMPLITUDE = 2.0  # rad (115 degrees)


def test_a_pendulums_small_swing_has_the_compound_pendulums_period(tmp_path):
    analytic = small_angle_period()
    simulated = simulated_period(tmp_path, SMALL_AMPLITUDE)
    assert abs(relative_error(analytic, simulated)) < 1e-4
    assert_documented('pendulum period, 0.01 rad amplitude (s)', analytic, simulated)


def test_a_pendulums_large_swing_has_the_elliptic_integrals_period(tmp_path):
    analytic = exact_period(LARGE_AMPLITUDE)
    assert analytic > 1.3 * small_angle_period()  # far from the small-angle value
    simulated = simulated_period(tmp_path, LARGE_AMPLITUDE)
    assert abs(relative_error(analytic, simulated)) < 1e-4
    assert_documented('pendulum period, 2 rad amplitude (s)', analytic, simulated)


def test_the_agm_period_is_the_series_for_the_complete_elliptic_integral():
    # T / T0 = 1 + q^2/4 + 9 q^4/64 + ..., q = sin(amplitude / 2): an independent check.
    q = math.sin(0.3 / 2.0)
    series = 1 + q ** 2 / 4 + 9 * q ** 4 / 64 + 25 * q ** 6 / 256 + 1225 * q ** 8 / 16384
    assert exact_period(0.3) / small_angle_period() == pytest.approx(series, rel=1e-8)


# --- objects: free fall, and a box sliding to rest ------------------------------------------

def world(folder: pathlib.Path):
    """A simulation of a fixed robot (the pendulum, out of the way) and its Entities."""
    urdf = folder / 'pendulum.urdf'
    urdf.write_text(pendulum_urdf(), encoding='utf-8')
    controllers = folder / 'broadcaster.yaml'
    controllers.write_text(BROADCASTER_ONLY, encoding='utf-8')
    simulation = make_simulation(str(urdf), str(controllers), TIME_STEP)
    return simulation, Entities(simulation.physics, simulation.description.name)


FALL_TIME = 1.0  # s
DROP_HEIGHT = 10.0  # m


def test_a_dropped_box_falls_half_g_t_squared(tmp_path):
    simulation, entities = world(tmp_path)
    with simulation:
        entities.spawn('box', resource_string=grasp_box_urdf(size=0.1, mass=1.0),
                       pose=Transform((5.0, 0.0, DROP_HEIGHT)))
        simulation.advance(round(FALL_TIME / TIME_STEP))
        fallen = DROP_HEIGHT - entities.state('box').pose.translation[2]
        entities.close()
    analytic = 0.5 * G * FALL_TIME ** 2
    # PyBullet integrates velocity, then position with the new velocity (semi-implicit Euler):
    # after n steps the drop is g dt^2 n (n + 1) / 2, ahead of the exact one by g dt t / 2.
    n = round(FALL_TIME / TIME_STEP)
    assert fallen == pytest.approx(G * TIME_STEP ** 2 * n * (n + 1) / 2.0, rel=1e-9)
    assert abs(relative_error(analytic, fallen)) < 2e-3
    assert_documented('free fall for 1 s (m)', analytic, fallen)


SLIDE_SPEED = 2.0  # m/s
BOX_MU = 0.5  # the box's <mu1>/<mu2>: on the ground, the contact's coefficient


def slide_distance(folder: pathlib.Path, mu: float | None) -> tuple[float, float]:
    """Launch a 10 cm box along x on the ground; return how far it slid and its final speed."""
    simulation, entities = world(folder)
    with simulation:
        entities.spawn('box', resource_string=grasp_box_urdf(size=0.1, mass=1.0, mu=mu),
                       pose=Transform((5.0, 0.0, 0.05)))
        simulation.advance(200)  # settled on the ground
        start = entities.state('box').pose
        entities.set_state('box', EntityState(start, (SLIDE_SPEED, 0.0, 0.0)))
        simulation.advance(1500)
        state = entities.state('box')
        entities.close()
    return state.pose.translation[0] - start.translation[0], math.hypot(*state.linear)


def test_a_box_slides_to_rest_in_v_squared_over_two_mu_g(tmp_path):
    distance, speed = slide_distance(tmp_path, BOX_MU)
    assert speed < 1e-3  # at rest
    # Gazebo's ODE takes min(box 0.5, ground plane 100) = 0.5; PyBullet multiplies the two
    # surfaces' values and the ground's is 1, so the product is the box's own 0.5 too.
    analytic = SLIDE_SPEED ** 2 / (2.0 * BOX_MU * G)
    assert abs(relative_error(analytic, distance)) < 0.02
    assert_documented('box sliding to rest from 2 m/s, μ 0.5 (m)', analytic, distance)


def test_without_friction_tags_the_box_slides_on_pybullets_own_coefficient(tmp_path):
    distance, _speed = slide_distance(tmp_path, None)
    # PyBullet's 0.5 for the box times the ground's 1: Gazebo's would be its default 1.
    assert distance == pytest.approx(
        SLIDE_SPEED ** 2 / (2.0 * PYBULLET_DEFAULT_FRICTION * G), rel=0.02)


# --- a wheel rolling without slip, and its odometry -----------------------------------------

DRIVE_SPEED = 0.2  # m/s
SETTLE_S, WINDOW_S = 1.0, 4.0


@pytest.fixture(scope='module')
def rolling(tmp_path_factory) -> dict[str, float]:
    """Drive the rover straight; over WINDOW_S after SETTLE_S, what moved how far."""
    description, controllers = write_rover(tmp_path_factory.mktemp('rover'))
    with make_simulation(str(description), str(controllers), TIME_STEP,
                         fixed_base=None) as simulation:
        controller = simulation.controller(CONTROLLER)
        odometry = []
        controller.set_odometry_sink(lambda _time, x, *_rest: odometry.append(x))

        def drive(seconds: float) -> None:
            for _ in range(round(seconds / TIME_STEP)):
                controller.set_command(StampedTwist(0.0, (DRIVE_SPEED, 0.0, 0.0),
                                                    (0.0, 0.0, 0.0)))
                simulation.advance(1)

        def sample() -> tuple[float, float, float]:
            wheels = simulation.joint_positions()
            turned = (wheels['left_wheel_joint'] + wheels['right_wheel_joint']) / 2.0
            return simulation.physics.base_frame().translation[0], turned, odometry[-1]

        drive(SETTLE_S)
        x0, turned0, odom0 = sample()
        drive(WINDOW_S)
        x1, turned1, odom1 = sample()
    return {'travelled': x1 - x0, 'rolled': WHEEL_RADIUS * (turned1 - turned0),
            'odometry': odom1 - odom0}


def test_a_wheel_rolling_without_slip_carries_the_base_r_times_its_turn(rolling):
    measured = rolling
    analytic = measured['rolled']  # r * the wheels' measured turn
    assert analytic == pytest.approx(DRIVE_SPEED * WINDOW_S, rel=0.01)
    assert abs(relative_error(analytic, measured['travelled'])) < 1e-3
    assert_documented('wheel rolling 4 s at 0.2 m/s: base travel vs r·Δφ (m)', analytic,
                      measured['travelled'])


def test_the_odometry_of_the_rolling_wheels_is_omega_r_t(rolling):
    measured = rolling
    analytic = (DRIVE_SPEED / WHEEL_RADIUS) * WHEEL_RADIUS * WINDOW_S  # omega r t
    assert abs(relative_error(analytic, measured['odometry'])) < 1e-3
    assert_documented('odometry of that drive vs ω·r·t (m)', analytic, measured['odometry'])


# --- a gripper holding a box against gravity ------------------------------------------------

GRIP_MU = FINGER_MU * PYBULLET_DEFAULT_FRICTION  # fingers' 2.0 times the untagged box's 0.5
LIFT = 0.15  # m
HELD = 1e-3  # m: the most a held box may sink in the second after the grip is set
HOLD_S = 1.0


def squeeze_threshold() -> float:
    """The weakest max_effort that holds the box: 2 mu N = m g, with N = max_effort / 2.

    One actuator drives both fingers, the second a 1:1 ``<mimic>`` of the
    first: by virtual work, F dq = N dq + N dq, so each finger presses with
    half the actuator's force.
    """
    return BOX_MASS * G / GRIP_MU


def hold(folder: pathlib.Path, max_effort: float) -> tuple[float, tuple[float, float]]:
    """Lift the box in a firm grip, then squeeze with ``max_effort`` for HOLD_S.

    Returns how far the box sank meanwhile, and the normal force of each
    finger's contacts with it during the firm grip (N).
    """
    urdf, controllers = write_gripper_arm(folder)
    with make_simulation(str(urdf), str(controllers), TIME_STEP) as simulation:
        entities = Entities(simulation.physics, simulation.description.name)
        gripper = simulation.controller('gripper_controller')

        def run_goal(request: GripperRequest) -> None:
            goal = gripper.start_goal(request, simulation.time)
            for _ in range(300):
                if goal.done:
                    break
                simulation.advance(10)

        firm = 2.0 * squeeze_threshold()
        run_goal(GripperRequest(FINGER_OPEN, firm))
        entities.spawn('box', resource_string=grasp_box_urdf(),
                       pose=Transform((0.0, 0.0, BOX_SIZE / 2)))
        simulation.advance(100)
        run_goal(GripperRequest(0.0, firm))
        simulation.controller('lift_controller').set_command(LIFT)
        simulation.advance(2000)
        lifted = entities.state('box').pose.translation[2]
        assert lifted == pytest.approx(BOX_SIZE / 2 + LIFT, abs=2e-3), 'the firm grip slipped'
        physics = simulation.physics
        normals = tuple(
            sum(point[CONTACT_NORMAL_FORCE] for point in pybullet.getContactPoints(
                bodyA=entities.get('box').body, bodyB=physics.body_id,
                linkIndexB=physics.link_index(finger), physicsClientId=physics.client_id))
            for finger in ('left_finger', 'right_finger'))
        # The same closing goal with the grip under test.
        gripper.start_goal(GripperRequest(0.0, max_effort), simulation.time)
        simulation.advance(round(HOLD_S / TIME_STEP))
        sunk = lifted - entities.state('box').pose.translation[2]
        entities.close()
    return sunk, normals


def holds(folder: pathlib.Path, max_effort: float) -> bool:
    return hold(folder, max_effort)[0] < HELD


def test_each_finger_presses_with_half_the_actuators_force(tmp_path):
    _sunk, normals = hold(tmp_path, squeeze_threshold())
    firm = 2.0 * squeeze_threshold()
    assert normals == pytest.approx((firm / 2.0, firm / 2.0), rel=1e-3)


@pytest.mark.slow
def test_a_gripper_holds_a_box_while_two_mu_n_carries_m_g_and_drops_it_below(tmp_path):
    analytic = squeeze_threshold()
    low, high = 0.95 * analytic, 1.10 * analytic
    assert not holds(tmp_path, low)  # below: it slips out
    assert holds(tmp_path, high)  # above: held
    while high - low > 2.5e-3 * analytic:  # bisection to a quarter of a percent
        middle = (low + high) / 2.0
        if holds(tmp_path, middle):
            high = middle
        else:
            low = middle
    simulated = (low + high) / 2.0
    assert abs(relative_error(analytic, simulated)) < 0.06
    assert_documented('gripper: weakest max_effort holding a 0.2 kg box, μ 1.0 (N)', analytic,
                      simulated)


# --- a PID step response against the closed-loop model --------------------------------------

INERTIA = 0.01  # kg m^2 about the joint axis (the link's centre of mass is on it)
KP, KD = 10.0, 0.2  # N m/rad, N m s/rad
STEP = 0.5  # rad
MAX_VELOCITY = 100.0  # rad/s: the URDF limit the setpoint ramps at
RESPONSE_S = 1.0


def pid_joint_urdf() -> str:
    return f"""<?xml version="1.0"?>
<robot name="turntable">
  <link name="base_link"><inertial><mass value="10"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="turn" type="revolute">
    <parent link="base_link"/><child link="table"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 0 1"/><dynamics damping="0" friction="0"/>
    <limit lower="-3" upper="3" effort="1000" velocity="{MAX_VELOCITY}"/>
  </joint>
  <link name="table">
    <inertial><mass value="1"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="{INERTIA}"/></inertial>
  </link>
</robot>
"""


PID_YAML = f"""\
controller_manager:
  ros__parameters:
    update_rate: {round(1 / TIME_STEP)}
    turn_controller:
      type: effort_controllers/JointPositionController
turn_controller:
  ros__parameters:
    joint: turn
    pid: {{p: {KP}, i: 0.0, d: {KD}}}
"""


def closed_loop_model(times: numpy.ndarray) -> numpy.ndarray:
    """I theta'' = p (r(t) - theta) - d theta', r ramping to STEP at MAX_VELOCITY; RK4."""
    def reference(t: float) -> float:
        return min(MAX_VELOCITY * t, STEP)

    def derivative(t: float, state: numpy.ndarray) -> numpy.ndarray:
        angle, rate = state
        return numpy.array([rate, (KP * (reference(t) - angle) - KD * rate) / INERTIA])

    h = TIME_STEP / 20.0
    state, t, out = numpy.zeros(2), 0.0, []
    for target in times:
        while t < target - 1e-12:
            k1 = derivative(t, state)
            k2 = derivative(t + h / 2, state + h / 2 * k1)
            k3 = derivative(t + h / 2, state + h / 2 * k2)
            k4 = derivative(t + h, state + h * k3)
            state, t = state + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4), t + h
        out.append(state[0])
    return numpy.array(out)


@pytest.fixture(scope='module')
def step_response(tmp_path_factory) -> tuple[numpy.ndarray, numpy.ndarray]:
    """Step the turntable's command by STEP at t = 0; its angle every step, with the times."""
    folder = tmp_path_factory.mktemp('turntable')
    urdf = folder / 'turntable.urdf'
    urdf.write_text(pid_joint_urdf(), encoding='utf-8')
    controllers = folder / 'pid.yaml'
    controllers.write_text(PID_YAML, encoding='utf-8')
    with make_simulation(str(urdf), str(controllers), TIME_STEP) as simulation:
        simulation.controller('turn_controller').set_command(STEP)
        times, angles = [], []
        for _ in range(round(RESPONSE_S / TIME_STEP)):
            simulation.advance(1)
            times.append(simulation.time)
            angles.append(simulation.joint_positions()['turn'])
    return numpy.array(times), numpy.array(angles)


def discrete_closed_loop(steps: int) -> numpy.ndarray:
    """The same loop as a sampled system: effort held over each step, semi-implicit Euler.

    Each step the PD law acts on the state at the step's start, the
    setpoint already one ramp step further, and the velocity is updated
    before the angle -- the discretisation PyBullet and the controller make.
    """
    angle, rate, out = 0.0, 0.0, []
    for k in range(steps):
        setpoint = min(MAX_VELOCITY * (k + 1) * TIME_STEP, STEP)
        rate += (KP * (setpoint - angle) - KD * rate) / INERTIA * TIME_STEP
        angle += rate * TIME_STEP
        out.append(angle)
    return numpy.array(out)


def overshoot_percent(angles: numpy.ndarray) -> float:
    return 100.0 * (angles.max() - STEP) / STEP


def test_a_pid_step_overshoots_as_the_closed_loop_model(step_response):
    times, angles = step_response
    model = closed_loop_model(times)
    # The model itself: an underdamped second-order loop (zeta 0.32) reaching the step.
    assert 0.3 < KD / (2.0 * math.sqrt(KP * INERTIA)) < 0.35
    assert model[-1] == pytest.approx(STEP, abs=1e-3)
    analytic, simulated = overshoot_percent(model), overshoot_percent(angles)
    assert abs(simulated - analytic) < 1.0  # percentage points
    assert_documented('PID step 0.5 rad, I 0.01 kg·m², p 10, d 0.2: overshoot (%)', analytic,
                      simulated)


def test_a_pid_step_follows_the_continuous_model_within_a_step_of_lead(step_response):
    times, angles = step_response
    deviation = 100.0 * numpy.abs(angles - closed_loop_model(times)).max() / STEP
    # The sampled loop runs about one step ahead of the continuous one (see
    # discrete_closed_loop): the deviation is the response's rise over one step.
    assert deviation < 3.0
    assert_documented('PID step: largest deviation from the continuous model (% of the step)',
                      0.0, deviation)


def test_a_pid_step_is_the_discrete_closed_loop_solution(step_response):
    _times, angles = step_response
    deviation = 100.0 * numpy.abs(angles - discrete_closed_loop(len(angles))).max() / STEP
    assert deviation < 1e-9
    row = doc_row('PID step: largest deviation from the discrete closed-loop solution '
                  '(% of the step)')
    assert row['simulated'] == '< 1e-9'
