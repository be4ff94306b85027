# Copyright 2026 pan_tilt_sim maintainers. Licensed under the Apache License, Version 2.0.
"""Stand-in for ros_gz_sim's gz_server.launch.py: sim_node running the world, no robot.

The same launch arguments: ``world_sdf_file`` (found as in gz_sim.launch.py) or
``world_sdf_string`` (written to a file sim_node reads); the simulation runs, as
ros_gz_sim's gzserver runs it.  ``use_composition``, ``container_name`` and
``create_own_container`` are named in one warning: sim_node is a process of its own.
"""

from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from launch import LaunchDescription

ARGUMENTS = {'world_sdf_file': '', 'world_sdf_string': '', 'container_name': 'ros_gz_container',
             'create_own_container': 'False', 'use_composition': 'False'}


def launch_gz_server(context, *args, **kwargs):
    """sim_node, as ros_gz_sim's gzserver would be started with these arguments."""
    import shlex
    import tempfile

    import launch.logging

    from pan_tilt_sim.tools.stand_ins import gz_sim

    logger = launch.logging.get_logger('gz_server.launch.py')
    given = {name: LaunchConfiguration(name).perform(context) for name in ARGUMENTS}
    if given['use_composition'].strip().lower() == 'true':
        logger.warning(f"use_composition:={given['use_composition']} (container "
                       f"'{given['container_name']}') is not honoured: sim_node runs as a "
                       'process of its own')
    world = given['world_sdf_file']
    if not world and given['world_sdf_string']:
        with tempfile.NamedTemporaryFile('w', prefix='gz_server_world_', suffix='.sdf',
                                         delete=False) as written:
            written.write(given['world_sdf_string'])
        world = written.name
    if not world:
        logger.error("Must specify either 'world_sdf_file' or 'world_sdf_string'")
        return []
    server = gz_sim.server(f'-r {shlex.quote(world)}')
    return [Node(package='pan_tilt_sim', executable='sim_node', name=gz_sim.NODE_NAME,
                 output='screen', parameters=[server.parameters])]


def generate_launch_description():
    """Return the arguments and the OpaqueFunction that starts sim_node."""
    return LaunchDescription([
        *[DeclareLaunchArgument(name, default_value=default)
          for name, default in ARGUMENTS.items()],
        OpaqueFunction(function=launch_gz_server),
    ])
