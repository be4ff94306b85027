"""Hostile drive geometry, sensor sizes, frames and plugins end start-up with one line.

Each of these was once accepted and later crashed the node, froze it,
published nonsense or named the wrong file.  Now each is a
ConfigurationError of one line naming the file, the controller, plugin or
sensor, the field and the limit -- sim_node's exit code 2 (two cases run
as the program to show it end to end).
"""

from __future__ import annotations

import pathlib

import pytest
import rclpy  # noqa: F401  (the context fixture needs rclpy importable)
import sim_process
import yaml
from mobile_fixtures import (
    ROS2_DIFF_DRIVE,
    drive_parameters,
    plugin_rover_urdf,
    rover_controllers,
    rover_urdf,
)
from rclpy.parameter import Parameter

from pan_tilt_sim.errors import ConfigurationError, ControllerConfigError, DescriptionError
from pan_tilt_sim.ros.sim_node import SimNode

CAMERA = '''
  <gazebo reference="base_link">
    <sensor type="camera" name="front_camera">
      <update_rate>10</update_rate>
      <camera><horizontal_fov>1.0</horizontal_fov>
        <image><width>WIDTH</width><height>HEIGHT</height></image>
        <clip><near>0.1</near><far>10</far></clip></camera>
      <plugin name="camera" filename="libgazebo_ros_camera.so"/>
    </sensor>
  </gazebo>'''


def _replaced(text: str, old: str, new: str) -> str:
    assert old in text
    return text.replace(old, new)


def _rover(extra: str = '') -> str:
    return rover_urdf(extra=extra)


def _tricycle_controllers(**params) -> str:
    return yaml.safe_dump({'controller_manager': {'ros__parameters': {
        'tricycle': {'type': 'tricycle_controller/TricycleController'}}},
        'tricycle': {'ros__parameters': {
            'traction_joint_name': 'left_wheel_joint', 'steering_joint_name': 'right_wheel_joint',
            'wheelbase': 0.3, 'wheel_radius': 0.05, **params}}})


def _mecanum_controllers(**params) -> str:
    wheels = {f'{wheel}_wheel_command_joint_name': f'{wheel}_joint'
              for wheel in ('front_left', 'front_right', 'rear_right', 'rear_left')}
    return yaml.safe_dump({'controller_manager': {'ros__parameters': {
        'mecanum': {'type': 'mecanum_drive_controller/MecanumDriveController'}}},
        'mecanum': {'ros__parameters': {
            **wheels, 'kinematics': {'wheels_radius': 0.05,
                                     'sum_of_robot_center_projection_on_X_Y_axis': 0.3},
            **params}}})


# Per case: (URDF text, controllers text or None: the URDF's plugins run it).
FILES = {
    'separation_multiplier': (_rover(), rover_controllers(
        drive_parameters(wheel_separation_multiplier=0.0))),
    'radius_multiplier': (_rover(), rover_controllers(
        drive_parameters(left_wheel_radius_multiplier=0.0))),
    'lidar_samples': (_replaced(plugin_rover_urdf(), '<samples>90<', '<samples>10000000<'),
                      None),
    'camera_pixels': (_rover(CAMERA.replace('WIDTH', '100000').replace('HEIGHT', '100000')),
                      rover_controllers()),
    'lidar_angle': (_replaced(plugin_rover_urdf(), '<max_angle>1.5708<', '<max_angle>1e300<'),
                    None),
    'same_wheel_twice': (plugin_rover_urdf(_replaced(
        ROS2_DIFF_DRIVE, '<right_joint>right_wheel_joint<', '<right_joint>left_wheel_joint<')),
        None),
    'odom_is_base': (_rover(), rover_controllers(
        drive_parameters(odom_frame_id='base_link', base_frame_id='base_link'))),
    'empty_odom_bad_prefix': (_rover(), rover_controllers(
        drive_parameters(odom_frame_id='', tf_frame_prefix='a b/..//'))),
    'empty_odom': (_rover(), rover_controllers(drive_parameters(odom_frame_id=''))),
    'tricycle_timeout': (_rover(), _tricycle_controllers(cmd_vel_timeout=-5)),
    'mecanum_timeout': (_rover(), _mecanum_controllers(reference_timeout=-1.0)),
    'fixed_wheel': (plugin_rover_urdf(_replaced(
        ROS2_DIFF_DRIVE, '<left_joint>left_wheel_joint<', '<left_joint>caster_joint<')), None),
}


def _case(name: str, error: type, *expected: str):
    return pytest.param(name, error, expected, id=name.replace('_', ' '))


CASES = [
    # 1, 2: a multiplier the kinematics divide by.
    _case('separation_multiplier', ControllerConfigError,
          '{controllers}: base_controller.wheel_separation_multiplier: 0.0 must be > 0'),
    _case('radius_multiplier', ControllerConfigError,
          '{controllers}: base_controller.left_wheel_radius_multiplier: 0.0 must be > 0'),
    # 3, 5, 6: sensor sizes and angles, with the limit and its reason.
    _case('lidar_samples', DescriptionError, "{urdf}: sensor 'lidar': <horizontal> 10000000 "
          'samples x resolution 1 is more than the limit of 262144 beams per scan',
          '128 channels x 2048 columns'),
    _case('camera_pixels', DescriptionError, "{urdf}: sensor 'front_camera': 100000 x 100000 = "
          '10000000000 pixels per image is more than the limit of 8294400', '4K UHD'),
    _case('lidar_angle', DescriptionError, "{urdf}: sensor 'lidar': <horizontal><max_angle> "
          '1e+300 rad is beyond +-2 pi'),
    # 7, 12: a drive plugin's wheels get a controller's checks, the error naming the plugin.
    _case('same_wheel_twice', DescriptionError, "{urdf}: plugin 'diff_drive' "
          "(libgazebo_ros_diff_drive.so): <right_joint> 'left_wheel_joint' is already a wheel "
          '(<left_joint>)'),
    _case('fixed_wheel', DescriptionError, "{urdf}: plugin 'diff_drive' "
          "(libgazebo_ros_diff_drive.so): <left_joint> 'caster_joint' is a fixed joint"),
    # 8: frame ids.
    _case('odom_is_base', ControllerConfigError, '{controllers}: base_controller.base_frame_id: '
          "'base_link' is odom_frame_id too"),
    _case('empty_odom_bad_prefix', ControllerConfigError,
          "{controllers}: base_controller.tf_frame_prefix: 'a b/..//' is not a valid frame id "
          'prefix'),
    _case('empty_odom', ControllerConfigError,
          "{controllers}: base_controller.odom_frame_id: '' is not a frame id: it is empty"),
    # 9: timeouts.
    _case('tricycle_timeout', ControllerConfigError,
          '{controllers}: tricycle.cmd_vel_timeout: -5 must be >= 0'),
    _case('mecanum_timeout', ControllerConfigError,
          '{controllers}: mecanum.reference_timeout: -1.0 must be >= 0'),
]


def _write(directory: pathlib.Path, name: str) -> tuple[pathlib.Path, pathlib.Path | None]:
    urdf_text, controllers_text = FILES[name]
    urdf = directory / f'{name}.urdf'
    urdf.write_text(urdf_text, encoding='utf-8')
    if controllers_text is None:
        return urdf, None
    controllers = directory / f'{name}.yaml'
    controllers.write_text(controllers_text, encoding='utf-8')
    return urdf, controllers


def _expected(parts, urdf, controllers) -> list[str]:
    return [part.replace('{urdf}', str(urdf)).replace('{controllers}', str(controllers))
            for part in parts]


@pytest.mark.parametrize(('name', 'error', 'expected'), CASES)
def test_the_case_ends_start_up_with_one_line_naming_file_field_and_limit(
        context, tmp_path, name, error, expected):
    urdf, controllers = _write(tmp_path, name)
    overrides = [Parameter('robot_description_file', value=str(urdf)),
                 Parameter('real_time_factor', value=0.0)]
    if controllers is not None:
        overrides.append(Parameter('controllers_file', value=str(controllers)))
    with pytest.raises(ConfigurationError) as raised:
        node = SimNode(context=context, parameter_overrides=overrides)
        node.destroy_node()
    message = str(raised.value)
    assert isinstance(raised.value, error), f'{type(raised.value).__name__}: {message}'
    assert '\n' not in message
    for part in _expected(expected, urdf, controllers):
        assert part in message


@pytest.mark.parametrize('name', ['camera_pixels', 'fixed_wheel'])
def test_the_program_exits_2_with_the_one_line(tmp_path, name):
    urdf, controllers = _write(tmp_path, name)
    args = ['-p', f'robot_description_file:={urdf}']
    if controllers is not None:
        args += ['-p', f'controllers_file:={controllers}']
    result = sim_process.run(*args)
    line = sim_process.error_line(result)
    parts = next(case.values[2] for case in CASES if case.values[0] == name)
    for part in _expected(parts, urdf, controllers):
        assert part in line
