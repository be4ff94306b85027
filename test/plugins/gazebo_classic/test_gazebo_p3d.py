"""libgazebo_ros_p3d.so's unit on its own: rate, frames, offsets, noise.

The unit reads link states from a table the tests set, so every figure is exact.
"""

from __future__ import annotations

import math
import pathlib
import random

import pytest
from mobile_fixtures import plugin_rover_urdf

from pan_tilt_sim.model.transforms import Transform, quaternion_from_rpy
from pan_tilt_sim.model.urdf import parse_urdf
from pan_tilt_sim.plugins.gazebo_classic.p3d import GazeboP3d
from pan_tilt_sim.plugins.registry import read_settings

DT = 0.001
BASE = (Transform((1.0, 2.0, 0.1), quaternion_from_rpy(0.0, 0.0, math.pi / 2)),
        (0.0, 0.5, 0.0), (0.0, 0.0, 0.2))
WHEEL = (Transform((1.0, 2.0, 0.05)), (0.0, 0.5, 0.0), (0.0, 0.0, 0.0))


def unit(elements: str, **kwargs) -> tuple[GazeboP3d, list]:
    """Return the p3d unit of ``elements``, reading BASE and WHEEL; and its samples."""
    text = f'<plugin name="truth" filename="libgazebo_ros_p3d.so">{elements}</plugin>'
    (plugin,) = read_settings(parse_urdf(plugin_rover_urdf(ground_truth=text),
                                         pathlib.Path('r.urdf')), GazeboP3d)
    p3d = GazeboP3d(plugin, **kwargs)
    p3d.set_link_state({'base_link': BASE, 'left_wheel': WHEEL}.__getitem__)
    samples: list = []
    p3d.set_odometry_sink(lambda *sample: samples.append(sample))
    return p3d, samples


def run(p3d: GazeboP3d, seconds: float) -> None:
    for step in range(round(seconds / DT)):
        p3d.update(step * DT, DT)


def test_it_publishes_the_true_pose_and_twist_in_the_world():
    p3d, samples = unit('<body_name>base_link</body_name>')
    run(p3d, 0.003)
    assert [time for time, *_ in samples] == [pytest.approx(0.001), pytest.approx(0.002)]
    _, pose, linear, angular = samples[-1]
    assert pose == BASE[0] and linear == BASE[1] and angular == BASE[2]


def test_the_update_rate_spaces_the_samples():
    p3d, samples = unit('<body_name>base_link</body_name><update_rate>100</update_rate>')
    run(p3d, 0.031)  # steps at 0 to 0.030 s
    assert [round(time, 6) for time, *_ in samples] == [0.01, 0.02, 0.03]


def test_nobody_listening_takes_no_sample():
    p3d, samples = unit('<body_name>base_link</body_name>')
    p3d.set_odometry_sink(None)
    run(p3d, 0.01)
    assert samples == []


def test_offsets_move_and_turn_the_pose():
    p3d, samples = unit('<body_name>left_wheel</body_name><xyz_offsets>1 0 0</xyz_offsets>'
                        '<rpy_offsets>0 0 1.5707963267948966</rpy_offsets>')
    run(p3d, 0.002)
    _, pose, _, _ = samples[-1]
    assert pose.translation == pytest.approx((2.0, 2.0, 0.05))
    assert pose.rotation == pytest.approx(quaternion_from_rpy(0.0, 0.0, math.pi / 2))


def test_a_link_frame_gives_the_pose_and_twist_relative_to_it():
    p3d, samples = unit('<body_name>left_wheel</body_name><frame_name>base_link</frame_name>')
    run(p3d, 0.002)
    _, pose, linear, angular = samples[-1]
    assert pose.translation == pytest.approx((0.0, 0.0, -0.05), abs=1e-12)
    assert pose.rotation == pytest.approx(quaternion_from_rpy(0.0, 0.0, -math.pi / 2))
    assert linear == pytest.approx((0.0, 0.0, 0.0), abs=1e-12)
    assert angular == pytest.approx((0.0, 0.0, -0.2))


def test_gaussian_noise_is_added_to_the_twist_only():
    p3d, samples = unit('<body_name>base_link</body_name><gaussian_noise>0.1</gaussian_noise>',
                        rng=random.Random(3))
    run(p3d, 0.2)
    linear_x = [linear[0] for _, _, linear, _ in samples]
    assert all(pose == BASE[0] for _, pose, _, _ in samples)
    assert 0.05 < (sum(x * x for x in linear_x) / len(linear_x)) ** 0.5 < 0.15
