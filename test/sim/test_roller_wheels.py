"""Wheels with free rollers on the ground: the base moves by contact forces, as the rollers allow.

The mecanum base of test/support/roller_fixtures.py stands free on its four wheels,
the omni base on its three; their controllers' wheel speeds are the only
thing driving them, and the roller friction
(pan_tilt_sim/sim/roller_wheels.py) is the only grip the wheels have.
Each drive is closed loop on the controller's odometry, as a navigation
stack would drive it; the true pose is PyBullet's.
"""

from __future__ import annotations

import math

import pytest
from roller_fixtures import (
    CONTROLLER,
    REST_HEIGHT,
    mecanum_joints,
    omni_joints,
    write_mecanum,
    write_omni,
)

from pan_tilt_sim.controllers.framework.surface import StampedTwist
from pan_tilt_sim.sim.bullet import pybullet
from pan_tilt_sim.sim.engine import make_simulation

TIME_STEP = 0.001
UPDATE_STEPS = 10  # one controller update at 100 Hz
FRICTION = 1  # index of the lateral friction in pybullet.getDynamicsInfo


def mecanum(tmp_path, friction=None):
    """Return a Simulation of the mecanum base, free on the ground (wheels' ``friction``)."""
    description, controllers = write_mecanum(tmp_path, friction=friction)
    return make_simulation(str(description), str(controllers), TIME_STEP, fixed_base=None)


def omni(tmp_path):
    """Return a Simulation of the omni base, free on the ground."""
    description, controllers = write_omni(tmp_path)
    return make_simulation(str(description), str(controllers), TIME_STEP, fixed_base=None)


def drive_until(simulation, velocity: tuple[float, float, float], done) -> None:
    """Command ``velocity`` (vx, vy, wz) until ``done(odometry)``, then stop and settle."""
    controller = simulation.controller(CONTROLLER)
    vx, vy, wz = velocity
    for _ in range(20000):
        if done(controller.odometry):
            break
        controller.set_command(StampedTwist(0.0, (vx, vy, 0.0), (0.0, 0.0, wz)))
        simulation.advance(UPDATE_STEPS)
    else:
        pytest.fail('the odometry never got there')
    for _ in range(100):
        controller.set_command(StampedTwist(0.0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)))
        simulation.advance(UPDATE_STEPS)


def yaw(rotation) -> float:
    """Return the heading of a quaternion that turns about z only."""
    return 2.0 * math.atan2(rotation[2], rotation[3])


def turns_a_quarter_on_the_spot(simulation) -> None:
    """Turn the base a quarter on the spot by its odometry; check the true heading agrees."""
    drive_until(simulation, (0.0, 0.0, 0.5),
                lambda odometry: odometry.heading >= math.pi / 2)
    frame = simulation.physics.base_frame()
    heading = yaw(frame.rotation)
    assert heading == pytest.approx(math.pi / 2, rel=0.02)
    assert simulation.controller(CONTROLLER).odometry.heading == pytest.approx(
        heading, rel=0.02)
    assert math.hypot(*frame.translation[:2]) < 0.02


def wheel_frictions(simulation, joints: list[str]) -> list[float]:
    """Return PyBullet's lateral friction of each wheel link of ``joints``."""
    physics = simulation.physics
    return [pybullet.getDynamicsInfo(physics.body_id, physics.joint_index(joint),
                                     physicsClientId=physics.client_id)[FRICTION]
            for joint in joints]


def test_one_metre_forward_the_odometry_agrees_with_the_true_pose(tmp_path):
    with mecanum(tmp_path) as simulation:
        drive_until(simulation, (0.2, 0.0, 0.0), lambda odometry: odometry.x >= 1.0)
        (x, y, z), odometry = simulation.physics.base_frame().translation, simulation.controller(
            CONTROLLER).odometry
        assert x == pytest.approx(1.0, rel=0.02)
        assert odometry.x == pytest.approx(x, rel=0.02)
        assert abs(y) < 0.02 and abs(odometry.y) < 0.02
        assert z == pytest.approx(REST_HEIGHT, abs=2e-3)  # upright, on its wheels


def test_one_metre_sideways_the_rollers_let_it_strafe_and_the_odometry_agrees(tmp_path):
    with mecanum(tmp_path) as simulation:
        drive_until(simulation, (0.0, 0.2, 0.0), lambda odometry: odometry.y >= 1.0)
        frame, odometry = simulation.physics.base_frame(), simulation.controller(
            CONTROLLER).odometry
        x, y, _ = frame.translation
        assert y == pytest.approx(1.0, rel=0.02)
        assert odometry.y == pytest.approx(y, rel=0.02)
        assert abs(x) < 0.02 and abs(yaw(frame.rotation)) < 0.02


def test_a_quarter_turn_on_the_spot_the_odometry_agrees_with_the_true_heading(tmp_path):
    with mecanum(tmp_path) as simulation:
        turns_a_quarter_on_the_spot(simulation)


def test_the_grip_across_the_rollers_is_bounded_by_the_wheels_friction(tmp_path):
    # Each wheel pushes along its traction direction, 45 degrees off x, with at most mu N:
    # together at most mu g / sqrt(2) of forward acceleration, however fast the wheels spin.
    mu = 0.1
    with mecanum(tmp_path, friction=mu) as simulation:
        controller = simulation.controller(CONTROLLER)
        for _ in range(20):  # 0.2 s asking for 2 m/s at once
            controller.set_command(StampedTwist(0.0, (2.0, 0.0, 0.0), (0.0, 0.0, 0.0)))
            simulation.advance(UPDATE_STEPS)
        (speed, _, _), _ = simulation.physics.base_velocity()
        most = mu * 9.81 / math.sqrt(2.0) * 0.2
        assert 0.8 * most < speed < 1.05 * most


def test_the_roller_wheels_have_no_pybullet_friction_while_their_controller_is_active(tmp_path):
    with mecanum(tmp_path) as simulation:
        assert wheel_frictions(simulation, mecanum_joints()) == [0.0] * 4
        simulation.manager.switch(deactivate=[CONTROLLER])
        assert wheel_frictions(simulation, mecanum_joints()) == [1.0] * 4



@pytest.mark.parametrize('velocity, axis', [((0.2, 0.0, 0.0), 0), ((0.0, 0.2, 0.0), 1)])
def test_the_omni_base_drives_one_metre_forward_or_sideways_and_the_odometry_agrees(
        tmp_path, velocity, axis):
    with omni(tmp_path) as simulation:
        drive_until(simulation, velocity,
                    lambda odometry: (odometry.x, odometry.y)[axis] >= 1.0)
        frame, odometry = simulation.physics.base_frame(), simulation.controller(
            CONTROLLER).odometry
        travelled = frame.translation[axis]
        assert travelled == pytest.approx(1.0, rel=0.02)
        assert (odometry.x, odometry.y)[axis] == pytest.approx(travelled, rel=0.02)
        assert abs(frame.translation[1 - axis]) < 0.02 and abs(yaw(frame.rotation)) < 0.02


def test_the_omni_base_turns_a_quarter_on_the_spot_and_the_odometry_agrees(tmp_path):
    with omni(tmp_path) as simulation:
        turns_a_quarter_on_the_spot(simulation)


def test_the_omni_wheels_have_no_pybullet_friction_while_their_controller_is_active(tmp_path):
    with omni(tmp_path) as simulation:
        assert wheel_frictions(simulation, omni_joints()) == [0.0] * 3
