"""omni_wheel_drive_controller/OmniWheelDriveController on its own: kinematics, timeout, odometry.

The controller runs against joint handles the tests turn themselves (ideal
wheels: each turns exactly as commanded), at its update rate of 100 Hz.
Geometry of test/support/roller_fixtures.py: three wheels at 0, 120 and 240
degrees, robot radius 0.15 m, wheel radius 0.05 m.
"""

from __future__ import annotations

import math

import pytest
from holonomic_drive import DT, NAME, configured, run, twist
from roller_fixtures import OMNI_RADIUS, WHEEL_RADIUS, omni_joints, omni_parameters

from pan_tilt_sim.controllers import JointHandle
from pan_tilt_sim.controllers.drives.omni_wheel_drive_controller import OmniWheelDriveController
from pan_tilt_sim.controllers.framework import registry
from pan_tilt_sim.controllers.framework.base import ActuatorKind, CommandResult
from pan_tilt_sim.controllers.framework.surface import CommandTopic, StateTopic
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.robot import JointKind, JointSpec

ROOT3 = math.sqrt(3.0)


def controller(**overrides) -> tuple[OmniWheelDriveController, dict[str, JointHandle]]:
    """Return a configured controller of the three wheels, and the wheels' handles."""
    parameters = omni_parameters(update_rate=100.0, **overrides)
    return configured(OmniWheelDriveController, parameters, omni_joints(), 'omni.yaml')


def targets(handles: dict[str, JointHandle]) -> list[float]:
    """Return the wheels' commanded velocities in wheel_names order."""
    return [handles[name].velocity_target for name in omni_joints()]


def test_a_twist_becomes_wheel_velocities_by_the_inverse_kinematics():
    drive, handles = controller()
    drive.set_command(twist(0.2, 0.1, 0.5))
    drive.update(0.0, DT)
    # (sin(theta) vx - cos(theta) vy - R wz) / r at theta = 0, 120, 240 degrees.
    assert targets(handles) == pytest.approx([
        (-0.1 - 0.075) / 0.05, (ROOT3 / 2 * 0.2 + 0.05 - 0.075) / 0.05,
        (-ROOT3 / 2 * 0.2 + 0.05 - 0.075) / 0.05])


def test_the_wheel_offset_turns_every_wheel_angle():
    drive, handles = controller(wheel_offset=math.pi / 2)
    drive.set_command(twist(0.2, 0.0, 0.0))
    drive.update(0.0, DT)
    assert targets(handles) == pytest.approx([4.0, -2.0, -2.0])


def test_the_forward_kinematics_give_back_the_twist_of_the_wheel_velocities():
    drive, _ = controller()
    velocities = [-3.5, (ROOT3 / 2 * 0.2 - 0.025) / 0.05, (-ROOT3 / 2 * 0.2 - 0.025) / 0.05]
    assert drive.odometry.body_twist(velocities) == pytest.approx((0.2, 0.1, 0.5))


def test_odometry_from_the_wheel_positions_integrates_a_strafe_and_then_an_arc():
    drive, handles = controller(cmd_vel_timeout=1.0)
    end = run(drive, handles, 1.0, command=twist(0.0, 0.2, 0.0))
    odometry = drive.odometry
    # The wheels' turn is read one update after it was commanded.
    assert (odometry.x, odometry.y) == pytest.approx((0.0, 0.2 - 0.2 * DT), abs=1e-9)
    run(drive, handles, 1.0, start=end, command=twist(0.1, 0.0, math.pi / 2))
    # A quarter circle of radius 0.1 / (pi / 2) m turning left from heading 0, strafed before.
    radius = 0.1 / (math.pi / 2)
    assert odometry.heading == pytest.approx(math.pi / 2 * (1 - DT), abs=1e-9)
    assert odometry.x == pytest.approx(radius * math.sin(odometry.heading), abs=1e-9)


def test_open_loop_and_velocity_feedback_odometry():
    drive, handles = controller(open_loop=True, cmd_vel_timeout=1.0)
    assert drive.state_interfaces() == {}
    run(drive, handles, 1.0, command=twist(0.2, 0.0, 0.0))
    assert drive.odometry.x == pytest.approx(0.2 * (1 - DT))
    drive, handles = controller(position_feedback=False, cmd_vel_timeout=1.0)
    assert set(drive.state_interfaces().values()) == {('velocity',)}
    run(drive, handles, 1.0, command=twist(0.2, 0.0, 0.0))
    assert drive.odometry.x == pytest.approx(0.2 * (1 - DT))


def test_the_wheels_are_driven_by_the_ideal_velocity_actuator_and_carry_omni_rollers():
    drive, _ = controller()
    assert drive.command_interfaces() == {joint: ('velocity',) for joint in omni_joints()}
    assert drive.state_interfaces() == {joint: ('position',) for joint in omni_joints()}
    assert {actuator.kind for actuator in drive.actuators().values()} == {
        ActuatorKind.IDEAL_VELOCITY}
    assert drive.roller_wheels() == {joint: math.pi / 2 for joint in omni_joints()}
    assert registry.drives_base('omni_wheel_drive_controller/OmniWheelDriveController')


def test_nothing_is_commanded_nor_published_before_the_first_command():
    drive, handles = controller()
    samples = []
    drive.set_odometry_sink(lambda *sample: samples.append(sample))
    run(drive, handles, 0.3)
    assert samples == [] and targets(handles) == [0.0] * 3


def test_a_stale_command_brakes_once_cmd_vel_timeout_passed():
    drive, handles = controller(cmd_vel_timeout=0.1)
    drive.set_command(twist(0.2, 0.0, 0.0))
    run(drive, handles, 0.1)
    assert targets(handles)[1] == pytest.approx(ROOT3 / 2 * 0.2 / WHEEL_RADIUS)
    run(drive, handles, 0.05, start=0.11)
    assert targets(handles) == [0.0] * 3
    assert any('timed out' in notice for notice in drive.notices)


@pytest.mark.parametrize('value', [math.nan, math.inf, -math.inf])
def test_a_twist_that_is_not_finite_is_refused_and_changes_nothing(value):
    drive, handles = controller(cmd_vel_timeout=1.0)
    run(drive, handles, 0.05, command=twist(0.2, 0.0, 0.0))
    for bad in (twist(value, 0.0, 0.0), twist(0.0, value, 0.0), twist(0.0, 0.0, value)):
        assert drive.set_command(bad) is CommandResult.REJECTED
        assert 'not finite numbers' in drive.command_problem(bad, CommandResult.REJECTED)
    run(drive, handles, 0.05, start=0.05)
    assert targets(handles)[0] == pytest.approx(0.0)
    assert targets(handles)[1] == pytest.approx(ROOT3 / 2 * 0.2 / WHEEL_RADIUS)


def test_a_twist_stamped_longer_ago_than_the_timeout_is_refused():
    drive, handles = controller(cmd_vel_timeout=0.1)
    run(drive, handles, 0.5)
    assert drive.set_command(twist(0.2, 0.0, 0.0, stamp=0.3)) is CommandResult.REJECTED
    assert 'more than cmd_vel_timeout' in drive.command_problem(None, CommandResult.REJECTED)


def test_a_twist_exactly_cmd_vel_timeout_old_is_stale_too():
    drive, _ = controller(cmd_vel_timeout=0.25)
    drive.update(0.5, DT)
    assert drive.set_command(twist(0.2, 0.0, 0.0, stamp=0.25)) is CommandResult.REJECTED
    assert drive.set_command(twist(0.2, 0.0, 0.0, stamp=0.375)) is CommandResult.ACCEPTED


def test_it_exports_three_velocity_references_and_follows_them_when_chained():
    drive, handles = controller(cmd_vel_timeout=0.1)
    references = drive.reference_interfaces()
    assert list(references) == [f'{NAME}/linear/x/velocity', f'{NAME}/linear/y/velocity',
                                f'{NAME}/angular/z/velocity']
    drive.set_chained_mode(True)
    for reference, value in zip(references.values(), (0.0, 0.0, 1.0), strict=True):
        reference.value = value
    run(drive, handles, 0.5)  # no cmd_vel, and no timeout: the references rule
    assert targets(handles) == pytest.approx([-OMNI_RADIUS / WHEEL_RADIUS] * 3)


def test_the_surface_is_cmd_vel_in_and_odom_and_tf_out():
    drive, _ = controller(**{'diagonal_covariance': {'pose': [0.01] * 6}})
    surface = {endpoint.name: endpoint for endpoint in drive.ros_surface()}
    assert isinstance(surface['~/cmd_vel'], CommandTopic)
    assert surface['~/cmd_vel'].message == 'geometry_msgs/msg/TwistStamped'
    assert isinstance(surface['~/odom'], StateTopic)
    assert surface['~/odom'].fields['pose_covariance_diagonal'] == (0.01,) * 6
    assert surface['~/odom'].fields['twist_covariance_diagonal'] == (0.0,) * 6
    assert surface['/tf'].message == 'tf2_msgs/msg/TFMessage'
    drive, _ = controller(enable_odom_tf=False)
    assert '/tf' not in {endpoint.name for endpoint in drive.ros_surface()}


@pytest.mark.parametrize('overrides, field, problem', [
    ({'wheel_names': ['a', 'b']}, 'wheel_names', 'less than 3'),
    ({'wheel_names': ['a', 'b', 'a']}, 'wheel_names', "'a' is named more than once"),
    ({'robot_radius': 0.0}, 'robot_radius', 'must be > 0'),
    ({'wheel_radius': -0.05}, 'wheel_radius', 'must be > 0'),
    ({'diagonal_covariance': {'twist': [0.1]}}, 'diagonal_covariance.twist',
     'must have 6 elements'),
])
def test_a_wrong_parameter_is_an_error_naming_the_file_controller_and_field(
        overrides, field, problem):
    with pytest.raises(ControllerConfigError, match=rf'^omni\.yaml: {NAME}\.{field}: .*'
                       rf'{problem}'):
        OmniWheelDriveController(NAME, omni_parameters(**overrides), 'omni.yaml')


def test_a_missing_wheel_offset_is_an_error_naming_it():
    params = omni_parameters()
    del params['wheel_offset']
    with pytest.raises(ControllerConfigError, match=rf'{NAME}\.wheel_offset: missing'):
        OmniWheelDriveController(NAME, params, 'omni.yaml')


def test_a_wheel_the_robot_lacks_is_an_error_naming_the_parameter():
    drive = OmniWheelDriveController(NAME, omni_parameters(
        wheel_names=['wheel_0_joint', 'wheel_1_joint', 'whel_2_joint']), 'omni.yaml')
    handles = {name: JointHandle(JointSpec(name, JointKind.CONTINUOUS))
               for name in omni_joints()}
    with pytest.raises(ControllerConfigError, match=rf"{NAME}\.wheel_names: joint "
                                                    "'whel_2_joint' is not a movable joint"):
        drive.configure(handles)
