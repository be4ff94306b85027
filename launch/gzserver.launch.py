# Copyright 2026 pan_tilt_sim maintainers. Licensed under the Apache License, Version 2.0.
"""Stand-in for gazebo_ros's gzserver.launch.py (Gazebo classic): sim_node with the world.

Launch files that include gzserver.launch.py and gzclient.launch.py apart (as
turtlebot3_gazebo's do) get what gazebo.launch.py gives: the same arguments, read
the same way (docs/launch-files.md); ``spawn_entity.py`` then brings the robot.
"""

from launch.actions import DeclareLaunchArgument, OpaqueFunction, Shutdown
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from launch import LaunchDescription

# gazebo.launch.py's own arguments (and gzclient's), not gzserver.launch.py's.
NOT_GZSERVER = ('gui', 'server', 'gui_required')


def launch_gzserver(context, *args, **kwargs):
    """sim_node, as gzserver would be started with these arguments."""
    import launch.logging

    from pan_tilt_sim.tools.stand_ins import gazebo_classic

    logger = launch.logging.get_logger('gzserver.launch.py')
    arguments = {name: LaunchConfiguration(name, default=default).perform(context)
                 for name, default in gazebo_classic.ARGUMENTS.items()
                 if name not in NOT_GZSERVER}
    server = gazebo_classic.server(arguments)
    for line in server.warnings:
        logger.warning(line)
    return [Node(package='pan_tilt_sim', executable='sim_node', name=gazebo_classic.NODE_NAME,
                 output='screen', parameters=[server.parameters],
                 ros_arguments=server.ros_arguments,
                 on_exit=Shutdown() if server.shutdown_on_exit else None)]


def generate_launch_description():
    """Return the arguments and the OpaqueFunction that starts sim_node."""
    from pan_tilt_sim.tools.stand_ins.gazebo_classic import ARGUMENTS

    return LaunchDescription([
        *[DeclareLaunchArgument(name, default_value=default)
          for name, default in ARGUMENTS.items() if name not in NOT_GZSERVER],
        OpaqueFunction(function=launch_gzserver),
    ])
