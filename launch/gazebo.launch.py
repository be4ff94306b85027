# Copyright 2026 pan_tilt_sim maintainers. Licensed under the Apache License, Version 2.0.
"""Stand-in for gazebo_ros's gazebo.launch.py (Gazebo classic): sim_node with the world.

The same launch arguments as gazebo_ros's (world, pause, verbose, extra_gazebo_args,
gui, server, ...); then ``spawn_entity.py`` (pan_tilt_sim's) brings the robot.
docs/launch-files.md says which arguments are honoured.
"""

from launch.actions import DeclareLaunchArgument, OpaqueFunction, Shutdown
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from launch import LaunchDescription


def launch_gazebo(context, *args, **kwargs):
    """sim_node, as gzserver would be started with these arguments."""
    import launch.logging

    from pan_tilt_sim.tools.stand_ins import gazebo_classic

    logger = launch.logging.get_logger('gazebo.launch.py')
    arguments = {name: LaunchConfiguration(name).perform(context)
                 for name in gazebo_classic.ARGUMENTS}
    server = gazebo_classic.server(arguments)
    for line in server.warnings:
        logger.warning(line)
    if not server.run:
        return []
    return [Node(package='pan_tilt_sim', executable='sim_node', name=gazebo_classic.NODE_NAME,
                 output='screen', parameters=[server.parameters],
                 ros_arguments=server.ros_arguments,
                 on_exit=Shutdown() if server.shutdown_on_exit else None)]


def generate_launch_description():
    """Return the arguments and the OpaqueFunction that starts sim_node."""
    from pan_tilt_sim.tools.stand_ins.gazebo_classic import ARGUMENTS

    return LaunchDescription([
        *[DeclareLaunchArgument(name, default_value=default)
          for name, default in ARGUMENTS.items()],
        OpaqueFunction(function=launch_gazebo),
    ])
