"""gz-sim OdometryPublisher's unit on its own: rate, 2-D and 3-D poses, offsets, twist axes."""

from __future__ import annotations

import math
import pathlib

import pytest
from mobile_fixtures import GZ_DIFF_DRIVE, plugin_rover_urdf

from pan_tilt_sim.model.transforms import Transform, quaternion_from_rpy
from pan_tilt_sim.model.urdf import parse_urdf
from pan_tilt_sim.plugins.gz.odometry_publisher import GzOdometryPublisher
from pan_tilt_sim.plugins.registry import read_settings

DT = 0.001
TILTED = (Transform((1.0, 2.0, 0.3), quaternion_from_rpy(0.1, 0.0, math.pi / 2)),
          (0.0, 0.5, 0.0), (0.0, 0.0, 0.2))


def unit(elements: str = '') -> tuple[GzOdometryPublisher, list]:
    text = ('<plugin filename="gz-sim-odometry-publisher-system" name="odometry">'
            f'{elements}</plugin>')
    (plugin,) = read_settings(parse_urdf(plugin_rover_urdf(GZ_DIFF_DRIVE, ground_truth=text),
                                         pathlib.Path('r.urdf')), GzOdometryPublisher)
    publisher = GzOdometryPublisher(plugin)
    publisher.set_base_motion(lambda: TILTED)
    samples: list = []
    publisher.set_odometry_sink(lambda *sample: samples.append(sample))
    return publisher, samples


def run(publisher: GzOdometryPublisher, seconds: float) -> None:
    for step in range(round(seconds / DT)):
        publisher.update(step * DT, DT)


def test_two_dimensions_keep_x_y_and_yaw_at_the_publish_frequency():
    publisher, samples = unit()
    run(publisher, 1.0)
    assert len(samples) == pytest.approx(50, abs=1)  # 50 Hz by default
    _time, pose, linear, angular = samples[-1]
    assert pose.translation == (1.0, 2.0, 0.0)
    assert pose.rotation == pytest.approx((0.0, 0.0, math.sin(math.pi / 4),
                                           math.cos(math.pi / 4)))
    assert linear[0] == pytest.approx(0.5) and linear[2] == 0.0  # forward, in base axes
    assert angular[:2] == (0.0, 0.0)


def test_three_dimensions_keep_the_whole_pose_and_offsets_move_it():
    publisher, samples = unit('<dimensions>3</dimensions><xyz_offset>0.1 0 0</xyz_offset>')
    run(publisher, 0.1)
    _time, pose, _linear, _angular = samples[-1]
    assert pose.translation == pytest.approx((1.0, 2.1, 0.3))  # 0.1 m ahead, facing +y
    assert pose.rotation == pytest.approx(TILTED[0].rotation)


def test_nothing_is_taken_while_nobody_listens():
    publisher, samples = unit()
    publisher.set_odometry_sink(None)
    run(publisher, 0.1)
    assert samples == []
