"""One robot in its namespace, as Nav2's bringup_launch.py groups its nodes.

A GroupAction with PushRosNamespace(namespace) and SetRemap('/tf', 'tf') holds the
robot's nodes, none with a namespace of its own: a robot_state_publisher of the
description made for that namespace, a ``parameter_bridge`` with the shared
``config_file`` and ``expand_gz_topic_names``, and ``create -name <robot_name> -topic
robot_description`` (relative: the namespace's).  Included once per robot by
two_rovers_grouped.launch.py; ``pan_tilt_sim`` reads ``ros_gz_sim``/``ros_gz_bridge``.
"""

from launch.actions import DeclareLaunchArgument, GroupAction
from launch.substitutions import Command, FindExecutable, LaunchConfiguration
from launch_ros.actions import Node, PushRosNamespace, SetRemap

from launch import LaunchDescription

SIM_PACKAGE = 'pan_tilt_sim'  # ros_gz_sim
BRIDGE_PACKAGE = 'pan_tilt_sim'  # ros_gz_bridge


def generate_launch_description():
    namespace = LaunchConfiguration('namespace')
    return LaunchDescription([
        DeclareLaunchArgument('namespace', default_value=''),
        DeclareLaunchArgument('robot_name', default_value='rover'),
        DeclareLaunchArgument('x_pose', default_value='0.0'),
        DeclareLaunchArgument('y_pose', default_value='0.0'),
        GroupAction([
            PushRosNamespace(namespace),
            SetRemap(src='/tf', dst='tf'),
            Node(package='robot_state_publisher', executable='robot_state_publisher',
                 parameters=[{'use_sim_time': True, 'robot_description': Command([
                     FindExecutable(name='xacro'), ' ', LaunchConfiguration('description_file'),
                     ' namespace:=', namespace])}]),
            Node(package=BRIDGE_PACKAGE, executable='parameter_bridge', output='screen',
                 parameters=[{'config_file': LaunchConfiguration('bridge_config'),
                              'expand_gz_topic_names': True, 'use_sim_time': True}]),
            Node(package=SIM_PACKAGE, executable='create', output='screen',
                 arguments=['-name', LaunchConfiguration('robot_name'),
                            '-topic', 'robot_description',
                            '-x', LaunchConfiguration('x_pose'),
                            '-y', LaunchConfiguration('y_pose'), '-z', '0.01']),
        ]),
    ])
