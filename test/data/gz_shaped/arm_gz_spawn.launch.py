"""A gz (ros_gz_sim) launch file with its Gazebo-side package names changed to pan_tilt_sim.

The shape of ros2_control_demos' example 9 (``rrbot_gazebo.launch.py``, jazzy) for the
three-joint arm: gz_sim.launch.py included with the world in ``gz_args``, the ``/clock``
bridge, robot_state_publisher with the xacro output, ``create -topic robot_description``,
and the spawners chained on create's exit (``OnProcessExit(target_action=spawn)``).
Against Gazebo, ``pan_tilt_sim`` would read ``ros_gz_sim`` and ``ros_gz_bridge``.
"""

from launch.actions import DeclareLaunchArgument, IncludeLaunchDescription, RegisterEventHandler
from launch.event_handlers import OnProcessExit
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
    robot_description = Command([
        PathJoinSubstitution([FindExecutable(name='xacro')]), ' ',
        PathJoinSubstitution([FindPackageShare('pan_tilt_sim'), 'urdf', 'three_joint_arm.xacro']),
    ])
    gazebo = IncludeLaunchDescription(
        PythonLaunchDescriptionSource(
            [PathJoinSubstitution([FindPackageShare(SIM_PACKAGE), 'launch', 'gz_sim.launch.py'])]),
        launch_arguments=[('gz_args', [' -r -v 3 ', LaunchConfiguration('world')])],
    )
    bridge = Node(
        package=BRIDGE_PACKAGE, executable='parameter_bridge',
        arguments=['/clock@rosgraph_msgs/msg/Clock[gz.msgs.Clock'], output='screen',
    )
    robot_state_publisher = Node(
        package='robot_state_publisher', executable='robot_state_publisher', output='both',
        parameters=[{'use_sim_time': True}, {'robot_description': robot_description}],
    )
    spawn = Node(
        package=SIM_PACKAGE, executable='create', output='screen',
        arguments=['-topic', '/robot_description', '-name', 'three_joint_arm',
                   '-allow_renaming', 'true'],
    )
    joint_state_broadcaster = Node(
        package='controller_manager', executable='spawner',
        arguments=['joint_state_broadcaster'],
    )
    arm_controller = Node(
        package='controller_manager', executable='spawner',
        arguments=['arm_controller', '--param-file', LaunchConfiguration('controllers')],
    )
    return LaunchDescription([
        DeclareLaunchArgument('world', default_value='empty.sdf'),
        DeclareLaunchArgument('controllers', default_value=PathJoinSubstitution(
            [FindPackageShare('pan_tilt_sim'), 'config', 'three_joint_arm_controllers.yaml'])),
        gazebo,
        bridge,
        robot_state_publisher,
        spawn,
        RegisterEventHandler(OnProcessExit(target_action=spawn,
                                           on_exit=[joint_state_broadcaster])),
        RegisterEventHandler(OnProcessExit(target_action=joint_state_broadcaster,
                                           on_exit=[arm_controller])),
    ])
