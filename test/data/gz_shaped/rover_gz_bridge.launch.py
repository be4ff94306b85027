"""A gz launch file with a bridge config YAML, Gazebo-side package names changed to pan_tilt_sim.

The shape of Nav2's ``spawn_tb3.launch.py`` with its world include (nav2_bringup's
shape): gz_sim.launch.py with the world in ``gz_args``, ``parameter_bridge`` with a
``config_file`` in a namespace-less bridge, robot_state_publisher with the robot's
description, and ``create -topic robot_description -name -x -y -z -Y``.  Against
Gazebo, ``pan_tilt_sim`` would read ``ros_gz_sim`` and ``ros_gz_bridge``.
"""

from launch.actions import DeclareLaunchArgument, IncludeLaunchDescription
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import (
    Command,
    FindExecutable,
    LaunchConfiguration,
    PathJoinSubstitution,
)
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare

from launch import LaunchDescription

SIM_PACKAGE = 'pan_tilt_sim'  # ros_gz_sim
BRIDGE_PACKAGE = 'pan_tilt_sim'  # ros_gz_bridge


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument('description_file'),
        DeclareLaunchArgument('bridge_config'),
        DeclareLaunchArgument('x_pose', default_value='1.0'),
        DeclareLaunchArgument('y_pose', default_value='-0.5'),
        IncludeLaunchDescription(
            PythonLaunchDescriptionSource(
                PathJoinSubstitution([FindPackageShare(SIM_PACKAGE), 'launch',
                                      'gz_sim.launch.py'])),
            launch_arguments={'gz_args': ['-r -s ', 'empty.sdf'],
                              'on_exit_shutdown': 'True'}.items(),
        ),
        Node(package=BRIDGE_PACKAGE, executable='parameter_bridge', output='screen',
             parameters=[{'config_file': LaunchConfiguration('bridge_config'),
                          'use_sim_time': True}]),
        Node(package='robot_state_publisher', executable='robot_state_publisher',
             parameters=[{'use_sim_time': True, 'robot_description': Command([
                 PathJoinSubstitution([FindExecutable(name='xacro')]), ' ',
                 LaunchConfiguration('description_file')])}]),
        Node(package=SIM_PACKAGE, executable='create', output='screen',
             arguments=['-name', 'rover', '-topic', 'robot_description',
                        '-x', LaunchConfiguration('x_pose'),
                        '-y', LaunchConfiguration('y_pose'), '-z', '0.01', '-Y', '0.0']),
    ])
