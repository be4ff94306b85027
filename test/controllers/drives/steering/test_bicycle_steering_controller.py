"""bicycle_steering_controller/BicycleSteeringController: its kinematics, by hand.

Wheelbase 0.3 m, wheel radius 0.05 m: a twist of 0.2 m/s and 0.2 rad/s
steers the front wheel to atan(0.3) and turns the rear wheel at 4 rad/s; the
rear wheel's middle runs on a circle of 1 m.  The joints are ideal
(steering_harness.py).
"""

from __future__ import annotations

import math

import pytest
from steering_fixtures import BICYCLE, steering_parameters
from steering_harness import DT, configured, run, twist

from pan_tilt_sim.errors import ControllerConfigError


def bicycle(**overrides):
    """Return the configured controller and its joints for the fixture bicycle."""
    return configured(BICYCLE, steering_parameters(BICYCLE, **overrides))


@pytest.mark.parametrize('linear, angular, angle, wheel', [
    (0.2, 0.2, math.atan(0.3), 4.0),
    (-0.2, 0.2, -math.atan(0.3), -4.0),  # backwards the wheel steers the other way
    (0.2, 0.0, 0.0, 4.0),
    (0.0, 0.5, math.pi / 2, 0.0),  # turning on the spot: across, standing
    (0.0, 0.0, 0.0, 0.0),
])
def test_a_twist_gives_the_steering_angle_and_the_wheel_speed(linear, angular, angle, wheel):
    controller, joints = bicycle()
    controller.set_command(twist(linear, angular))
    controller.update(0.0, DT)
    assert controller.steering_commands == pytest.approx([min(angle, 0.6)])
    assert joints['rear_wheel_joint'].velocity_target == pytest.approx(wheel)


def test_the_odometry_follows_the_arc_of_one_metre_radius():
    controller, joints = bicycle()
    run(controller, joints, 2.0, command=twist(0.2, 0.2))
    odometry = controller.odometry
    assert math.hypot(odometry.x, odometry.y - 1.0) == pytest.approx(1.0, abs=1e-3)
    assert odometry.heading == pytest.approx(0.4, abs=0.01)


def test_the_deprecated_radius_still_counts_with_a_warning():
    controller, joints = bicycle(traction_wheel_radius=0.0, rear_wheel_radius=0.1)
    controller.set_command(twist(0.2, 0.0))
    controller.update(0.0, DT)
    assert joints['rear_wheel_joint'].velocity_target == pytest.approx(2.0)
    assert 'rear_wheel_radius: deprecated' in controller.config_warnings[0]


def test_two_traction_joints_are_refused():
    with pytest.raises(ControllerConfigError, match=r'traction_joints_names: Bicycle '
                       'configuration requires exactly one traction joint, but 2 were provided'):
        bicycle(traction_joints_names=['rear_wheel_joint', 'other_wheel_joint'])
