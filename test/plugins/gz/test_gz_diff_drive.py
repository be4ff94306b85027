"""gz-sim DiffDrive's unit on its own: wheel speeds, the speed limiter, odometry, topics.

The system runs against ideal wheels (each turns exactly at its target), so
every figure follows from its kinematics alone.
"""

from __future__ import annotations

import math
import pathlib

import pytest
from mobile_fixtures import GZ_DIFF_DRIVE, WHEEL_RADIUS, WHEEL_SEPARATION, plugin_rover_urdf

from pan_tilt_sim.controllers import JointHandle
from pan_tilt_sim.controllers.framework.base import ActuatorKind, CommandResult
from pan_tilt_sim.controllers.framework.surface import CommandTopic, StampedTwist, StateTopic
from pan_tilt_sim.model.robot import JointKind, JointSpec
from pan_tilt_sim.model.urdf import parse_urdf
from pan_tilt_sim.plugins.gz.diff_drive import GzDiffDrive
from pan_tilt_sim.plugins.registry import read_settings

DT = 0.001
WHEELS = ('left_wheel_joint', 'right_wheel_joint')
UNLIMITED = GZ_DIFF_DRIVE.replace('<max_linear_acceleration>1.0</max_linear_acceleration>', '')


def twist(linear: float, angular: float) -> StampedTwist:
    return StampedTwist(0.0, (linear, 0.0, 0.0), (0.0, 0.0, angular))


def unit(text: str = GZ_DIFF_DRIVE) -> tuple[GzDiffDrive, dict[str, JointHandle]]:
    robot = parse_urdf(plugin_rover_urdf(text), pathlib.Path('r.urdf'))
    (plugin,) = read_settings(robot, GzDiffDrive)
    handles = {name: JointHandle(JointSpec(name, JointKind.CONTINUOUS)) for name in WHEELS}
    drive = GzDiffDrive(plugin)
    drive.configure(handles)
    return drive, handles


def run(drive: GzDiffDrive, handles: dict[str, JointHandle], seconds: float) -> None:
    for step in range(round(seconds / DT)):
        drive.update(step * DT, DT)
        for handle in handles.values():
            handle.velocity = handle.velocity_target
            handle.position += handle.velocity * DT


def test_the_wheels_are_ideal_velocity_driven_at_the_twists_speeds():
    drive, handles = unit(UNLIMITED.replace('<min_linear_acceleration>-1.0'
                                            '</min_linear_acceleration>', ''))
    assert {actuator.kind for actuator in drive.actuators().values()} == {
        ActuatorKind.IDEAL_VELOCITY}
    assert drive.set_command(twist(0.2, 1.0)) is CommandResult.ACCEPTED
    run(drive, handles, 0.01)
    half = 1.0 * WHEEL_SEPARATION / 2.0
    assert handles['left_wheel_joint'].velocity_target == pytest.approx(
        (0.2 - half) / WHEEL_RADIUS)
    assert handles['right_wheel_joint'].velocity_target == pytest.approx(
        (0.2 + half) / WHEEL_RADIUS)


def test_the_acceleration_limit_ramps_the_speed_every_step():
    drive, handles = unit()  # max/min linear acceleration +-1 m/s^2
    drive.set_command(twist(0.2, 0.0))
    run(drive, handles, 0.1)
    speed = handles['left_wheel_joint'].velocity_target * WHEEL_RADIUS
    assert speed == pytest.approx(0.1, abs=0.002)


def test_an_absent_minimum_leaves_that_direction_unbounded():
    drive, handles = unit(GZ_DIFF_DRIVE.replace(
        '<min_linear_acceleration>-1.0</min_linear_acceleration>', ''))
    drive.set_command(twist(0.2, 0.0))
    run(drive, handles, 0.3)
    drive.set_command(twist(0.0, 0.0))
    drive.update(0.3, DT)
    assert handles['left_wheel_joint'].velocity_target == 0.0  # stops at once: no lower bound


def test_the_odometry_integrates_the_first_wheels_at_the_publish_frequency():
    drive, handles = unit(UNLIMITED)
    samples: list = []
    drive.set_odometry_sink(lambda *sample: samples.append(sample))
    transforms: list = []
    drive.set_tf_sink(lambda time, frames: transforms.append(frames))
    drive.set_command(twist(0.5, 0.0))
    run(drive, handles, 1.0)
    assert len(samples) == pytest.approx(100, abs=1)  # odom_publish_frequency 100
    time, x, y, heading, linear, angular = samples[-1]
    assert x == pytest.approx(0.5 * time, abs=0.01) and y == pytest.approx(0.0, abs=1e-9)
    assert linear == pytest.approx(0.5, abs=1e-6)
    parent, child, pose = transforms[-1][0]
    assert (parent, child) == ('rover/odom', 'rover/base_link')
    assert pose.translation[0] == pytest.approx(x)


def test_a_non_finite_twist_is_refused_and_the_last_holds():
    drive, handles = unit(UNLIMITED)
    drive.set_command(twist(0.2, 0.0))
    assert drive.set_command(twist(math.nan, 0.0)) is CommandResult.REJECTED
    assert 'not finite' in drive.command_problem(None, CommandResult.REJECTED)
    run(drive, handles, 0.01)
    assert handles['left_wheel_joint'].velocity_target * WHEEL_RADIUS == pytest.approx(0.2)


def test_its_topics_are_the_bridged_gz_names():
    drive, _ = unit()
    command, odometry, tf = drive.ros_surface()
    assert isinstance(command, CommandTopic) and command.name == '/model/rover/cmd_vel'
    assert command.message == 'geometry_msgs/msg/Twist'
    assert isinstance(odometry, StateTopic) and odometry.name == '/model/rover/odometry'
    assert tf.name == '/model/rover/tf' and tf.message == 'tf2_msgs/msg/TFMessage'


def test_a_reset_drops_the_command_and_the_odometry():
    drive, handles = unit(UNLIMITED)
    drive.set_command(twist(0.5, 0.0))
    run(drive, handles, 0.5)
    drive.reset()
    assert drive.odometry.x == 0.0
    run(drive, handles, 0.1)
    assert handles['left_wheel_joint'].velocity_target == 0.0


def test_turning_in_place_the_odometry_heading_follows_the_two_wheels():
    drive, handles = unit(UNLIMITED)
    samples: list = []
    drive.set_odometry_sink(lambda *sample: samples.append(sample))
    drive.set_command(twist(0.0, 1.0))
    run(drive, handles, 1.0)
    time, x, y, heading, linear, angular = samples[-1]
    assert heading == pytest.approx(time, abs=0.01)  # 1 rad/s
    assert angular == pytest.approx(1.0, abs=1e-6) and abs(x) < 1e-9
