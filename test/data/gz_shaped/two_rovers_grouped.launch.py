"""Two robots in one world, Nav2's multi-robot top level: one GroupAction per robot.

The shape of nav2_bringup's ``unique_multi_tb3_simulation_launch.py``: the world
once (gz_sim.launch.py), then per robot a scoped GroupAction that includes the
robot's launch file (rover_in_namespace.launch.py, ``tb3_simulation_launch.py``'s
place) with its ``namespace``, ``robot_name`` and pose as launch arguments, and a
LogInfo.  Each include's arguments stay in its group: both robots include the same
file.  Against Gazebo, ``pan_tilt_sim`` would read ``ros_gz_sim``.
"""

import pathlib

from launch.actions import (
    DeclareLaunchArgument,
    GroupAction,
    IncludeLaunchDescription,
    LogInfo,
)
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import PathJoinSubstitution, TextSubstitution
from launch_ros.substitutions import FindPackageShare

from launch import LaunchDescription

HERE = pathlib.Path(__file__).resolve().parent
SIM_PACKAGE = 'pan_tilt_sim'  # ros_gz_sim
ROBOTS = [
    {'name': 'robot1', 'x_pose': 0.0, 'y_pose': 0.0},
    {'name': 'robot2', 'x_pose': 0.0, 'y_pose': 1.0},
]


def generate_launch_description():
    actions = [
        DeclareLaunchArgument('description_file'),
        DeclareLaunchArgument('bridge_config'),
        IncludeLaunchDescription(
            PythonLaunchDescriptionSource(
                PathJoinSubstitution([FindPackageShare(SIM_PACKAGE), 'launch',
                                      'gz_sim.launch.py'])),
            launch_arguments={'gz_args': ['-r -s ', 'empty.sdf']}.items(),
        ),
    ]
    for robot in ROBOTS:
        actions.append(GroupAction([
            IncludeLaunchDescription(
                PythonLaunchDescriptionSource(str(HERE / 'rover_in_namespace.launch.py')),
                launch_arguments={
                    'namespace': robot['name'],
                    'robot_name': TextSubstitution(text=robot['name']),
                    'x_pose': TextSubstitution(text=str(robot['x_pose'])),
                    'y_pose': TextSubstitution(text=str(robot['y_pose'])),
                }.items()),
            LogInfo(msg=['Launching ', robot['name']]),
        ]))
    return LaunchDescription(actions)
