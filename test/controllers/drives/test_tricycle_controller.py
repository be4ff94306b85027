"""tricycle_controller/TricycleController on its own: kinematics, limits, timeout, odometry.

The tricycle of test/support/steering_fixtures.py: its front wheel steers and
drives, 0.3 m ahead of the rear axle, radius 0.05 m.  A twist of 0.2 m/s and
0.2 rad/s (a circle of 1 m about the rear axle's middle) steers it to
atan(0.3) and rolls it at 0.2 / (0.05 cos(atan(0.3))) = 4 sqrt(1.09) rad/s.
The joints are ideal: the steering stands where it is sent, the wheel turns
as commanded.
"""

from __future__ import annotations

import math

import pytest
from steering_fixtures import TRICYCLE_CONTROLLER, WHEEL_RADIUS, WHEELBASE
from steering_harness import DT, twist

from pan_tilt_sim.controllers import JointHandle
from pan_tilt_sim.controllers.drives.tricycle_controller import TricycleController
from pan_tilt_sim.controllers.framework.base import ActuatorKind, CommandResult
from pan_tilt_sim.controllers.framework.registry import create_controller, drives_base
from pan_tilt_sim.controllers.framework.surface import CommandTopic, Service, StateTopic
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.robot import JointKind, JointSpec

NAME = 'tricycle_controller'
WHEEL, STEERING = 'front_wheel_joint', 'front_steering_joint'
PHI = math.atan(0.3)


def tricycle(**overrides) -> tuple[TricycleController, dict[str, JointHandle]]:
    """Return a configured controller over the front wheel, and the joints' handles."""
    params = {'traction_joint_name': WHEEL, 'steering_joint_name': STEERING,
              'wheelbase': WHEELBASE, 'wheel_radius': WHEEL_RADIUS, **overrides}
    joints = {WHEEL: JointHandle(JointSpec(WHEEL, JointKind.CONTINUOUS, velocity_limit=40.0)),
              STEERING: JointHandle(JointSpec(STEERING, JointKind.REVOLUTE, -1.6, 1.6,
                                              velocity_limit=3.0))}
    controller = create_controller(NAME, TRICYCLE_CONTROLLER, params, 'trike.yaml')
    controller.configure(joints)
    return controller, joints


def run(controller, joints, seconds, start=0.0, command=None) -> float:
    """Step ``seconds`` with ideal joints, resending ``command``; return the end time."""
    steps = round(seconds / DT)
    for step in range(steps):
        if command is not None:
            assert controller.set_command(command) is CommandResult.ACCEPTED
        controller.update(start + step * DT, DT)
        joints[STEERING].position = controller.limited_command[1]
        joints[WHEEL].velocity = joints[WHEEL].velocity_target
        joints[WHEEL].position += joints[WHEEL].velocity_target * DT
    return start + steps * DT


@pytest.mark.parametrize('linear, angular, angle, speed', [
    (0.2, 0.2, PHI, 4.0 * math.sqrt(1.09)),
    (0.2, 0.0, 0.0, 4.0),
    (-0.2, 0.2, -PHI, -4.0 * math.sqrt(1.09)),
    (0.0, 0.5, math.pi / 2, 0.5 * 0.3 / 0.05),  # on the spot: across
    (0.0, -0.5, -math.pi / 2, 0.5 * 0.3 / 0.05),
    (0.0, 0.0, 0.0, 0.0),
])
def test_a_twist_gives_the_steering_angle_and_the_wheel_speed(linear, angular, angle, speed):
    controller, _ = tricycle()
    assert controller.twist_to_ackermann(linear, angular) == pytest.approx((angle, speed))


def test_the_command_drives_the_wheel_and_steers_it():
    controller, joints = tricycle()
    joints[STEERING].position = PHI  # already steered: full speed
    controller.set_command(twist(0.2, 0.2))
    controller.update(0.0, DT)
    assert joints[WHEEL].velocity_target == pytest.approx(4.0 * math.sqrt(1.09))
    assert controller.limited_command[1] == pytest.approx(PHI)
    assert controller.steering_command == pytest.approx(PHI)
    kinds = {joint: actuator.kind for joint, actuator in controller.actuators().items()}
    assert kinds == {WHEEL: ActuatorKind.IDEAL_VELOCITY, STEERING: ActuatorKind.IDEAL_POSITION}
    assert controller.command_interfaces() == {WHEEL: ('velocity',), STEERING: ('position',)}
    assert drives_base(TRICYCLE_CONTROLLER)


def test_far_from_its_command_the_steering_slows_the_wheel_by_the_cosine_of_the_error():
    controller, joints = tricycle()
    controller.set_command(twist(0.1, 2.0 * 0.1 / 0.3))  # atan(2): 1.107 rad from straight
    controller.update(0.0, DT)
    angle = math.atan(2.0)
    assert joints[WHEEL].velocity_target == pytest.approx(
        0.1 / (0.05 * math.cos(angle)) * math.cos(angle))


def test_before_a_command_and_once_it_is_stale_the_wheel_stops_and_steers_straight():
    controller, joints = tricycle(cmd_vel_timeout=200)
    run(controller, joints, 0.05)
    assert controller.limited_command == (0.0, 0.0)
    controller.set_command(twist(0.2, 0.2, stamp=0.05))
    run(controller, joints, 0.1, start=0.05)
    assert controller.limited_command[1] == pytest.approx(PHI)
    run(controller, joints, 0.2, start=0.15)
    assert controller.limited_command == (0.0, 0.0)
    assert joints[WHEEL].velocity_target == 0.0
    assert controller.notices == ['velocity command timed out (0.2 s without one at sim time '
                                  '0.260 s): stopping']


@pytest.mark.parametrize('linear, angular', [(math.nan, 0.0), (0.2, -math.inf)])
def test_a_twist_that_is_not_finite_is_refused_and_the_last_one_stays(linear, angular):
    controller, joints = tricycle()
    controller.set_command(twist(0.2, 0.0))
    run(controller, joints, 0.02)
    assert controller.set_command(twist(linear, angular)) is CommandResult.REJECTED
    assert 'not finite numbers' in controller.command_problem(None, CommandResult.REJECTED)
    run(controller, joints, 0.02, start=0.02)
    assert joints[WHEEL].velocity_target == pytest.approx(4.0)


def test_the_traction_acceleration_limit_ramps_the_wheel_speed():
    controller, joints = tricycle(**{'traction.max_acceleration': 10.0})
    run(controller, joints, 0.2, command=twist(0.2, 0.0))  # 20 updates at 100 Hz
    speeds = []
    for step in range(20):
        run(controller, joints, 0.01, start=0.2 + step * 0.01, command=twist(0.2, 0.0))
        speeds.append(controller.limited_command[0])
    assert speeds[0] == pytest.approx(2.1)  # 10 rad/s^2 from 0 at t = 0, 21 updates
    assert speeds[-1] == pytest.approx(4.0)
    assert all(b - a <= 0.1 + 1e-9 for a, b in zip(speeds, speeds[1:], strict=False))


def test_the_steering_limits_bound_the_angle_and_its_rate():
    controller, joints = tricycle(**{'steering.max_position': 0.2, 'steering.max_velocity': 1.0})
    run(controller, joints, 0.05, command=twist(0.2, 0.2))  # updates at 0, 10, ... 40 ms
    assert controller.limited_command[1] == pytest.approx(0.05)  # 1 rad/s for 5 updates
    run(controller, joints, 0.5, start=0.05, command=twist(0.2, 0.2))
    assert controller.limited_command[1] == pytest.approx(0.2)


@pytest.mark.parametrize('overrides, field, problem', [
    ({'traction.max_velocity': -1.0}, 'traction', 'limits cannot be negative'),
    ({'traction.min_acceleration': 2.0, 'traction.max_acceleration': 1.0}, 'traction',
     'min_acceleration 2 > max_acceleration 1'),
    ({'steering.max_velocity': -1.0}, 'steering', 'limits cannot be negative'),
    ({'steering_joint_name': WHEEL}, 'steering_joint_name', 'is also the traction_joint_name'),
    ({'wheel_radius': 0.0}, 'wheel_radius', 'must be > 0'),
])
def test_a_bad_parameter_is_refused_naming_it(overrides, field, problem):
    with pytest.raises(ControllerConfigError, match=rf'^trike\.yaml: {NAME}\.{field}: .*'
                       f'{problem}'):
        tricycle(**overrides)


def test_a_joint_the_robot_lacks_names_the_parameter():
    with pytest.raises(ControllerConfigError, match=rf"{NAME}\.steering_joint_name: joint "
                       "'front_steer' is not a movable joint"):
        tricycle(steering_joint_name='front_steer')


def test_the_odometry_follows_the_arc_of_one_metre_radius():
    controller, joints = tricycle()
    run(controller, joints, 2.0, command=twist(0.2, 0.2))
    odometry = controller.odometry
    assert math.hypot(odometry.x, odometry.y - 1.0) == pytest.approx(1.0, abs=2e-3)
    assert odometry.heading == pytest.approx(0.4, abs=0.02)
    assert (odometry.linear, odometry.angular) == pytest.approx((0.2, 0.2), abs=1e-6)


def test_reset_odometry_puts_it_back_at_the_origin():
    controller, joints = tricycle()
    run(controller, joints, 0.5, command=twist(0.2, 0.2))
    assert controller.odometry.x > 0.05
    controller.reset_odometry()
    assert (controller.odometry.x, controller.odometry.y, controller.odometry.heading) == (
        0.0, 0.0, 0.0)


def test_odom_only_twist_leaves_the_pose_at_zero():
    controller, joints = tricycle(odom_only_twist=True)
    samples = []
    controller.set_odometry_sink(lambda *sample: samples.append(sample))
    run(controller, joints, 0.5, command=twist(0.2, 0.0))
    time, x, y, heading, linear, angular = samples[-1]
    assert (x, y, heading) == (0.0, 0.0, 0.0) and linear == pytest.approx(0.2)


def test_deactivation_stops_the_wheel_and_steers_straight():
    controller, joints = tricycle()
    run(controller, joints, 0.1, command=twist(0.2, 0.2))
    controller.deactivate()
    assert joints[WHEEL].velocity_target == 0.0
    assert controller.steering_command == 0.0


def test_its_surface_follows_its_switches():
    controller, _ = tricycle()
    surface = {endpoint.name: endpoint for endpoint in controller.ros_surface()}
    assert isinstance(surface['~/cmd_vel'], CommandTopic)
    assert surface['~/cmd_vel'].message == 'geometry_msgs/msg/TwistStamped'
    assert surface['~/odom'].message == 'nav_msgs/msg/Odometry'
    assert isinstance(surface['~/reset_odometry'], Service)
    assert '/tf' not in surface and '~/cmd_ackermann' not in surface  # both off by default
    controller, _ = tricycle(enable_odom_tf=True, publish_ackermann_command=True)
    surface = {endpoint.name: endpoint for endpoint in controller.ros_surface()}
    assert isinstance(surface['/tf'], StateTopic)
    assert surface['~/cmd_ackermann'].message == 'ackermann_msgs/msg/AckermannDrive'
