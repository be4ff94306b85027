"""libgazebo_ros_diff_drive.so's unit on its own: wheel speeds, ramp, torque, odometry, surface.

The plugin runs against joint handles whose velocities the tests set
themselves (ideal wheels: each turns exactly at its target), so every figure
follows from the plugin's kinematics alone.
"""

from __future__ import annotations

import math
import pathlib

import pytest
from mobile_fixtures import (
    ROS1_DIFF_DRIVE,
    ROS2_DIFF_DRIVE,
    WHEEL_RADIUS,
    WHEEL_SEPARATION,
    plugin_rover_urdf,
)

from pan_tilt_sim.controllers import JointHandle
from pan_tilt_sim.controllers.framework.base import ActuatorKind, CommandResult
from pan_tilt_sim.controllers.framework.surface import CommandTopic, StampedTwist, StateTopic
from pan_tilt_sim.model.robot import JointKind, JointSpec
from pan_tilt_sim.model.urdf import parse_urdf
from pan_tilt_sim.plugins.gazebo_classic.diff_drive import GazeboDiffDrive
from pan_tilt_sim.plugins.registry import read_settings

DT = 0.001
WHEELS = ('left_wheel_joint', 'right_wheel_joint')


def twist(linear: float, angular: float) -> StampedTwist:
    """Return a Twist value: linear.x and angular.z (unstamped)."""
    return StampedTwist(0.0, (linear, 0.0, 0.0), (0.0, 0.0, angular))


def unit(plugin_text: str = ROS2_DIFF_DRIVE) -> tuple[GazeboDiffDrive, dict[str, JointHandle]]:
    """Return the configured plugin unit of the rover, and its wheels' handles."""
    robot = parse_urdf(plugin_rover_urdf(plugin_text), pathlib.Path('r.urdf'))
    (plugin,) = read_settings(robot, GazeboDiffDrive)
    handles = {name: JointHandle(JointSpec(name, JointKind.CONTINUOUS)) for name in WHEELS}
    drive = GazeboDiffDrive(plugin)
    drive.configure(handles)
    return drive, handles


def run(drive: GazeboDiffDrive, handles: dict[str, JointHandle], seconds: float,
        start: float = 0.0) -> float:
    """Step for ``seconds``; ideal wheels turn at their targets; return the next step's time."""
    time = start
    for _ in range(round(seconds / DT)):
        drive.update(time, DT)
        for handle in handles.values():
            handle.velocity = handle.velocity_target
            handle.position += handle.velocity * DT
        time += DT
    return time


def test_the_wheels_are_velocity_driven_with_the_wheel_torque_as_force_limit():
    drive, handles = unit()
    actuators = drive.actuators()
    assert set(actuators) == set(WHEELS)
    assert all(actuator.kind is ActuatorKind.IDEAL_VELOCITY and actuator.force_from_controller
               for actuator in actuators.values())
    run(drive, handles, 0.02)
    assert all(handle.force_limit == 20.0 for handle in handles.values())


def test_a_turn_sets_each_wheel_to_v_minus_plus_w_half_separation_over_radius():
    drive, handles = unit(ROS2_DIFF_DRIVE.replace('<max_wheel_acceleration>1.0',
                                                  '<max_wheel_acceleration>0'))
    assert drive.set_command(twist(0.2, 1.0)) is CommandResult.ACCEPTED
    run(drive, handles, 0.02)
    half = WHEEL_SEPARATION / 2
    assert handles['left_wheel_joint'].velocity_target == pytest.approx((0.2 - half) / WHEEL_RADIUS)
    assert handles['right_wheel_joint'].velocity_target == pytest.approx(
        (0.2 + half) / WHEEL_RADIUS)


def test_the_wheel_acceleration_ramps_the_wheels_by_its_amount_per_update():
    drive, handles = unit()  # 1 m/s^2 at 100 Hz: 0.01 m/s per update
    drive.set_command(twist(0.2, 0.0))
    time = run(drive, handles, 0.011)  # steps at 0 to 0.010 s: one update, at 0.01 s
    assert handles['left_wheel_joint'].velocity_target * WHEEL_RADIUS == pytest.approx(0.01)
    time = run(drive, handles, 0.1, start=time)
    assert handles['left_wheel_joint'].velocity_target * WHEEL_RADIUS == pytest.approx(
        0.11, abs=0.011)
    run(drive, handles, 0.3, start=time)
    assert handles['left_wheel_joint'].velocity_target * WHEEL_RADIUS == pytest.approx(0.2)


def test_the_encoder_odometry_integrates_the_wheels():
    drive, handles = unit(ROS1_DIFF_DRIVE)  # no ramp
    drive.set_command(twist(0.2, 0.0))
    run(drive, handles, 2.0)
    assert drive.odometry.x == pytest.approx(0.2 * 2.0, abs=0.01)
    assert drive.odometry.y == pytest.approx(0.0, abs=1e-9)


def test_world_odometry_publishes_the_base_state_it_is_given():
    drive, handles = unit(ROS2_DIFF_DRIVE.replace('<odometry_source>0', '<odometry_source>1'))
    drive.set_base_state(lambda: ((1.0, 2.0, 0.5), (0.3, 0.0, 0.1)))
    samples = []
    drive.set_odometry_sink(lambda *sample: samples.append(sample))
    run(drive, handles, 0.011)
    assert samples == [(pytest.approx(0.01), 1.0, 2.0, 0.5, 0.3, 0.1)]


def test_a_non_finite_twist_is_refused_and_the_last_one_holds():
    drive, handles = unit()
    drive.set_command(twist(0.1, 0.0))
    assert drive.set_command(twist(math.nan, 0.0)) is CommandResult.REJECTED
    assert 'not finite' in drive.command_problem(None, CommandResult.REJECTED)
    assert drive.set_command(twist(0.0, math.inf)) is CommandResult.REJECTED
    run(drive, handles, 0.5)
    assert handles['left_wheel_joint'].velocity_target * WHEEL_RADIUS == pytest.approx(0.1)


def test_its_surface_is_the_plugins_topics_and_frames():
    drive, _ = unit()
    surface = {endpoint.name: endpoint for endpoint in drive.ros_surface()}
    assert isinstance(surface['/cmd_vel'], CommandTopic)
    assert surface['/cmd_vel'].message == 'geometry_msgs/msg/Twist'
    assert isinstance(surface['/odom'], StateTopic)
    assert surface['/odom'].fields['child_frame_id'] == 'base_link'
    assert '/tf' in surface
    quiet, _ = unit(ROS2_DIFF_DRIVE.replace('<publish_odom>true', '<publish_odom>false')
                    .replace('<publish_odom_tf>true', '<publish_odom_tf>false'))
    assert [endpoint.name for endpoint in quiet.ros_surface()] == ['/cmd_vel']


def test_its_tf_goes_to_slash_tf_unless_remapped_into_its_namespace():
    remapped, _ = unit(ROS2_DIFF_DRIVE.replace(
        '<left_joint>', '<ros><namespace>robot2</namespace><remapping>/tf:=tf</remapping>'
                        '</ros><left_joint>'))
    names = [endpoint.name for endpoint in remapped.ros_surface()]
    assert names == ['/robot2/cmd_vel', '/robot2/odom', '/robot2/tf']
    # Without the remapping /tf is absolute, in any namespace (tf2's broadcaster).
    plain, _ = unit(ROS2_DIFF_DRIVE.replace(
        '<left_joint>', '<ros><namespace>robot2</namespace></ros><left_joint>'))
    assert [endpoint.name for endpoint in plain.ros_surface()][-1] == '/tf'


def test_a_reset_drops_the_command_and_the_odometry():
    drive, handles = unit(ROS1_DIFF_DRIVE)
    drive.set_command(twist(0.2, 0.0))
    run(drive, handles, 0.5)
    drive.reset()
    assert drive.odometry.x == 0.0
    run(drive, handles, 0.05)
    assert all(handle.velocity_target == 0.0 for handle in handles.values())


def test_the_start_up_line_names_the_plugins_torque():
    drive, _ = unit(ROS1_DIFF_DRIVE)
    spec = JointSpec('left_wheel_joint', JointKind.CONTINUOUS, effort_limit=2.0)
    line = drive.actuators()['left_wheel_joint'].describe(spec)
    assert "at most 20 N*m (the plugin's wheelTorque)" in line
