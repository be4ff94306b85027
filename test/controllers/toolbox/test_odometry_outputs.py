"""OdometryOutputs: where a drive's odometry and its odom -> base transform go."""

from __future__ import annotations

import math

import pytest

from pan_tilt_sim.controllers.toolbox.odometry_outputs import OdometryOutputs


def test_a_planar_sample_goes_to_the_odometry_and_as_a_transform_to_tf():
    outputs = OdometryOutputs()
    samples, transforms = [], []
    outputs.set_odometry_sink(lambda *sample: samples.append(sample))
    outputs.set_tf_sink(lambda time, frames: transforms.append((time, frames)))
    outputs.publish_planar(2.5, 1.0, -2.0, math.pi / 2.0, 0.3, -0.1, ('odom', 'base'))
    assert samples == [(2.5, 1.0, -2.0, math.pi / 2.0, 0.3, -0.1)]
    [(time, [(parent, child, pose)])] = transforms
    assert (time, parent, child) == (2.5, 'odom', 'base')
    assert pose.translation == (1.0, -2.0, 0.0)
    assert pose.rotation == pytest.approx((0.0, 0.0, math.sqrt(0.5), math.sqrt(0.5)))
    assert pose.apply((1.0, 0.0, 0.0)) == pytest.approx((1.0, -1.0, 0.0))  # x turned to +y


def test_without_sinks_nothing_is_sent():
    outputs = OdometryOutputs()
    outputs.publish_planar(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, ('odom', 'base'))  # no sink: no error
    samples = []
    outputs.set_tf_sink(lambda time, frames: samples.append(frames))
    outputs.publish_planar(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, ('odom', 'base'))
    assert len(samples) == 1
