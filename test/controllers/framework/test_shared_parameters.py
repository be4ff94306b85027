"""The parameter entries the drive controllers share: odometry frames and covariances, tf prefix."""

from __future__ import annotations

import pytest

from pan_tilt_sim.controllers.framework.parameter_spec import ParameterSpec, load_parameters
from pan_tilt_sim.controllers.framework.shared_parameters import odometry_frames, tf_frame_prefix
from pan_tilt_sim.errors import ControllerConfigError


def test_the_entries_have_upstreams_names_and_defaults():
    frames = odometry_frames()
    assert [param.name for param in frames] == [
        'odom_frame_id', 'base_frame_id', 'pose_covariance_diagonal', 'twist_covariance_diagonal']
    assert [param.default for param in frames] == ['odom', 'base_link', [0.0] * 6, [0.0] * 6]
    assert not any(param.read_only for param in frames)


def test_names_defaults_and_read_only_are_the_callers():
    frames = odometry_frames(covariance=(0.1,) * 6, pose_name='diagonal_covariance.pose',
                             twist_name='diagonal_covariance.twist', read_only=True)
    assert (frames.pose_covariance.name, frames.twist_covariance.name) == (
        'diagonal_covariance.pose', 'diagonal_covariance.twist')
    assert frames.pose_covariance.default == frames.twist_covariance.default == [0.1] * 6
    assert all(param.read_only for param in frames)


def test_each_call_has_its_own_default_lists():
    first, second = odometry_frames(), odometry_frames()
    first.pose_covariance.default.append(1.0)
    assert second.pose_covariance.default == [0.0] * 6


@pytest.mark.parametrize('field, value', [
    ('pose_covariance_diagonal', [0.0] * 5),
    ('twist_covariance_diagonal', [0.0] * 7),
    ('odom_frame_id', 'bad frame'),
])
def test_a_covariance_of_another_length_or_a_bad_frame_is_refused(field, value):
    spec = ParameterSpec(odometry_frames())
    load_parameters(spec, {}, 'c', 'controllers.yaml')  # the defaults pass
    with pytest.raises(ControllerConfigError, match=f'c.{field}'):
        load_parameters(spec, {field: value}, 'c', 'controllers.yaml')


def test_the_frame_prefix_entries_have_upstreams_names_and_defaults():
    enable, prefix = tf_frame_prefix()
    assert (enable.name, enable.default, prefix.name, prefix.default) == (
        'tf_frame_prefix_enable', True, 'tf_frame_prefix', '')
    assert not enable.read_only and not prefix.read_only


def test_each_frame_prefix_entry_is_read_only_as_the_caller_says():
    enable, prefix = tf_frame_prefix(prefix_read_only=True)
    assert (enable.read_only, prefix.read_only) == (False, True)
    enable, prefix = tf_frame_prefix(enable_read_only=True, prefix_read_only=True)
    assert enable.read_only and prefix.read_only


def test_a_frame_prefix_with_a_space_is_refused():
    spec = ParameterSpec(tf_frame_prefix())
    loaded = load_parameters(spec, {'tf_frame_prefix': 'robot/'}, 'c', 'controllers.yaml')
    assert loaded.get('tf_frame_prefix') == 'robot/'
    with pytest.raises(ControllerConfigError, match='c.tf_frame_prefix'):
        load_parameters(spec, {'tf_frame_prefix': 'bad prefix'}, 'c', 'controllers.yaml')
