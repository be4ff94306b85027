# Copyright 2026 pan_tilt_sim maintainers. Licensed under the Apache License, Version 2.0.
"""Stand-in for gazebo_ros's gzclient.launch.py (Gazebo classic's GUI): starts nothing.

sim_node is headless; its server comes from gzserver.launch.py or gazebo.launch.py.
The arguments are gzclient.launch.py's, so an include that passes them still reads.
"""

from launch.actions import DeclareLaunchArgument, LogInfo

from launch import LaunchDescription

ARGUMENTS = {'version': 'false', 'verbose': 'false', 'help': 'false', 'extra_gazebo_args': '',
             'gdb': 'false', 'valgrind': 'false', 'gui_required': 'false'}


def generate_launch_description():
    """Return gzclient.launch.py's arguments and one line saying no GUI starts."""
    return LaunchDescription([
        *[DeclareLaunchArgument(name, default_value=default)
          for name, default in ARGUMENTS.items()],
        LogInfo(msg='gzclient.launch.py: sim_node is headless, no Gazebo client is started'),
    ])
