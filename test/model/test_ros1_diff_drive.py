"""ROS 1's diff_drive_controller parameters, read as jazzy's: names, defaults, URDF geometry."""

import pathlib

import pytest
from mobile_fixtures import WHEEL_RADIUS, WHEEL_SEPARATION, rover_urdf

from pan_tilt_sim.controllers.drives.diff_drive_controller import DiffDriveController
from pan_tilt_sim.controllers.framework.base import CommandKind
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model import ros1_diff_drive
from pan_tilt_sim.model.urdf import parse_urdf

TYPE = 'diff_drive_controller/DiffDriveController'
ROVER = parse_urdf(rover_urdf(ros2_control=False), pathlib.Path('rover.urdf'))


def noetic(**extra):
    params = {'type': TYPE, 'left_wheel': 'left_wheel_joint', 'right_wheel': ['right_wheel_joint'],
              'wheel_separation': 0.3, 'wheel_radius': 0.05}
    params.update(extra)
    return params


def test_the_ros1_layout_is_told_by_left_wheel_and_right_wheel():
    assert ros1_diff_drive.is_ros1_layout(noetic())
    assert not ros1_diff_drive.is_ros1_layout({'left_wheel_names': ['a'], 'left_wheel': 'a'})
    assert not ros1_diff_drive.is_ros1_layout({'wheel_radius': 0.1})


def test_a_string_or_a_list_names_the_wheels_and_frames_are_not_prefixed():
    params = ros1_diff_drive.jazzy_params(noetic())
    assert params['left_wheel_names'] == ['left_wheel_joint']
    assert params['right_wheel_names'] == ['right_wheel_joint']
    assert params['tf_frame_prefix_enable'] is False
    assert 'left_wheel' not in params and 'type' in params


def test_limits_are_off_unless_has_limits_and_min_acceleration_bounds_both_directions():
    params = ros1_diff_drive.jazzy_params(noetic(
        linear={'x': {'has_velocity_limits': True, 'max_velocity': 0.5,
                      'has_acceleration_limits': True, 'max_acceleration': 1.0,
                      'min_acceleration': -2.0, 'max_jerk': 5.0}},
        angular={'z': {'max_velocity': 1.0}}))
    assert params['linear']['x'] == {'max_velocity': 0.5, 'min_velocity': -0.5,
                                     'max_acceleration': 1.0, 'max_deceleration': -2.0,
                                     'max_acceleration_reverse': -2.0}
    assert params['angular']['z'] == {}  # has_velocity_limits defaults to false in noetic


def test_a_limit_group_turned_on_without_a_maximum_is_zero_as_in_noetic():
    params = ros1_diff_drive.jazzy_params(noetic(linear={'x': {'has_velocity_limits': True}}))
    assert params['linear']['x'] == {'max_velocity': 0.0, 'min_velocity': -0.0}


def test_the_wheel_radius_multiplier_is_both_sides_default_and_publish_cmd_is_renamed():
    params = ros1_diff_drive.jazzy_params(noetic(wheel_radius_multiplier=1.1, publish_cmd=True,
                                                 right_wheel_radius_multiplier=0.9))
    assert params['left_wheel_radius_multiplier'] == 1.1
    assert params['right_wheel_radius_multiplier'] == 0.9
    assert params['publish_limited_velocity'] is True


def test_missing_wheel_geometry_comes_from_the_urdf_as_noetic_reads_it():
    params = {key: value for key, value in noetic().items()
              if key not in ('wheel_separation', 'wheel_radius')}
    filled = ros1_diff_drive.with_urdf_geometry(TYPE, params, ROVER)
    assert filled['wheel_radius'] == pytest.approx(WHEEL_RADIUS)
    assert filled['wheel_separation'] == pytest.approx(WHEEL_SEPARATION)
    given = ros1_diff_drive.with_urdf_geometry(TYPE, noetic(wheel_radius=0.07), ROVER)
    assert given['wheel_radius'] == 0.07
    jazzy = {'left_wheel_names': ['left_wheel_joint']}
    assert ros1_diff_drive.with_urdf_geometry(TYPE, jazzy, ROVER) is jazzy


def test_the_controller_takes_an_unstamped_twist_in_the_ros1_layout():
    controller = DiffDriveController('base_controller', noetic(publish_rate=20.0))
    assert controller.ros1 and controller.command_kind is CommandKind.TWIST
    assert controller.joint_names == ('left_wheel_joint', 'right_wheel_joint')
    assert controller.frame_ids() == ('odom', 'base_link')
    jazzy = DiffDriveController('base_controller', {
        'left_wheel_names': ['left_wheel_joint'], 'right_wheel_names': ['right_wheel_joint'],
        'wheel_separation': 0.3, 'wheel_radius': 0.05})
    assert not jazzy.ros1 and jazzy.command_kind is CommandKind.TWIST_STAMPED


@pytest.mark.parametrize(('params', 'field', 'problem'), [
    ({'left_wheel': 'left_wheel_joint', 'wheel_separation': 0.3, 'wheel_radius': 0.05},
     'base_controller.right_wheel:', 'missing'),
    ({'left_wheel': 'left_wheel_joint', 'right_wheel': 'right_wheel_joint',
      'wheel_separation': 0.3}, 'base_controller.wheel_radius:', 'noetic reads it from the URDF'),
    ({'left_wheel': ['left_wheel_joint', 'caster_joint'], 'right_wheel': 'right_wheel_joint',
      'wheel_separation': 0.3, 'wheel_radius': 0.05}, 'base_controller.right_wheel:',
     '1 wheels, but left_wheel names 2'),
])
def test_a_ros1_layout_error_names_the_ros1_field(params, field, problem):
    with pytest.raises(ControllerConfigError) as raised:
        DiffDriveController('base_controller', params, 'controllers.yaml')
    message = str(raised.value)
    assert message.startswith('controllers.yaml: ') and field in message and problem in message
    assert '\n' not in message
