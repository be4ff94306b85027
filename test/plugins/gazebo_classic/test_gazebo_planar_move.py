"""libgazebo_ros_planar_move.so's unit on its own: the velocity it sets, its odometry, timeout.

The unit reads the base's motion from a value the tests set, so every figure is exact.
"""

from __future__ import annotations

import math
import pathlib

import pytest
from mobile_fixtures import PLANAR_MOVE, plugin_rover_urdf

from pan_tilt_sim.controllers.framework.base import CommandResult
from pan_tilt_sim.controllers.framework.surface import StampedTwist
from pan_tilt_sim.model.transforms import Transform, quaternion_from_rpy
from pan_tilt_sim.model.urdf import parse_urdf
from pan_tilt_sim.plugins.gazebo_classic.planar_move import GazeboPlanarMove
from pan_tilt_sim.plugins.registry import read_settings

DT = 0.001
FACING_LEFT = (Transform((1.0, 2.0, 0.075), quaternion_from_rpy(0.0, 0.0, math.pi / 2)),
               (0.0, 0.3, 0.0), (0.0, 0.0, 0.1))
ROS1 = ('<plugin name="move" filename="libgazebo_ros_planar_move.so">'
        '<cmdTimeout>0.5</cmdTimeout><odometryRate>10</odometryRate></plugin>')


def twist(x: float, y: float, angular: float) -> StampedTwist:
    return StampedTwist(0.0, (x, y, 0.0), (0.0, 0.0, angular))


def unit(text: str = PLANAR_MOVE) -> GazeboPlanarMove:
    (plugin,) = read_settings(parse_urdf(plugin_rover_urdf(text),
                                         pathlib.Path('r.urdf')), GazeboPlanarMove)
    mover = GazeboPlanarMove(plugin)
    mover.set_base_motion(lambda: FACING_LEFT)
    return mover


def test_the_twist_is_turned_into_a_world_velocity_by_the_base_heading():
    mover = unit()
    assert mover.set_command(twist(0.2, 0.1, 0.5)) is CommandResult.ACCEPTED
    mover.update(0.01, DT)  # one update period (100 Hz) after the start
    linear, angular = mover.take_base_velocity()
    assert linear == pytest.approx((-0.1, 0.2, 0.0))  # forward is +y, left is -x
    assert angular == (0.0, 0.0, 0.5)
    assert mover.take_base_velocity() is None  # once per update


def test_the_velocity_is_set_at_the_update_rate():
    mover = unit()  # update_rate 100
    mover.set_command(twist(0.2, 0.0, 0.0))
    due = []
    for step in range(1, 101):  # as the plugin: the first update one period after the start
        mover.update(step * DT, DT)
        due.append(mover.take_base_velocity() is not None)
    assert sum(due) == 10


def test_the_odometry_is_the_true_pose_and_the_twist_in_the_base_axes():
    mover = unit()
    samples: list = []
    mover.set_odometry_sink(lambda *sample: samples.append(sample))
    frames: list = []
    mover.set_tf_sink(lambda time, transforms: frames.append(transforms))
    for step in range(1, 101):
        mover.update(step * DT, DT)
    assert len(samples) == 10  # publish_rate 100
    _time, pose, linear, angular = samples[-1]
    assert pose == FACING_LEFT[0]
    assert linear == pytest.approx((0.3, 0.0, 0.0))  # moving along +y, facing +y
    assert angular == (0.0, 0.0, 0.1)
    assert frames[-1][0][:2] == ('odom', 'base_link')


def test_ros1_the_command_times_out_after_cmd_timeout():
    mover = unit(ROS1)
    mover.update(0.0, DT)
    mover.set_command(twist(0.2, 0.0, 0.0))
    mover.update(0.4, DT)
    assert mover.command == (0.2, 0.0, 0.0)
    mover.update(0.6, DT)
    assert mover.command == (0.0, 0.0, 0.0)


def test_a_non_finite_twist_is_refused_and_a_reset_drops_the_command():
    mover = unit()
    mover.set_command(twist(0.2, 0.0, 0.0))
    bad = twist(0.0, math.inf, 0.0)
    assert mover.set_command(bad) is CommandResult.REJECTED
    assert mover.command_problem(bad, CommandResult.REJECTED) == (
        'ignored cmd_vel (linear.x 0.0, linear.y inf, angular.z 0.0): not finite numbers')
    assert mover.command == (0.2, 0.0, 0.0)
    mover.reset()
    assert mover.command == (0.0, 0.0, 0.0)
