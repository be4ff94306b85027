# Copyright 2026 pan_tilt_sim maintainers. Licensed under the Apache License, Version 2.0.
"""Stand-in for ros_gz_sim's gz_spawn_model.launch.py: pan_tilt_sim's ``create``.

The same launch arguments (world, file, model_string, topic, entity_name,
allow_renaming, x, y, z, R, P, Y) become ``create``'s ROS parameters, as there;
``create`` hands the robot to the running sim_node and exits 0 once it is in.
"""

from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from launch import LaunchDescription

# Launch argument -> create's parameter, and the argument's default.
SOURCES = {'world': ('world', ''), 'file': ('file', ''), 'model_string': ('string', ''),
           'topic': ('topic', ''), 'entity_name': ('name', ''),
           'allow_renaming': ('allow_renaming', 'False')}
POSE = ('x', 'y', 'z', 'R', 'P', 'Y')  # not declared there either: default '0.0'


def generate_launch_description():
    """Return the arguments and the create node."""
    parameters = {parameter: LaunchConfiguration(argument)
                  for argument, (parameter, _default) in SOURCES.items()}
    parameters.update({axis: LaunchConfiguration(axis, default='0.0') for axis in POSE})
    return LaunchDescription([
        *[DeclareLaunchArgument(argument, default_value=default)
          for argument, (_parameter, default) in SOURCES.items()],
        Node(package='pan_tilt_sim', executable='create', output='screen',
             parameters=[parameters]),
    ])
