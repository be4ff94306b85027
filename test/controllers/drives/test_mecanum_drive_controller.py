"""mecanum_drive_controller/MecanumDriveController on its own: kinematics, timeout, odometry.

The controller runs against joint handles the tests turn themselves (ideal
wheels: each turns exactly as commanded), at its update rate of 100 Hz, so
every figure follows from the kinematics alone.  Geometry of
test/support/roller_fixtures.py: wheel radius 0.05 m, lx + ly = 0.32 m.
"""

from __future__ import annotations

import math

import pytest
from holonomic_drive import DT, NAME, configured, run, twist
from roller_fixtures import MECANUM_LX, MECANUM_LY, WHEEL_RADIUS, mecanum_joints, mecanum_parameters

from pan_tilt_sim.controllers import JointHandle
from pan_tilt_sim.controllers.drives.mecanum_drive_controller import MecanumDriveController
from pan_tilt_sim.controllers.framework import registry
from pan_tilt_sim.controllers.framework.base import ActuatorKind, CommandResult, Reference
from pan_tilt_sim.controllers.framework.surface import CommandTopic, StateTopic
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.robot import JointKind, JointSpec

FL, FR, RR, RL = mecanum_joints()


def controller(**overrides) -> tuple[MecanumDriveController, dict[str, JointHandle]]:
    """Return a configured controller of the four wheels, and the wheels' handles."""
    parameters = mecanum_parameters(update_rate=100.0, **overrides)
    return configured(MecanumDriveController, parameters, mecanum_joints(), 'mecanum.yaml')


def targets(handles: dict[str, JointHandle]) -> list[float]:
    """Return the wheels' commanded velocities: front left, front right, rear right, rear left."""
    return [handles[name].velocity_target for name in (FL, FR, RR, RL)]


def test_a_body_twist_becomes_wheel_velocities_by_the_inverse_kinematics():
    drive, handles = controller()
    drive.set_command(twist(0.2, 0.1, 0.5))
    drive.update(0.0, DT)
    # (vx -+ vy -+ (lx + ly) wz) / r with lx + ly = 0.32 m, r = 0.05 m.
    assert targets(handles) == pytest.approx([-1.2, 9.2, 5.2, 2.8])


def test_the_base_frame_offset_moves_the_twist_to_the_wheels_centre():
    drive, handles = controller(kinematics={
        'wheels_radius': WHEEL_RADIUS, 'base_frame_offset': {'x': 0.1},
        'sum_of_robot_center_projection_on_X_Y_axis': MECANUM_LX + MECANUM_LY})
    drive.set_command(twist(0.0, 0.0, 1.0))
    drive.update(0.0, DT)
    # Turning about a point 0.1 m ahead of the centre moves the centre at -0.1 m/s along y.
    assert targets(handles) == pytest.approx([-4.4, 4.4, 8.4, -8.4])


def test_the_forward_kinematics_give_back_the_twist_of_the_wheel_velocities():
    drive, _ = controller()
    assert drive.odometry.body_twist(-1.2, 9.2, 5.2, 2.8) == pytest.approx((0.2, 0.1, 0.5))
    assert drive.odometry.body_twist(4.0, 4.0, 4.0, 4.0) == pytest.approx((0.2, 0.0, 0.0))
    assert drive.odometry.body_twist(-4.0, 4.0, -4.0, 4.0) == pytest.approx((0.0, 0.2, 0.0))


def test_odometry_integrates_a_diagonal_and_then_a_turn():
    drive, handles = controller(reference_timeout=1.0)
    end = run(drive, handles, 1.0, command=twist(0.2, 0.1, 0.0))
    odometry = drive.odometry
    # The wheels' velocities are read one update after they were commanded.
    assert (odometry.x, odometry.y) == pytest.approx((0.2 - 0.002, 0.1 - 0.001), abs=1e-9)
    assert (odometry.linear_x, odometry.linear_y) == pytest.approx((0.2, 0.1))
    run(drive, handles, 1.0, start=end, command=twist(0.0, 0.0, math.pi / 2))
    assert odometry.heading == pytest.approx(math.pi / 2 - math.pi / 2 * DT, abs=1e-9)


def test_the_wheels_are_driven_by_the_ideal_velocity_actuator_and_carry_45_degree_rollers():
    drive, _ = controller()
    assert drive.command_interfaces() == {joint: ('velocity',) for joint in mecanum_joints()}
    assert drive.state_interfaces() == {joint: ('velocity',) for joint in mecanum_joints()}
    assert {actuator.kind for actuator in drive.actuators().values()} == {
        ActuatorKind.IDEAL_VELOCITY}
    quarter = math.pi / 4
    assert drive.roller_wheels() == {FL: quarter, FR: -quarter, RR: quarter, RL: -quarter}
    assert registry.drives_base('mecanum_drive_controller/MecanumDriveController')


def test_separate_state_joints_are_read_instead_of_the_command_joints():
    drive = MecanumDriveController(NAME, mecanum_parameters(
        front_left_wheel_state_joint_name='other_joint'), 'mecanum.yaml')
    assert drive.state_interfaces()['other_joint'] == ('velocity',)
    assert FL not in drive.state_interfaces()


def test_a_following_controllers_references_take_the_commands_and_the_state_joints_the_wheels():
    follower = {f'pid/{joint}/velocity': Reference(f'pid/{joint}/velocity')
                for joint in mecanum_joints()}
    params = mecanum_parameters()
    for wheel, joint in zip(('front_left', 'front_right', 'rear_right', 'rear_left'),
                            mecanum_joints(), strict=True):
        params[f'{wheel}_wheel_command_joint_name'] = f'pid/{joint}'
        params[f'{wheel}_wheel_state_joint_name'] = joint
    drive = MecanumDriveController(NAME, params, 'mecanum.yaml')
    drive.set_available_references(follower)
    handles = {name: JointHandle(JointSpec(name, JointKind.CONTINUOUS))
               for name in mecanum_joints()}
    drive.configure(handles)
    assert drive.command_interfaces() == {f'pid/{joint}': ('velocity',)
                                          for joint in mecanum_joints()}
    assert drive.actuators() == {}
    assert set(drive.roller_wheels()) == set(mecanum_joints())
    drive.set_command(twist(0.2, 0.1, 0.5))
    drive.update(0.0, DT)
    assert [reference.value for reference in follower.values()] == pytest.approx(
        [-1.2, 9.2, 5.2, 2.8])
    drive.deactivate()
    assert all(math.isnan(reference.value) for reference in follower.values())


def test_a_reference_is_used_until_reference_timeout_then_the_wheels_stop():
    drive, handles = controller(reference_timeout=0.1)
    drive.set_command(twist(0.2, 0.0, 0.0, stamp=0.0))
    run(drive, handles, 0.1)
    assert targets(handles) == pytest.approx([4.0] * 4)
    run(drive, handles, 0.05, start=0.11)
    assert targets(handles) == [0.0] * 4
    assert any('reference timed out' in notice for notice in drive.notices)


def test_a_zero_reference_timeout_uses_each_reference_for_one_update_only():
    drive, handles = controller(reference_timeout=0.0)
    drive.set_command(twist(0.2, 0.0, 0.0))
    drive.update(0.0, DT)
    assert targets(handles) == pytest.approx([4.0] * 4)
    drive.update(DT, DT)
    assert targets(handles) == [0.0] * 4


@pytest.mark.parametrize('value', [math.nan, math.inf, -math.inf])
def test_a_reference_that_is_not_finite_is_refused_and_changes_nothing(value):
    drive, handles = controller(reference_timeout=1.0)
    run(drive, handles, 0.05, command=twist(0.2, 0.0, 0.0))
    for bad in (twist(value, 0.0, 0.0), twist(0.0, value, 0.0), twist(0.0, 0.0, value)):
        assert drive.set_command(bad) is CommandResult.REJECTED
        assert 'not finite numbers' in drive.command_problem(bad, CommandResult.REJECTED)
    run(drive, handles, 0.05, start=0.05)
    assert targets(handles) == pytest.approx([4.0] * 4)


def test_a_reference_stamped_longer_ago_than_the_timeout_is_refused():
    drive, handles = controller(reference_timeout=0.1)
    run(drive, handles, 0.5)
    assert drive.set_command(twist(0.2, 0.0, 0.0, stamp=0.3)) is CommandResult.REJECTED
    assert 'more than reference_timeout' in drive.command_problem(None, CommandResult.REJECTED)


def test_a_reference_exactly_reference_timeout_old_is_still_taken():
    drive, _ = controller(reference_timeout=0.25)
    drive.update(0.5, 0.01)
    assert drive.set_command(twist(0.2, 0.0, 0.0, stamp=0.25)) is CommandResult.ACCEPTED
    assert drive.set_command(twist(0.2, 0.0, 0.0, stamp=0.125)) is CommandResult.REJECTED


def test_the_velocity_limits_clamp_each_axis_before_the_kinematics():
    drive, handles = controller(linear={'y': {'max_velocity': 0.1}})
    drive.set_command(twist(0.0, 0.3, 0.0))
    drive.update(0.0, DT)
    assert targets(handles) == pytest.approx([-2.0, 2.0, -2.0, 2.0])


def test_it_exports_three_velocity_references_reset_to_nan_after_each_update():
    drive, handles = controller()
    references = drive.reference_interfaces()
    assert list(references) == [f'{NAME}/linear/x/velocity', f'{NAME}/linear/y/velocity',
                                f'{NAME}/angular/z/velocity']
    drive.set_chained_mode(True)
    for reference, value in zip(references.values(), (0.0, 0.2, 0.0), strict=True):
        reference.value = value
    drive.update(0.0, DT)
    assert targets(handles) == pytest.approx([-4.0, 4.0, -4.0, 4.0])
    assert all(math.isnan(reference.value) for reference in references.values())
    drive.update(DT, DT)  # nobody wrote them again: the wheels stop
    assert targets(handles) == [0.0] * 4


def test_the_surface_is_reference_in_and_odometry_tf_odometry_and_state_out():
    drive, _ = controller()
    surface = {endpoint.name: endpoint for endpoint in drive.ros_surface()}
    assert isinstance(surface['~/reference'], CommandTopic)
    assert surface['~/reference'].message == 'geometry_msgs/msg/TwistStamped'
    assert isinstance(surface['~/odometry'], StateTopic)
    assert surface['~/odometry'].fields['frame_id'] == 'odom'
    assert surface['~/odometry'].fields['pose_covariance_diagonal'] == (0.1,) * 6
    assert surface['~/tf_odometry'].message == 'tf2_msgs/msg/TFMessage'
    assert surface['~/controller_state'].message == (
        'control_msgs/msg/MecanumDriveControllerState')
    drive, _ = controller(enable_odom_tf=False, tf_frame_prefix='robot')
    surface = {endpoint.name: endpoint for endpoint in drive.ros_surface()}
    assert '~/tf_odometry' not in surface
    assert surface['~/odometry'].fields['child_frame_id'] == 'robot/base_link'


def test_samples_leave_once_per_update_with_the_measured_wheels_and_the_reference():
    drive, handles = controller(reference_timeout=1.0)
    samples, states = [], []
    drive.set_odometry_sink(lambda time, pose, linear, angular: samples.append(time))
    drive.set_state_sink(lambda time, wheels, reference: states.append((wheels, reference)))
    run(drive, handles, 0.1, command=twist(0.2, 0.0, 0.0))
    for step in range(5):  # between updates, nothing
        drive.update(0.1 + step * 0.001, 0.001)
    assert samples == pytest.approx([step * DT for step in range(11)])
    assert states[-1] == (pytest.approx([4.0] * 4), pytest.approx([0.2, 0.0, 0.0]))


@pytest.mark.parametrize('overrides, field, problem', [
    ({'kinematics': {'wheels_radius': 0.0,
                     'sum_of_robot_center_projection_on_X_Y_axis': 0.3}},
     'kinematics.wheels_radius', 'must be > 0'),
    ({'kinematics': {'wheels_radius': 0.05}},
     'kinematics.sum_of_robot_center_projection_on_X_Y_axis', '0.0 must be > 0'),
    ({'front_left_wheel_command_joint_name': ''}, 'front_left_wheel_command_joint_name',
     'must not be empty'),
    ({'rear_left_wheel_command_joint_name': FL}, 'rear_left_wheel_command_joint_name',
     'already the command joint'),
    ({'pose_covariance_diagonal': [0.1]}, 'pose_covariance_diagonal', 'must have 6 elements'),
    ({'linear': {'y': {'max_velocity': -1.0}}}, 'linear.y.max_velocity', '>= 0 or NaN'),
    ({'angular': {'z': {'min_velocity': 1.0}}}, 'angular.z.min_velocity', '<= 0 or NaN'),
])
def test_a_wrong_parameter_is_an_error_naming_the_file_controller_and_field(
        overrides, field, problem):
    with pytest.raises(ControllerConfigError, match=rf'^mecanum\.yaml: {NAME}\.{field}: .*'
                       rf'{problem}'):
        MecanumDriveController(NAME, mecanum_parameters(**overrides), 'mecanum.yaml')


def test_a_wheel_the_robot_lacks_is_an_error_naming_the_parameter():
    drive = MecanumDriveController(NAME, mecanum_parameters(
        rear_right_wheel_command_joint_name='rear_rigth_wheel_joint'), 'mecanum.yaml')
    handles = {name: JointHandle(JointSpec(name, JointKind.CONTINUOUS))
               for name in mecanum_joints()}
    with pytest.raises(ControllerConfigError, match=rf"{NAME}\.rear_right_wheel_command_joint_"
                       r"name: joint 'rear_rigth_wheel_joint' is not a movable joint"):
        drive.configure(handles)
