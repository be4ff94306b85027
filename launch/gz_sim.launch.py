# Copyright 2026 pan_tilt_sim maintainers. Licensed under the Apache License, Version 2.0.
"""Stand-in for ros_gz_sim's gz_sim.launch.py: sim_node with the world gz_args names.

Include it as ros_gz_sim's (the same launch arguments: gz_args, gz_version,
ign_args, ign_version, debugger, on_exit_shutdown); then ``create`` (pan_tilt_sim's)
brings the robot.  docs/launch-files.md says what of gz_args is honoured.
"""

from launch.actions import DeclareLaunchArgument, OpaqueFunction, Shutdown
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from launch import LaunchDescription


def launch_gz(context, *args, **kwargs):
    """sim_node, as gz sim would be started with these arguments."""
    import launch.logging

    from pan_tilt_sim.tools.stand_ins import gz_sim

    logger = launch.logging.get_logger('gz_sim.launch.py')
    gz_args = LaunchConfiguration('gz_args').perform(context)
    ign_args = LaunchConfiguration('ign_args').perform(context)
    if not gz_args and ign_args:
        logger.warning('ign_args is deprecated, migrate to gz_args!')
        gz_args = ign_args
    for name in ('gz_version', 'ign_version'):
        if LaunchConfiguration(name).perform(context):
            logger.info(f'{name} is not needed by sim_node: ignored')
    if LaunchConfiguration('debugger').perform(context) != 'false':
        logger.warning('debugger is not honoured by sim_node (run it under gdb or pdb yourself)')
    server = gz_sim.server(gz_args)
    for line in server.warnings:
        logger.warning(line)
    if not server.run:
        return []
    on_exit = Shutdown() if (
        LaunchConfiguration('on_exit_shutdown').perform(context) != 'false') else None
    return [Node(package='pan_tilt_sim', executable='sim_node', name=gz_sim.NODE_NAME,
                 output='screen', parameters=[server.parameters],
                 ros_arguments=server.ros_arguments, on_exit=on_exit)]


def generate_launch_description():
    """Return the arguments and the OpaqueFunction that starts sim_node."""
    return LaunchDescription([
        DeclareLaunchArgument('gz_args', default_value='',
                              description='Arguments to be passed to Gazebo Sim'),
        DeclareLaunchArgument('gz_version', default_value='',
                              description="Gazebo Sim's major version (not needed)"),
        DeclareLaunchArgument('ign_args', default_value='',
                              description='Deprecated: Arguments to be passed to Gazebo Sim'),
        DeclareLaunchArgument('ign_version', default_value='',
                              description="Deprecated: Gazebo Sim's major version"),
        DeclareLaunchArgument('debugger', default_value='false',
                              description='Run in Debugger (not honoured)'),
        DeclareLaunchArgument('on_exit_shutdown', default_value='false',
                              description='Shutdown on sim_node exit'),
        OpaqueFunction(function=launch_gz),
    ])
