"""A Gazebo classic launch file with its gazebo_ros package name changed to pan_tilt_sim.

The shape of gazebo_ros2_control's demo launch files (humble): gazebo_ros's
gazebo.launch.py included (its world and extra_gazebo_args), robot_state_publisher
with the xacro output, ``spawn_entity.py -topic robot_description -entity``, and the
spawners chained on spawn_entity.py's exit.  The arm's URDF names its controllers
file in its gazebo_ros2_control plugin.  Against Gazebo, ``pan_tilt_sim`` would read
``gazebo_ros``.
"""

from launch.actions import IncludeLaunchDescription, RegisterEventHandler
from launch.event_handlers import OnProcessExit
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import Command, FindExecutable, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare

from launch import LaunchDescription

GAZEBO_PACKAGE = 'pan_tilt_sim'  # gazebo_ros


def generate_launch_description():
    gazebo = IncludeLaunchDescription(
        PythonLaunchDescriptionSource(
            [FindPackageShare(GAZEBO_PACKAGE), '/launch', '/gazebo.launch.py']),
        launch_arguments=[('extra_gazebo_args', '--verbose')],
    )
    robot_state_publisher = Node(
        package='robot_state_publisher', executable='robot_state_publisher', output='screen',
        parameters=[{'robot_description': Command([
            PathJoinSubstitution([FindExecutable(name='xacro')]), ' ',
            PathJoinSubstitution([FindPackageShare('pan_tilt_sim'), 'urdf',
                                  'three_joint_arm.xacro'])])}],
    )
    spawn_entity = Node(
        package=GAZEBO_PACKAGE, executable='spawn_entity.py', output='screen',
        arguments=['-topic', 'robot_description', '-entity', 'arm'],
    )
    joint_state_broadcaster = Node(
        package='controller_manager', executable='spawner',
        arguments=['joint_state_broadcaster'],
    )
    arm_controller = Node(
        package='controller_manager', executable='spawner', arguments=['arm_controller'],
    )
    return LaunchDescription([
        RegisterEventHandler(OnProcessExit(target_action=spawn_entity,
                                           on_exit=[joint_state_broadcaster])),
        RegisterEventHandler(OnProcessExit(target_action=joint_state_broadcaster,
                                           on_exit=[arm_controller])),
        gazebo,
        robot_state_publisher,
        spawn_entity,
    ])
