"""tricycle_steering_controller/TricycleSteeringController: its kinematics, by hand.

Wheelbase 0.3 m, rear track 0.25 m, wheel radius 0.05 m: a twist of
0.2 m/s and 0.2 rad/s steers the front wheel to atan(0.3), and once it is
there the rear wheels turn at 4.5 (right, outer) and 3.5 rad/s.  The joints
are ideal (steering_harness.py).
"""

from __future__ import annotations

import math

import pytest
from steering_fixtures import TRICYCLE, steering_parameters
from steering_harness import DT, configured, run, twist

from pan_tilt_sim.errors import ControllerConfigError


def tricycle(**overrides):
    """Return the configured controller and its joints for the fixture tricycle."""
    return configured(TRICYCLE, steering_parameters(TRICYCLE, **overrides))


def test_a_twist_steers_the_front_wheel_and_drives_the_rear_wheels_apart():
    controller, joints = tricycle()
    controller.set_command(twist(0.2, 0.2))
    controller.update(0.0, DT)
    assert controller.steering_commands == pytest.approx([math.atan(0.3)])
    assert joints['rear_right_wheel_joint'].velocity_target == pytest.approx(4.0)
    joints['front_steering_joint'].position = math.atan(0.3)
    controller.update(0.01, DT)
    assert joints['rear_right_wheel_joint'].velocity_target == pytest.approx(4.5)
    assert joints['rear_left_wheel_joint'].velocity_target == pytest.approx(3.5)


def test_the_odometry_follows_the_arc_of_one_metre_radius():
    controller, joints = tricycle()
    run(controller, joints, 2.0, command=twist(0.2, 0.2))
    odometry = controller.odometry
    assert math.hypot(odometry.x, odometry.y - 1.0) == pytest.approx(1.0, abs=1e-3)
    assert odometry.heading == pytest.approx(0.4, abs=0.01)
    assert odometry.linear == pytest.approx(0.2, abs=1e-6)


def test_the_deprecated_wheel_track_still_counts_with_a_warning():
    controller, joints = tricycle(traction_track_width=0.0, wheel_track=0.5, open_loop=True)
    controller.set_command(twist(0.2, 0.2))
    controller.update(0.0, DT)
    assert joints['rear_right_wheel_joint'].velocity_target == pytest.approx(5.0)
    assert 'wheel_track: deprecated' in controller.config_warnings[0]


def test_without_a_track_width_it_refuses_to_start():
    with pytest.raises(ControllerConfigError, match=r'^car\.yaml: steering_controller\.'
                       r'traction_track_width: not set'):
        tricycle(traction_track_width=0.0)


def test_the_odometry_takes_each_rear_wheel_along_its_own_arc():
    controller, joints = tricycle(velocity_rolling_window_size=1)
    joints['front_steering_joint'].position = math.atan(0.3)  # about a centre 1 m to the left
    joints['rear_right_wheel_joint'].velocity = 4.5  # on 1.125 m of radius
    joints['rear_left_wheel_joint'].velocity = 3.0  # on 0.875 m
    controller.update(0.0, DT)
    linear = (4.5 / 1.125 + 3.0 / 0.875) / 2.0 * 0.05
    assert controller.odometry.linear == pytest.approx(linear)
    assert controller.odometry.angular == pytest.approx(linear / 1.0)
