"""diff_drive_controller/DiffDriveController on its own: kinematics, limits, timeout, odometry.

The controller runs against joint handles whose positions the tests move
themselves (ideal wheels: each turns exactly as commanded), so every figure
follows from the kinematics alone.
"""

from __future__ import annotations

import math

import pytest
import yaml
from mobile_fixtures import WHEEL_RADIUS, WHEEL_SEPARATION, drive_parameters, write_rover

from pan_tilt_sim.controllers import JointHandle
from pan_tilt_sim.controllers.drives.diff_drive_controller import DiffDriveController
from pan_tilt_sim.controllers.framework import registry
from pan_tilt_sim.controllers.framework.base import ActuatorKind, CommandResult, Reference
from pan_tilt_sim.controllers.framework.manager import ControllerManager
from pan_tilt_sim.controllers.framework.surface import CommandTopic, StampedTwist, StateTopic
from pan_tilt_sim.controllers.toolbox.rate_limiter import (
    InvalidLimitsError,
    RateLimiter,
    RateLimits,
)
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.controller_config import load_controllers_config
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.model.robot import JointKind, JointSpec

DT = 0.001
NAME = 'base_controller'
WHEELS = ('left_wheel_joint', 'right_wheel_joint', 'left_rear_joint', 'right_rear_joint')


def twist(linear: float, angular: float, stamp: float = 0.0) -> StampedTwist:
    """Return a TwistStamped value: linear.x and angular.z."""
    return StampedTwist(stamp, (linear, 0.0, 0.0), (0.0, 0.0, angular))


def wheel_handles() -> dict[str, JointHandle]:
    """Return handles for four continuous wheel joints."""
    return {name: JointHandle(JointSpec(name, JointKind.CONTINUOUS)) for name in WHEELS}


def controller(**overrides) -> tuple[DiffDriveController, dict[str, JointHandle]]:
    """Return a configured controller over the two front wheels, and the wheels' handles."""
    handles = wheel_handles()
    drive = DiffDriveController(NAME, drive_parameters(**overrides), 'rover.yaml')
    drive.configure(handles)
    return drive, handles


def run(drive: DiffDriveController, handles: dict[str, JointHandle], seconds: float,
        start: float = 0.0, command: StampedTwist | None = None) -> float:
    """Step ``drive`` for ``seconds``; ideal wheels turn as commanded; return the end time."""
    steps = round(seconds / DT)
    time = start
    for step in range(steps):
        time = start + step * DT
        if command is not None:
            assert drive.set_command(command) is CommandResult.ACCEPTED
        drive.update(time, DT)
        for handle in handles.values():
            handle.velocity = handle.velocity_target
            handle.position += handle.velocity_target * DT
    return start + steps * DT


def test_a_twist_becomes_wheel_velocities_by_the_kinematics():
    drive, handles = controller()
    drive.set_command(twist(0.2, 0.5))
    drive.update(0.0, DT)
    half = WHEEL_SEPARATION / 2
    assert handles['left_wheel_joint'].velocity_target == pytest.approx(
        (0.2 - 0.5 * half) / WHEEL_RADIUS)
    assert handles['right_wheel_joint'].velocity_target == pytest.approx(
        (0.2 + 0.5 * half) / WHEEL_RADIUS)


def test_the_multipliers_correct_separation_and_each_side_radius():
    drive, handles = controller(wheel_separation_multiplier=2.0, left_wheel_radius_multiplier=0.5,
                                right_wheel_radius_multiplier=2.0)
    drive.set_command(twist(0.0, 1.0))
    drive.update(0.0, DT)
    assert handles['left_wheel_joint'].velocity_target == pytest.approx(
        -WHEEL_SEPARATION / (0.5 * WHEEL_RADIUS))
    assert handles['right_wheel_joint'].velocity_target == pytest.approx(
        WHEEL_SEPARATION / (2.0 * WHEEL_RADIUS))


def test_every_wheel_of_a_side_gets_its_side_velocity():
    drive, handles = controller(left_wheel_names=['left_wheel_joint', 'left_rear_joint'],
                                right_wheel_names=['right_wheel_joint', 'right_rear_joint'])
    drive.set_command(twist(0.1, 0.0))
    drive.update(0.0, DT)
    assert [handles[name].velocity_target for name in WHEELS] == pytest.approx(
        [0.1 / WHEEL_RADIUS] * 4)
    assert drive.command_interfaces() == {name: ('velocity',) for name in WHEELS}


def test_the_wheels_are_driven_by_the_ideal_velocity_actuator():
    drive, _ = controller()
    assert {name: actuator.kind for name, actuator in drive.actuators().items()} == {
        'left_wheel_joint': ActuatorKind.IDEAL_VELOCITY,
        'right_wheel_joint': ActuatorKind.IDEAL_VELOCITY}
    assert DiffDriveController.drives_base
    assert registry.drives_base('diff_drive_controller/DiffDriveController')
    assert not registry.drives_base('velocity_controllers/JointGroupVelocityController')


def test_nothing_is_commanded_before_the_first_twist_but_the_odometry_is_published():
    drive, handles = controller()
    samples = []
    drive.set_odometry_sink(lambda *sample: samples.append(sample))
    run(drive, handles, 0.1)
    assert all(handle.velocity_target == 0.0 for handle in handles.values())
    assert len(samples) == 5 and samples[-1][1:] == (0.0, 0.0, 0.0, 0.0, 0.0)


@pytest.mark.parametrize('value', [math.nan, math.inf, -math.inf])
def test_a_twist_that_is_not_finite_is_refused_and_changes_nothing(value):
    drive, handles = controller()
    drive.set_command(twist(0.2, 0.0))
    drive.update(0.0, DT)
    before = handles['left_wheel_joint'].velocity_target
    assert drive.set_command(twist(value, 0.0)) is CommandResult.REJECTED
    assert drive.set_command(twist(0.0, value)) is CommandResult.REJECTED
    assert 'not finite' in drive.command_problem(twist(0.0, value), CommandResult.REJECTED)
    drive.update(DT, DT)
    assert handles['left_wheel_joint'].velocity_target == before


def test_a_stale_command_brakes_the_robot_once_cmd_vel_timeout_passed():
    drive, handles = controller(cmd_vel_timeout=0.2)
    drive.set_command(twist(0.2, 0.0))  # unstamped: stamped on arrival, at sim time 0
    end = run(drive, handles, 0.15)
    assert handles['left_wheel_joint'].velocity_target == pytest.approx(0.2 / WHEEL_RADIUS)
    run(drive, handles, 0.1, start=end)
    assert handles['left_wheel_joint'].velocity_target == 0.0
    assert len(drive.notices) == 1 and 'timed out' in drive.notices[0]


def test_a_zero_cmd_vel_timeout_never_brakes():
    drive, handles = controller(cmd_vel_timeout=0.0)
    drive.set_command(twist(0.2, 0.0))
    run(drive, handles, 2.0)
    assert handles['left_wheel_joint'].velocity_target == pytest.approx(0.2 / WHEEL_RADIUS)


def test_a_twist_stamped_longer_ago_than_the_timeout_is_refused():
    drive, handles = controller(cmd_vel_timeout=0.5)
    end = run(drive, handles, 1.0)
    assert drive.set_command(twist(0.2, 0.0, stamp=end - 0.6)) is CommandResult.REJECTED
    assert 'cmd_vel_timeout' in drive.command_problem(None, CommandResult.REJECTED)
    assert drive.set_command(twist(0.2, 0.0, stamp=end - 0.1)) is CommandResult.ACCEPTED


def test_the_velocity_limit_clamps_the_command():
    drive, handles = controller(**{'linear.x.max_velocity': 0.1, 'angular.z.max_velocity': 0.3})
    drive.set_command(twist(0.5, -1.0))
    drive.update(0.0, DT)
    assert drive.limited_command == pytest.approx((0.1, -0.3))


def test_the_acceleration_limit_ramps_the_command():
    drive, handles = controller(**{'linear.x.max_acceleration': 0.5})
    end = run(drive, handles, 0.2, command=twist(0.2, 0.0))
    assert drive.limited_command[0] == pytest.approx(0.5 * 0.2, rel=1e-6)
    run(drive, handles, 0.3, start=end, command=twist(0.2, 0.0))
    assert drive.limited_command[0] == pytest.approx(0.2)


def test_the_deceleration_limit_ramps_a_stop_and_reverse_acceleration_a_start_backwards():
    drive, handles = controller(**{'linear.x.max_acceleration': 10.0,
                                   'linear.x.max_deceleration': -0.5,
                                   'linear.x.max_acceleration_reverse': -0.25})
    end = run(drive, handles, 0.1, command=twist(0.2, 0.0))
    assert drive.limited_command[0] == pytest.approx(0.2)
    end = run(drive, handles, 0.1, start=end, command=twist(0.0, 0.0))
    assert drive.limited_command[0] == pytest.approx(0.2 - 0.5 * 0.1, rel=1e-6)
    end = run(drive, handles, 1.0, start=end, command=twist(0.0, 0.0))
    run(drive, handles, 0.1, start=end, command=twist(-0.2, 0.0))
    assert drive.limited_command[0] == pytest.approx(-0.25 * 0.1, rel=1e-3)


def test_the_jerk_limit_rounds_the_start_of_a_ramp():
    limiter = RateLimiter(RateLimits(max_acceleration=1.0, max_jerk=10.0))
    values = [0.0, 0.0]
    for _ in range(5):
        values.append(limiter.limit(1.0, values[-1], values[-2], DT))
    steps = [after - before for before, after in zip(values[1:], values[2:], strict=False)]
    assert steps == pytest.approx([10.0 * DT * DT * k for k in range(1, 6)])


def test_the_deprecated_has_limits_switch_turns_a_group_off():
    drive, _ = controller(**{'linear.x.max_velocity': 0.1,
                             'linear.x.has_velocity_limits': False})
    drive.set_command(twist(0.5, 0.0))
    drive.update(0.0, DT)
    assert drive.limited_command[0] == pytest.approx(0.5)


def test_odometry_from_the_wheel_positions_integrates_a_straight_line():
    drive, handles = controller()
    run(drive, handles, 2.0, command=twist(0.25, 0.0))
    odometry = drive.odometry
    # The last update sees the wheels' travel up to the step before it.
    assert odometry.x == pytest.approx(0.25 * (2.0 - DT), rel=1e-6)
    assert odometry.y == pytest.approx(0.0, abs=1e-12)
    assert odometry.linear == pytest.approx(0.25)


def test_odometry_integrates_an_arc_exactly():
    drive, handles = controller()
    run(drive, handles, 3.0, command=twist(0.2, 1.0))
    odometry = drive.odometry
    # On a circle of radius 0.2 m about (0, 0.2), at the heading the wheels turned it to.
    heading = odometry.heading
    assert heading == pytest.approx(1.0 * (3.0 - DT), rel=1e-9)
    assert odometry.x == pytest.approx(0.2 * math.sin(heading), abs=1e-9)
    assert odometry.y == pytest.approx(0.2 * (1.0 - math.cos(heading)), abs=1e-9)
    assert odometry.angular == pytest.approx(1.0)


def test_open_loop_odometry_follows_the_limited_command_not_the_wheels():
    drive, handles = controller(open_loop=True, cmd_vel_timeout=0.0,
                                **{'linear.x.max_velocity': 0.1})
    drive.set_command(twist(0.3, 0.0))
    for step in range(1001):
        drive.update(step * DT, DT)  # the wheels never turn
    assert drive.odometry.x == pytest.approx(0.1, rel=1e-6)
    assert drive.state_interfaces() == {}


def test_velocity_feedback_odometry_integrates_the_wheels_velocities():
    drive, handles = controller(position_feedback=False)
    run(drive, handles, 1.0 + DT, command=twist(0.2, 0.0))
    assert drive.odometry.x == pytest.approx(0.2, rel=1e-3)
    assert drive.state_interfaces() == {'left_wheel_joint': ('velocity',),
                                        'right_wheel_joint': ('velocity',)}


def test_a_reset_puts_the_odometry_back_at_the_origin_and_forgets_the_command():
    drive, handles = controller()
    run(drive, handles, 0.5, command=twist(0.2, 0.3))
    drive.reset()
    assert (drive.odometry.x, drive.odometry.y, drive.odometry.heading) == (0.0, 0.0, 0.0)
    run(drive, handles, 0.1, start=0.5)  # the wheels stand, even though they were turned
    assert drive.odometry.x == 0.0
    assert all(handle.velocity_target == 0.0 for handle in handles.values())


def test_odometry_samples_leave_at_publish_rate_with_the_frames_and_covariances():
    drive, handles = controller(publish_rate=10.0, pose_covariance_diagonal=[1, 2, 3, 4, 5, 6],
                                tf_frame_prefix='robot1')
    samples, transforms = [], []
    surface = {endpoint.name: endpoint for endpoint in drive.ros_surface()}
    odometry, tf = surface['~/odom'], surface['/tf']
    assert isinstance(odometry, StateTopic) and odometry.message == 'nav_msgs/msg/Odometry'
    assert odometry.fields['frame_id'] == 'robot1/odom'
    assert odometry.fields['child_frame_id'] == 'robot1/base_link'
    assert odometry.fields['pose_covariance_diagonal'] == (1, 2, 3, 4, 5, 6)
    assert tf.message == 'tf2_msgs/msg/TFMessage'
    odometry.connect(lambda *sample: samples.append(sample))
    tf.connect(lambda time, frames: transforms.append((time, frames)))
    run(drive, handles, 1.0, command=twist(0.2, 0.0))
    assert [round(sample[0], 6) for sample in samples] == pytest.approx(
        [0.1 * k for k in range(10)])
    parent, child, pose = transforms[-1][1][0]
    assert (parent, child) == ('robot1/odom', 'robot1/base_link')
    assert pose.translation[0] == pytest.approx(samples[-1][1])


def test_the_surface_is_cmd_vel_odom_and_as_configured_tf_and_cmd_vel_out():
    drive, _ = controller(enable_odom_tf=False, publish_limited_velocity=True)
    drive.node_namespace = '/robot1'
    surface = {endpoint.name: endpoint for endpoint in drive.ros_surface()}
    assert set(surface) == {'~/cmd_vel', '~/odom', '~/cmd_vel_out'}
    command = surface['~/cmd_vel']
    assert isinstance(command, CommandTopic)
    assert command.message == 'geometry_msgs/msg/TwistStamped'
    assert surface['~/odom'].fields['frame_id'] == 'robot1/odom'  # the namespace's prefix
    plain, _ = controller(tf_frame_prefix_enable=False)
    plain.node_namespace = '/robot1'
    assert plain.frame_ids() == ('odom', 'base_link')


def test_it_exports_linear_and_angular_velocity_references_and_follows_them_when_chained():
    drive, handles = controller(cmd_vel_timeout=0.1)
    references = drive.reference_interfaces()
    assert list(references) == [f'{NAME}/linear/velocity', f'{NAME}/angular/velocity']
    assert all(math.isnan(reference.value) for reference in references.values())
    drive.set_chained_mode(True)
    references[f'{NAME}/linear/velocity'].value = 0.1
    references[f'{NAME}/angular/velocity'].value = 0.0
    run(drive, handles, 0.5)  # no cmd_vel, and no timeout: the references rule
    assert handles['right_wheel_joint'].velocity_target == pytest.approx(0.1 / WHEEL_RADIUS)


@pytest.mark.parametrize('overrides, field, problem', [
    ({'wheel_radius': 0.0}, 'wheel_radius', 'must be > 0'),
    ({'wheel_separation': -1.0}, 'wheel_separation', 'must be > 0'),
    ({'left_wheel_names': []}, 'left_wheel_names', 'must not be empty'),
    ({'right_wheel_names': ['a', 'b']}, 'right_wheel_names', 'each side needs as many'),
    ({'right_wheel_names': ['left_wheel_joint']}, 'right_wheel_names', 'also one of'),
    ({'pose_covariance_diagonal': [0.1]}, 'pose_covariance_diagonal', 'must have 6 elements'),
    ({'linear.x.max_velocity': -1.0}, 'linear.x.max_velocity', '>= 0 or NaN'),
    ({'angular.z.max_deceleration': 1.0}, 'angular.z.max_deceleration', '<= 0 or NaN'),
])
def test_a_wrong_parameter_is_an_error_naming_the_file_controller_and_field(
        overrides, field, problem):
    params = drive_parameters(**overrides)
    with pytest.raises(ControllerConfigError, match=rf'^rover\.yaml: {NAME}\.{field}: .*'
                       rf'{problem}'):
        DiffDriveController(NAME, params, 'rover.yaml')


@pytest.mark.parametrize('limits, problem', [
    (RateLimits(min_velocity=2.0, max_velocity=1.0), 'min_velocity 2 > max_velocity 1'),
    (RateLimits(max_acceleration=1.0, max_acceleration_reverse=2.0),
     'max_acceleration_reverse 2 > max_acceleration 1'),
    (RateLimits(max_jerk=1.0, min_jerk=3.0), 'min_jerk 3 > max_jerk 1'),
])
def test_a_rate_limiter_refuses_limits_that_contradict_each_other(limits, problem):
    with pytest.raises(InvalidLimitsError, match=problem):
        RateLimiter(limits)


def test_a_wheel_the_robot_lacks_is_an_error_naming_the_parameter():
    drive = DiffDriveController(NAME, drive_parameters(right_wheel_names=['right_whel_joint']),
                                'rover.yaml')
    with pytest.raises(ControllerConfigError, match=rf"{NAME}\.right_wheel_names: joint "
                                                    "'right_whel_joint' is not a movable joint"):
        drive.configure(wheel_handles())


def test_the_deprecated_min_acceleration_is_accepted_with_a_warning_that_it_does_nothing():
    drive = DiffDriveController(NAME, drive_parameters(**{'angular.z.min_acceleration': -1.0}),
                                'rover.yaml')
    assert any('angular.z.min_acceleration' in warning and 'no effect' in warning
               for warning in drive.config_warnings)


def test_a_velocity_group_chained_before_it_drives_the_base_through_its_references(tmp_path):
    description_path, _ = write_rover(tmp_path)
    controllers = tmp_path / 'chain.yaml'
    controllers.write_text(yaml.safe_dump({
        'controller_manager': {'ros__parameters': {
            NAME: {'type': 'diff_drive_controller/DiffDriveController'},
            'twist': {'type': 'velocity_controllers/JointGroupVelocityController'}}},
        NAME: {'ros__parameters': drive_parameters(cmd_vel_timeout=0.1)},
        'twist': {'ros__parameters': {'joints': [f'{NAME}/linear', f'{NAME}/angular']}}}))
    description = load_description(description_path)
    handles = {joint.name: JointHandle(joint) for joint in description.actuated_joints}
    manager = ControllerManager(load_controllers_config(controllers), handles, description.model)
    drive, twist = manager.controller(NAME), manager.controller('twist')
    assert drive.is_chained
    assert twist.set_command([0.1, 0.0]) is CommandResult.ACCEPTED
    for step in range(300):  # longer than cmd_vel_timeout: chained, it does not apply
        for update in manager.updates:
            update(step * DT, DT)
    assert handles['left_wheel_joint'].velocity_target == pytest.approx(0.1 / WHEEL_RADIUS)


def test_the_limited_twist_leaves_on_cmd_vel_out_at_the_update_rate():
    drive, handles = controller(publish_limited_velocity=True, update_rate=100.0,
                                **{'linear.x.max_velocity': 0.1})
    surface = {endpoint.name: endpoint for endpoint in drive.ros_surface()}
    limited = surface['~/cmd_vel_out']
    assert limited.message == 'geometry_msgs/msg/TwistStamped'
    samples = []
    limited.connect(lambda *sample: samples.append(sample))
    run(drive, handles, 0.1, command=twist(0.3, 0.2))
    assert len(samples) == 10
    assert samples[-1][1:] == pytest.approx((0.1, 0.2))


def pid_chain_file(tmp_path, **drive):
    """Write example 16's chain for the rover: each wheel a velocity PID's reference."""
    pids = {side: f'pid_controller_{side}_wheel_joint' for side in ('left', 'right')}
    document = {'controller_manager': {'ros__parameters': {
        **{pid: {'type': 'pid_controller/PidController'} for pid in pids.values()},
        NAME: {'type': 'diff_drive_controller/DiffDriveController'}}}}
    for side, pid in pids.items():
        document[pid] = {'ros__parameters': {
            'dof_names': [f'{side}_wheel_joint'], 'command_interface': 'velocity',
            'reference_and_state_interfaces': ['velocity'],
            'gains': {f'{side}_wheel_joint': {'p': 0.5, 'i': 2.5, 'd': 0.0}}}}
    document[NAME] = {'ros__parameters': drive_parameters(
        left_wheel_names=[f"{pids['left']}/left_wheel_joint"],
        right_wheel_names=[f"{pids['right']}/right_wheel_joint"], cmd_vel_timeout=0.0, **drive)}
    path = tmp_path / 'pid_chain.yaml'
    path.write_text(yaml.safe_dump(document))
    return path


def pid_chain(tmp_path, **drive):
    """Return the manager of example 16's chain on the rover's wheels, and their handles."""
    description_path, _ = write_rover(tmp_path)
    description = load_description(description_path)
    handles = {joint.name: JointHandle(joint) for joint in description.actuated_joints}
    manager = ControllerManager(load_controllers_config(pid_chain_file(tmp_path, **drive)),
                                handles, description.model)
    return manager, handles


def test_wheels_named_as_pid_references_get_the_wheel_velocities_written_there(tmp_path):
    manager, handles = pid_chain(tmp_path)
    drive = manager.controller(NAME)
    left = manager.controller('pid_controller_left_wheel_joint')
    assert left.is_chained and not drive.is_chained
    # The PIDs drive the wheels; the diff drive drives no joint itself.
    assert set(drive.actuators()) == set()
    assert drive.set_command(twist(0.2, 0.5)) is CommandResult.ACCEPTED
    for update in manager.updates:
        update(0.0, DT)
    half = WHEEL_SEPARATION / 2
    assert left.setpoints() == {'left_wheel_joint': pytest.approx((0.2 - 0.5 * half)
                                                                  / WHEEL_RADIUS)}
    assert drive.setpoints() == {
        'pid_controller_left_wheel_joint/left_wheel_joint': pytest.approx(
            (0.2 - 0.5 * half) / WHEEL_RADIUS),
        'pid_controller_right_wheel_joint/right_wheel_joint': pytest.approx(
            (0.2 + 0.5 * half) / WHEEL_RADIUS)}
    # The PID turned its reference into the wheel's velocity target.
    assert handles['left_wheel_joint'].velocity_target != 0.0


def test_a_chained_wheel_is_fed_back_by_the_joint_its_pid_reads(tmp_path):
    manager, handles = pid_chain(tmp_path, position_feedback=False, open_loop=False)
    drive = manager.controller(NAME)
    for handle in handles.values():
        handle.velocity = 4.0  # rad/s: 0.2 m/s straight ahead
    for step in range(1000):
        drive.update(step * DT, DT)
    assert drive.odometry.x == pytest.approx(0.2, rel=1e-3)


def test_a_chained_wheel_without_a_joint_behind_it_needs_open_loop(tmp_path):
    description_path, _ = write_rover(tmp_path)
    drive = DiffDriveController(NAME, drive_parameters(
        left_wheel_names=['other/left'], right_wheel_names=['other/right'], open_loop=False),
        'rover.yaml')
    left, right = Reference('other/left/velocity'), Reference('other/right/velocity')
    drive.set_available_references({left.name: left, right.name: right})
    with pytest.raises(ControllerConfigError,
                       match=rf"{NAME}\.left_wheel_names: 'other/left' is a reference "
                             "interface.*set open_loop to true"):
        drive.configure(wheel_handles())
    drive = DiffDriveController(NAME, drive_parameters(
        left_wheel_names=['other/left'], right_wheel_names=['other/right'], open_loop=True),
        'rover.yaml')
    drive.set_available_references({left.name: left, right.name: right})
    drive.configure(wheel_handles())
    drive.set_command(twist(0.1, 0.0))
    drive.update(0.0, DT)
    assert left.value == pytest.approx(0.1 / WHEEL_RADIUS) == right.value
