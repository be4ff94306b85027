"""ackermann_steering_controller/AckermannSteeringController: its kinematics, by hand.

The car of test/support/steering_fixtures.py: wheelbase 0.3 m, track 0.25 m, wheel
radius 0.05 m.  A twist of 0.2 m/s and 0.2 rad/s turns about a centre 1 m to
the left of the rear axle's middle: the centre steering angle is atan(0.3),
the right (outer) wheel steers to atan(0.3 / 1.125) and the left to
atan(0.3 / 0.875); the rear wheels roll 1.125 m and 0.875 m of arc per metre,
4.5 and 3.5 rad/s.  The joints are ideal (steering_harness.py).
"""

from __future__ import annotations

import math

import pytest
from steering_fixtures import ACKERMANN, steering_parameters
from steering_harness import DT, configured, run, twist

from pan_tilt_sim.errors import ControllerConfigError

PHI = math.atan(0.3)
RIGHT_ANGLE, LEFT_ANGLE = math.atan(0.3 / 1.125), math.atan(0.3 / 0.875)


def car(**overrides):
    """Return the configured controller and its joints for the fixture car."""
    return configured(ACKERMANN, steering_parameters(ACKERMANN, **overrides))


def test_a_twist_steers_each_front_wheel_about_the_common_centre_and_drives_the_rear_apart():
    controller, joints = car(open_loop=True)
    controller.set_command(twist(0.2, 0.2))
    controller.update(0.0, DT)
    assert controller.steering_commands == pytest.approx([RIGHT_ANGLE, LEFT_ANGLE])
    assert joints['rear_right_wheel_joint'].velocity_target == pytest.approx(4.5)
    assert joints['rear_left_wheel_joint'].velocity_target == pytest.approx(3.5)


def test_in_closed_loop_the_rear_wheels_follow_the_measured_steering_not_the_command():
    controller, joints = car()
    controller.set_command(twist(0.2, 0.2))
    controller.update(0.0, DT)
    # The steering still stands straight: both wheels at v / r, both steering joints at phi.
    assert controller.steering_commands == pytest.approx([PHI, PHI])
    assert joints['rear_right_wheel_joint'].velocity_target == pytest.approx(4.0)
    joints['front_right_steering_joint'].position = RIGHT_ANGLE
    joints['front_left_steering_joint'].position = LEFT_ANGLE
    controller.update(0.01, DT)
    assert controller.odometry.steering_angle == pytest.approx(PHI)
    assert joints['rear_right_wheel_joint'].velocity_target == pytest.approx(4.5)
    assert joints['rear_left_wheel_joint'].velocity_target == pytest.approx(3.5)
    assert controller.steering_commands == pytest.approx([RIGHT_ANGLE, LEFT_ANGLE])


@pytest.mark.parametrize('position_feedback', [False, True])
def test_the_odometry_follows_the_arc_of_one_metre_radius(position_feedback):
    controller, joints = car(position_feedback=position_feedback)
    run(controller, joints, 2.0, command=twist(0.2, 0.2))
    odometry = controller.odometry
    # On the circle about (0, 1) of radius 1; the heading is the arc turned so far.
    assert math.hypot(odometry.x, odometry.y - 1.0) == pytest.approx(1.0, abs=1e-3)
    assert odometry.heading == pytest.approx(math.atan2(odometry.x, 1.0 - odometry.y), abs=1e-3)
    assert odometry.heading == pytest.approx(0.4, abs=0.01)
    assert (odometry.linear, odometry.angular) == pytest.approx((0.2, 0.2), abs=1e-6)


def test_the_steering_track_defaults_to_the_traction_track_and_may_differ():
    controller, _ = car(open_loop=True, steering_track_width=0.45)
    controller.set_command(twist(0.2, 0.2))
    controller.update(0.0, DT)
    assert controller.steering_commands == pytest.approx(
        [math.atan(0.3 / 1.225), math.atan(0.3 / 0.775)])


def test_the_deprecated_radius_and_tracks_still_count_with_a_warning():
    controller, joints = car(open_loop=True, traction_wheels_radius=0.0, rear_wheels_radius=0.1,
                             traction_track_width=0.0, rear_wheel_track=0.25,
                             front_wheel_track=0.45)
    controller.set_command(twist(0.2, 0.2))
    controller.update(0.0, DT)
    assert joints['rear_right_wheel_joint'].velocity_target == pytest.approx(2.25)
    assert controller.steering_commands[0] == pytest.approx(math.atan(0.3 / 1.225))
    assert [line.split(': ')[1] for line in controller.config_warnings] == [
        'steering_controller.rear_wheels_radius', 'steering_controller.front_wheel_track',
        'steering_controller.rear_wheel_track']


def test_without_a_traction_wheel_radius_it_refuses_to_start():
    with pytest.raises(ControllerConfigError, match=r'^car\.yaml: steering_controller\.'
                       r'traction_wheels_radius: not set'):
        car(traction_wheels_radius=0.0)


def test_one_steering_joint_is_not_enough():
    with pytest.raises(ControllerConfigError, match=r'steering_controller\.steering_joints_names: '
                       'Ackermann configuration requires exactly two steering joints, but 1 '
                       'were provided'):
        car(steering_joints_names=['front_right_steering_joint'])
