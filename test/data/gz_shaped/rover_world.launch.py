"""A top-level launch file in nav2_bringup's shape, ros_gz_sim read as pan_tilt_sim.

The world is a ``.sdf.xacro`` that an ExecuteProcess (``xacro -o``) writes to a
temporary file while gz_sim.launch.py, included with that file in ``gz_args``,
starts the simulation, and an OnShutdown handler removes when the launch ends; the
robot comes from rover_spawn.launch.py (Nav2's spawn_tb3.launch.py shape), included
with the pose and namespace.
"""

import os
import pathlib
import tempfile

from ament_index_python.packages import get_package_share_directory
from launch.actions import (
    AppendEnvironmentVariable,
    DeclareLaunchArgument,
    ExecuteProcess,
    IncludeLaunchDescription,
    OpaqueFunction,
    RegisterEventHandler,
)
from launch.conditions import IfCondition
from launch.event_handlers import OnShutdown
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration

from launch import LaunchDescription

HERE = pathlib.Path(__file__).resolve().parent
SIM_PACKAGE = 'pan_tilt_sim'  # ros_gz_sim


def generate_launch_description():
    world_sdf = tempfile.mktemp(prefix='rover_', suffix='.sdf')
    return LaunchDescription([
        DeclareLaunchArgument('namespace', default_value=''),
        DeclareLaunchArgument('use_simulator', default_value='True'),
        DeclareLaunchArgument('headless', default_value='True'),
        DeclareLaunchArgument('world', default_value=str(HERE / 'rover_world.sdf.xacro')),
        DeclareLaunchArgument('description_file'),
        AppendEnvironmentVariable('GZ_SIM_RESOURCE_PATH', str(HERE)),
        ExecuteProcess(cmd=['xacro', '-o', world_sdf,
                            ['headless:=', LaunchConfiguration('headless')],
                            LaunchConfiguration('world')]),
        IncludeLaunchDescription(
            PythonLaunchDescriptionSource(os.path.join(
                get_package_share_directory(SIM_PACKAGE), 'launch', 'gz_sim.launch.py')),
            launch_arguments={'gz_args': ['-r -s ', world_sdf]}.items(),
            condition=IfCondition(LaunchConfiguration('use_simulator'))),
        IncludeLaunchDescription(
            PythonLaunchDescriptionSource(str(HERE / 'rover_spawn.launch.py')),
            launch_arguments={'namespace': LaunchConfiguration('namespace'),
                              'robot_name': 'rover',
                              'robot_file': LaunchConfiguration('description_file'),
                              'x_pose': '-2.00', 'y_pose': '-0.50'}.items()),
        RegisterEventHandler(event_handler=OnShutdown(on_shutdown=[
            OpaqueFunction(function=lambda _: os.remove(world_sdf))])),
    ])
