"""steering_controllers_library: what the Ackermann, bicycle and tricycle types share.

References and their timeout, refused twists, chaining, the update rate,
the joints' claims and errors, the steering joints' tracking, the ROS
surface -- shown on the bicycle and Ackermann types of
test/support/steering_fixtures.py, with ideal joints (steering_harness.py) where the
kinematics is not the point.
"""

from __future__ import annotations

import math

import pytest
from steering_fixtures import ACKERMANN, BICYCLE, steering_parameters
from steering_harness import DT, NAME, configured, handles, run, twist

from pan_tilt_sim.controllers import JointHandle
from pan_tilt_sim.controllers.framework.base import ActuatorKind, CommandResult
from pan_tilt_sim.controllers.framework.registry import create_controller, drives_base
from pan_tilt_sim.controllers.framework.surface import CommandTopic, StateTopic
from pan_tilt_sim.errors import ControllerConfigError

WHEEL = 'rear_wheel_joint'
STEERING = 'front_steering_joint'


def bicycle(**overrides):
    """Return a configured bicycle steering controller and its joints."""
    return configured(BICYCLE, steering_parameters(BICYCLE, **overrides))


def test_it_claims_velocity_on_traction_and_position_on_steering_and_frees_the_base():
    controller, _ = configured(ACKERMANN, steering_parameters(ACKERMANN))
    assert controller.command_interfaces() == {
        'rear_right_wheel_joint': ('velocity',), 'rear_left_wheel_joint': ('velocity',),
        'front_right_steering_joint': ('position',), 'front_left_steering_joint': ('position',)}
    assert controller.state_interfaces()['rear_right_wheel_joint'] == ('velocity',)
    assert controller.state_interfaces()['front_left_steering_joint'] == ('position',)
    kinds = {joint: actuator.kind for joint, actuator in controller.actuators().items()}
    assert kinds['rear_left_wheel_joint'] is ActuatorKind.IDEAL_VELOCITY
    assert kinds['front_right_steering_joint'] is ActuatorKind.IDEAL_POSITION
    assert drives_base(ACKERMANN) and drives_base(BICYCLE)
    assert list(controller.reference_interfaces()) == [
        f'{NAME}/linear/velocity', f'{NAME}/angular/velocity']


def test_its_surface_is_reference_in_odometry_tf_and_state_out():
    controller, _ = bicycle(odom_frame_id='map', base_frame_id='chassis')
    surface = {endpoint.name: endpoint for endpoint in controller.ros_surface()}
    assert isinstance(surface['~/reference'], CommandTopic)
    assert surface['~/reference'].message == 'geometry_msgs/msg/TwistStamped'
    assert {name: endpoint.message for name, endpoint in surface.items()
            if isinstance(endpoint, StateTopic)} == {
        '~/odometry': 'nav_msgs/msg/Odometry', '~/tf_odometry': 'tf2_msgs/msg/TFMessage',
        '~/controller_state': 'control_msgs/msg/SteeringControllerStatus'}
    fields = surface['~/odometry'].fields
    assert (fields['frame_id'], fields['child_frame_id']) == ('map', 'chassis')
    assert fields['pose_covariance_diagonal'] == (0.0, 7.0, 14.0, 21.0, 28.0, 35.0)


def test_it_publishes_odometry_tf_and_state_at_every_update():
    controller, joints = bicycle(update_rate=50)
    odometry, tf, status = [], [], []
    controller.set_odometry_sink(lambda *sample: odometry.append(sample))
    controller.set_tf_sink(lambda *sample: tf.append(sample))
    controller.set_status_sink(lambda *sample: status.append(sample))
    run(controller, joints, 0.1, command=twist(0.2, 0.2))
    assert [sample[0] for sample in odometry] == pytest.approx([0.02 * k for k in range(5)])
    assert len(tf) == 5 and tf[-1][1][0][:2] == ('odom', 'base_link')
    time, positions, velocities, commands, steer, steer_commands = status[-1]
    assert (positions, velocities, commands) == ([], [pytest.approx(4.0)], [pytest.approx(4.0)])
    assert steer == steer_commands == [pytest.approx(math.atan(0.3))]


def test_without_enable_odom_tf_no_transform_is_published():
    controller, joints = bicycle(enable_odom_tf=False)
    tf = []
    controller.set_tf_sink(lambda *sample: tf.append(sample))
    run(controller, joints, 0.05)
    assert tf == []


def test_the_kinematics_run_at_the_update_rate():
    controller, joints = bicycle(update_rate=10)
    run(controller, joints, 0.001)  # the update at t = 0 is done
    controller.set_command(twist(0.2, 0.0, stamp=0.001))
    run(controller, joints, 0.098, start=0.001)
    assert joints[WHEEL].velocity_target == 0.0
    run(controller, joints, 0.002, start=0.099)  # the update at t = 0.1 takes it
    assert joints[WHEEL].velocity_target == pytest.approx(4.0)


def test_the_traction_wheels_stop_once_the_reference_is_older_than_its_timeout():
    controller, joints = bicycle(reference_timeout=0.2)
    controller.set_command(twist(0.2, 0.2))
    run(controller, joints, 0.15)
    assert joints[WHEEL].velocity_target == pytest.approx(4.0)
    run(controller, joints, 0.1, start=0.15)
    assert joints[WHEEL].velocity_target == 0.0
    assert controller.steering_commands == pytest.approx([math.atan(0.3)])  # stays steered
    assert controller.notices == ['reference timed out (0.2 s without one at sim time '
                                  '0.210 s): the traction wheels stop']


def test_with_a_zero_timeout_a_reference_counts_for_one_update():
    controller, joints = bicycle(reference_timeout=0.0)
    controller.set_command(twist(0.2, 0.0, stamp=100.0))  # any age
    run(controller, joints, 0.005)
    assert joints[WHEEL].velocity_target == pytest.approx(4.0)
    run(controller, joints, 0.01, start=0.005)
    assert joints[WHEEL].velocity_target == 0.0


@pytest.mark.parametrize('linear, angular', [(math.nan, 0.0), (0.2, math.inf),
                                             (-math.inf, 0.0)])
def test_a_twist_that_is_not_finite_is_refused_and_the_last_one_stays(linear, angular):
    controller, joints = bicycle()
    controller.set_command(twist(0.2, 0.0))
    run(controller, joints, 0.02)
    assert controller.set_command(twist(linear, angular)) is CommandResult.REJECTED
    assert 'not finite numbers' in controller.command_problem(None, CommandResult.REJECTED)
    run(controller, joints, 0.02, start=0.02)
    assert joints[WHEEL].velocity_target == pytest.approx(4.0)


def test_a_twist_stamped_longer_ago_than_the_timeout_is_refused():
    controller, joints = bicycle(reference_timeout=0.5)
    run(controller, joints, 1.0)
    assert controller.set_command(twist(0.2, 0.0, stamp=0.4)) is CommandResult.REJECTED
    assert 'more than reference_timeout (0.5 s)' in controller.command_problem(
        None, CommandResult.REJECTED)
    assert controller.set_command(twist(0.2, 0.0, stamp=0.7)) is CommandResult.ACCEPTED


def test_in_chained_mode_the_references_drive_it_and_are_reset_after_each_update():
    controller, joints = bicycle()
    controller.set_chained_mode(True)
    controller.set_command(twist(0.5, 0.0))  # not used in chained mode
    linear, angular = controller.reference_interfaces().values()
    linear.value, angular.value = 0.2, 0.0
    controller.update(0.0, DT)
    assert joints[WHEEL].velocity_target == pytest.approx(4.0)
    assert math.isnan(linear.value) and math.isnan(angular.value)
    controller.update(0.01, DT)  # nothing written since: the wheel stops
    assert joints[WHEEL].velocity_target == 0.0


def test_the_steering_setpoint_ramps_to_the_command_within_the_joint_limits():
    controller, joints = bicycle()
    controller.set_command(twist(0.1, 1.0))  # atan(3): beyond the 0.6 rad limit
    controller.update(0.0, DT)
    assert controller.steering_commands == [0.6]
    steering = joints[STEERING]
    setpoints = []
    for step in range(1, 600):
        controller.update(step * DT, DT)
        steering.position += steering.velocity_target * DT
        setpoints.append(controller.setpoints()[STEERING])
    assert max(b - a for a, b in zip(setpoints, setpoints[1:], strict=False)) <= 3.0 * DT + 1e-9
    assert setpoints[-1] == 0.6 and steering.position == pytest.approx(0.6, abs=1e-3)


def test_deactivation_stops_the_wheels_and_holds_the_steering():
    controller, joints = bicycle()
    run(controller, joints, 0.05, command=twist(0.2, 0.2))
    controller.deactivate()
    assert joints[WHEEL].velocity_target == 0.0
    assert controller.setpoints()[STEERING] == pytest.approx(math.atan(0.3))


def test_the_deprecated_wheel_lists_map_as_front_steering_says():
    params = steering_parameters(BICYCLE, traction_joints_names=[], steering_joints_names=[],
                                 front_wheels_names=[WHEEL], rear_wheels_names=[STEERING],
                                 front_steering=False)  # front driven, rear steered
    controller = create_controller(NAME, BICYCLE, params, 'car.yaml')
    assert controller.command_interfaces() == {WHEEL: ('velocity',), STEERING: ('position',)}
    assert [line.split(': ')[1] for line in controller.config_warnings] == [
        f'{NAME}.front_steering', f'{NAME}.front_wheels_names', f'{NAME}.rear_wheels_names']


def test_state_joints_may_stand_for_the_commanded_ones():
    params = steering_parameters(BICYCLE, traction_joints_state_names=['wheel_encoder'],
                                 open_loop=False)
    joints = handles(params) | {'wheel_encoder': JointHandle(handles(
        {'traction_joints_names': ['wheel_encoder']})['wheel_encoder'].spec)}
    controller = create_controller(NAME, BICYCLE, params, 'car.yaml')
    controller.configure(joints)
    assert controller.state_interfaces()['wheel_encoder'] == ('velocity',)
    joints['wheel_encoder'].velocity = 4.0  # the encoder, not the driven wheel, moves
    for step in range(100):
        controller.update(step * DT, DT)
    assert controller.odometry.x == pytest.approx(0.02, abs=1e-3)  # 0.2 m/s for 0.1 s


@pytest.mark.parametrize('overrides, field, problem', [
    ({'traction_joints_names': []}, 'traction_joints_names',
     'Bicycle configuration requires exactly one traction joint, but 0 were provided'),
    ({'steering_joints_names': [WHEEL]}, 'steering_joints_names',
     f"'{WHEEL}' is also one of traction_joints_names"),
    ({'steering_joints_state_names': ['a', 'b']}, 'steering_joints_state_names',
     'Bicycle configuration requires exactly one steering joint, but 2 were provided'),
    ({'traction_joints_names': ['a', 'b', 'c', 'd', 'e']}, 'traction_joints_names',
     'must have at most 4 elements'),
    ({'wheelbase': 0.0}, 'wheelbase', 'must be > 0'),
])
def test_a_bad_parameter_is_refused_naming_it(overrides, field, problem):
    with pytest.raises(ControllerConfigError, match=rf'^car\.yaml: {NAME}\.{field}: .*'
                       f'{problem}'):
        create_controller(NAME, BICYCLE, steering_parameters(BICYCLE, **overrides), 'car.yaml')


def test_a_steering_joint_the_robot_lacks_names_the_parameter():
    params = steering_parameters(BICYCLE)
    joints = handles(params)
    del joints[STEERING]
    controller = create_controller(NAME, BICYCLE, params, 'car.yaml')
    with pytest.raises(ControllerConfigError, match=rf"^car\.yaml: {NAME}\.steering_joints_names: "
                       f"joint '{STEERING}' is not a movable joint of the robot"):
        controller.configure(joints)
