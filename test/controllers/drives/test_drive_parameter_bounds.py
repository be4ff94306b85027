"""Every drive type refuses, at configure, what its kinematics divide by or cannot publish.

Multipliers, radii, separations, wheelbases and tracks, timeouts and frame ids:
each is checked by the type's parameter spec, so a wrong value ends start-up
with ``<file>: <controller>.<field>: <what is wrong>`` instead of a
ZeroDivisionError, a self-transform or a confusing run-time warning.
"""

from __future__ import annotations

import pytest

from pan_tilt_sim.controllers.framework.parameter_spec import frame_id, frame_id_prefix
from pan_tilt_sim.controllers.framework.registry import CONTROLLER_TYPES, create_controller
from pan_tilt_sim.errors import ControllerConfigError

DIFF = 'diff_drive_controller/DiffDriveController'
MECANUM = 'mecanum_drive_controller/MecanumDriveController'
OMNI = 'omni_wheel_drive_controller/OmniWheelDriveController'
TRICYCLE = 'tricycle_controller/TricycleController'
ACKERMANN = 'ackermann_steering_controller/AckermannSteeringController'
BICYCLE = 'bicycle_steering_controller/BicycleSteeringController'
TRICYCLE_STEERING = 'tricycle_steering_controller/TricycleSteeringController'
ODOMETRY_TYPES = (DIFF, MECANUM, OMNI, TRICYCLE, ACKERMANN, BICYCLE, TRICYCLE_STEERING)


def _params(type_name: str, field: str, value) -> dict:
    params = CONTROLLER_TYPES[type_name].parameters.example()
    node = params
    *parents, leaf = field.split('.')
    for parent in parents:
        node = node.setdefault(parent, {})
    node[leaf] = value
    return params


def _refused(type_name: str, field: str, value, problem: str) -> None:
    with pytest.raises(ControllerConfigError) as raised:
        create_controller('c', type_name, _params(type_name, field, value), 'f.yaml')
    message = str(raised.value)
    assert message.startswith(f'f.yaml: c.{field}: '), message
    assert problem in message, message


@pytest.mark.parametrize(('type_name', 'field', 'value', 'problem'), [
    # Multipliers the wheel speeds and the odometry divide by.
    (DIFF, 'wheel_separation_multiplier', 0.0, '0.0 must be > 0'),
    (DIFF, 'wheel_separation_multiplier', -1.0, '-1.0 must be > 0'),
    (DIFF, 'left_wheel_radius_multiplier', 0.0, '0.0 must be > 0'),
    (DIFF, 'right_wheel_radius_multiplier', -0.5, '-0.5 must be > 0'),
    # Optional lengths (0: not set, as upstream): never negative.
    (ACKERMANN, 'traction_track_width', -0.3, '-0.3 must be >= 0'),
    (ACKERMANN, 'steering_track_width', -0.3, '-0.3 must be >= 0'),
    (ACKERMANN, 'front_wheel_track', -1.0, '-1.0 must be >= 0'),
    (ACKERMANN, 'rear_wheels_radius', -1.0, '-1.0 must be >= 0'),
    (BICYCLE, 'traction_wheel_radius', -0.05, '-0.05 must be >= 0'),
    (BICYCLE, 'front_wheel_radius', -0.05, '-0.05 must be >= 0'),
    (TRICYCLE_STEERING, 'wheel_track', -0.3, '-0.3 must be >= 0'),
    (TRICYCLE_STEERING, 'traction_wheels_radius', -0.05, '-0.05 must be >= 0'),
    # Timeouts.
    (TRICYCLE, 'cmd_vel_timeout', -5, '-5 must be >= 0'),
    (MECANUM, 'reference_timeout', -1.0, '-1.0 must be >= 0'),
    (OMNI, 'cmd_vel_timeout', -0.5, '-0.5 must be >= 0'),
    (ACKERMANN, 'reference_timeout', -1.0, '-1.0 must be >= 0'),
])
def test_a_geometry_or_timeout_out_of_bounds_is_refused_at_configure(type_name, field, value,
                                                                     problem):
    _refused(type_name, field, value, problem)


@pytest.mark.parametrize('type_name', ODOMETRY_TYPES)
@pytest.mark.parametrize(('field', 'value', 'problem'), [
    ('odom_frame_id', '', "'' is not a frame id: it is empty"),
    ('odom_frame_id', 'od om', "'od om' is not a valid frame id"),
    ('base_frame_id', 'base//link', "'base//link' is not a valid frame id"),
    ('base_frame_id', '../base', "'../base' is not a valid frame id"),
    ('base_frame_id', 'odom', "'odom' is odom_frame_id too"),
    ('base_frame_id', '/odom', "'/odom' is odom_frame_id too"),
])
def test_odometry_frames_must_be_frame_ids_and_two_different_ones(type_name, field, value,
                                                                  problem):
    _refused(type_name, field, value, problem)


@pytest.mark.parametrize('type_name', (DIFF, MECANUM, OMNI))
@pytest.mark.parametrize('prefix', ['a b/..//', 'x//', '..'])
def test_a_frame_prefix_that_makes_no_frame_id_is_refused(type_name, prefix):
    _refused(type_name, 'tf_frame_prefix', prefix, 'is not a valid frame id')


@pytest.mark.parametrize('type_name', ['imu_sensor_broadcaster/IMUSensorBroadcaster',
                                       'force_torque_sensor_broadcaster/'
                                       'ForceTorqueSensorBroadcaster',
                                       'range_sensor_broadcaster/RangeSensorBroadcaster',
                                       'pose_broadcaster/PoseBroadcaster'])
def test_a_sensor_broadcasters_frame_id_must_be_a_frame_id(type_name):
    _refused(type_name, 'frame_id', 'imu link', "'imu link' is not a valid frame id")


@pytest.mark.parametrize(('value', 'problem'), [
    ('', None), ('odom', None), ('/odom', None), ('robot_1/base-link.001', None),
    ('/', "'/' is not a frame id: it is empty"), ('a b', 'is not a valid frame id'),
    ('a//b', 'is not a valid frame id'), ('a/', 'is not a valid frame id'),
    ('a/./b', 'is not a valid frame id'), ('é', 'is not a valid frame id'),
])
def test_the_frame_id_rule_follows_tf2_and_ros_names(value, problem):
    checked = frame_id()(value)
    if value == '':
        assert checked == "'' is not a frame id: it is empty"
    elif problem is None:
        assert checked is None
    else:
        assert problem in checked


@pytest.mark.parametrize(('value', 'ok'), [
    ('', True), ('/', True), ('robot1', True), ('robot1/', True), ('/robot1/', True),
    ('a b', False), ('a//', False), ('a b/..//', False),
])
def test_a_frame_id_prefix_is_empty_or_a_frame_id_with_a_trailing_slash(value, ok):
    assert (frame_id_prefix()(value) is None) is ok


def test_upstream_defaults_and_valid_values_still_configure():
    for type_name in ODOMETRY_TYPES:
        create_controller('c', type_name, _params(type_name, 'odom_frame_id', 'robot1/odom'),
                          'f.yaml')
    create_controller('c', DIFF, _params(DIFF, 'wheel_separation_multiplier', 1.05), 'f.yaml')
    create_controller('c', TRICYCLE, _params(TRICYCLE, 'cmd_vel_timeout', 0), 'f.yaml')


@pytest.mark.parametrize(('type_name', 'field'), [
    ('joint_state_broadcaster/JointStateBroadcaster', 'publish_rate'),
    ('joint_state_broadcaster/JointStateBroadcaster', 'update_rate'),
    (DIFF, 'publish_rate'),
    (DIFF, 'update_rate'),
    (MECANUM, 'update_rate'),
    ('pose_broadcaster/PoseBroadcaster', 'tf.publish_rate'),
])
def test_a_rate_so_small_its_period_overflows_is_refused(type_name, field):
    _refused(type_name, field, 5e-324, '5e-324 must be a rate > 0 Hz')
