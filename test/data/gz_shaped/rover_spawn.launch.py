"""A spawn launch file in Nav2's spawn_tb3.launch.py shape, Gazebo-side packages read pan_tilt_sim.

A bridge in the launch namespace with a config YAML and expand_gz_topic_names, and
``create -name -string <xacro output> -x -y -z -R -P -Y`` in that namespace; the
pose comes as LaunchConfigurations with defaults.  No robot_state_publisher, as there.
"""

import pathlib

from launch.actions import AppendEnvironmentVariable, DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch.substitutions.command import Command
from launch.substitutions.find_executable import FindExecutable
from launch_ros.actions import Node

from launch import LaunchDescription

HERE = pathlib.Path(__file__).resolve().parent
SIM_PACKAGE = 'pan_tilt_sim'  # ros_gz_sim
BRIDGE_PACKAGE = 'pan_tilt_sim'  # ros_gz_bridge


def generate_launch_description():
    namespace = LaunchConfiguration('namespace')
    pose = {'x': LaunchConfiguration('x_pose', default='0.00'),
            'y': LaunchConfiguration('y_pose', default='0.00'),
            'z': LaunchConfiguration('z_pose', default='0.01'),
            'R': LaunchConfiguration('roll', default='0.00'),
            'P': LaunchConfiguration('pitch', default='0.00'),
            'Y': LaunchConfiguration('yaw', default='0.00')}
    ld = LaunchDescription()
    ld.add_action(DeclareLaunchArgument('namespace', default_value=''))
    ld.add_action(DeclareLaunchArgument('robot_name', default_value='rover'))
    ld.add_action(DeclareLaunchArgument('robot_file'))
    ld.add_action(AppendEnvironmentVariable('GZ_SIM_RESOURCE_PATH', str(HERE.parent)))
    ld.add_action(Node(
        package=BRIDGE_PACKAGE, executable='parameter_bridge', namespace=namespace,
        parameters=[{'config_file': str(HERE / 'rover_bridge.yaml'),
                     'expand_gz_topic_names': True, 'use_sim_time': True}],
        output='screen'))
    ld.add_action(Node(
        package=SIM_PACKAGE, executable='create', output='screen', namespace=namespace,
        arguments=['-name', LaunchConfiguration('robot_name'),
                   '-string', Command([FindExecutable(name='xacro'), ' ', 'namespace:=',
                                       namespace, ' ', LaunchConfiguration('robot_file')]),
                   '-x', pose['x'], '-y', pose['y'], '-z', pose['z'],
                   '-R', pose['R'], '-P', pose['P'], '-Y', pose['Y']]))
    return ld
