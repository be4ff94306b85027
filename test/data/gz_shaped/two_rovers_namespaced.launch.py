"""Two robots in one world, each in its namespace: Nav2's multi-robot gz shape, names changed.

The world once (gz_sim.launch.py with the world in ``gz_args``); then per robot, as Nav2's
``spawn_tb3.launch.py`` does in the robot's namespace: a ``parameter_bridge`` with one
shared ``config_file`` and ``expand_gz_topic_names`` (its gz names under the namespace),
a robot_state_publisher of the description made for that namespace, and ``create -name
<robot> -topic robot_description -x -y -z -Y``.  Against Gazebo, ``pan_tilt_sim`` would
read ``ros_gz_sim`` and ``ros_gz_bridge``.
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
ROBOTS = [
    {'name': 'robot1', 'x_pose': '0.0', 'y_pose': '0.0'},
    {'name': 'robot2', 'x_pose': '0.0', 'y_pose': '1.0'},
]


def generate_launch_description():
    actions = [
        DeclareLaunchArgument('description_file'),
        DeclareLaunchArgument('bridge_config'),
        IncludeLaunchDescription(
            PythonLaunchDescriptionSource(
                PathJoinSubstitution([FindPackageShare(SIM_PACKAGE), 'launch',
                                      'gz_sim.launch.py'])),
            launch_arguments={'gz_args': ['-r -s ', 'empty.sdf'],
                              'on_exit_shutdown': 'True'}.items(),
        ),
    ]
    for robot in ROBOTS:
        namespace = robot['name']
        actions += [
            Node(package=BRIDGE_PACKAGE, executable='parameter_bridge', namespace=namespace,
                 output='screen',
                 parameters=[{'config_file': LaunchConfiguration('bridge_config'),
                              'expand_gz_topic_names': True, 'use_sim_time': True}]),
            Node(package='robot_state_publisher', executable='robot_state_publisher',
                 namespace=namespace,
                 parameters=[{'use_sim_time': True, 'robot_description': Command([
                     PathJoinSubstitution([FindExecutable(name='xacro')]), ' ',
                     LaunchConfiguration('description_file'), ' namespace:=', namespace])}]),
            Node(package=SIM_PACKAGE, executable='create', namespace=namespace, output='screen',
                 arguments=['-name', namespace, '-topic', 'robot_description',
                            '-x', robot['x_pose'], '-y', robot['y_pose'], '-z', '0.01',
                            '-Y', '0.0']),
        ]
    return LaunchDescription(actions)
