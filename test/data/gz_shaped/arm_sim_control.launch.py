"""A launch file in the shape of UR's gz simulation launch, Gazebo swapped for sim_node.

Universal Robots' ``ur_simulation_gz/launch/ur_sim_control.launch.py`` builds
its nodes in an OpaqueFunction from the launch configurations: xacro found
with FindExecutable, an argument with ``choices``, the initial controller's
spawner picked by IfCondition / UnlessCondition, a RegisterEventHandler with
a condition of its own, and Gazebo's arguments made by IfElseSubstitution.
This file has those parts for the three-joint arm (urdf/three_joint_arm.xacro,
whose gazebo_ros2_control plugin names its controllers file), with the gz
include dropped and the spawn step replaced by sim_node named
``controller_manager``, as docs/launch-files.md shows.  The tests run it
through test/support/launch_stand_in.py.
"""

# ruff: noqa: I001 -- this repository's launch/ folder makes ruff take `launch` for first-party
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction, RegisterEventHandler
from launch.conditions import IfCondition, UnlessCondition
from launch.event_handlers import OnProcessExit
from launch.substitutions import (
    Command,
    FindExecutable,
    IfElseSubstitution,
    LaunchConfiguration,
    PathJoinSubstitution,
)
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare

CONTROLLER_MANAGER = '/controller_manager'


def launch_setup(context, *args, **kwargs):
    """Return the nodes, made from the launch configurations in ``context``."""
    activate = LaunchConfiguration('activate_joint_controller')
    # A launch file may perform a substitution itself: a plain text from here on.
    controller = LaunchConfiguration('initial_joint_controller').perform(context)
    robot_description = Command([
        PathJoinSubstitution([FindExecutable(name='xacro')]), ' ',
        LaunchConfiguration('description_file'),
    ])
    robot_state_publisher = Node(
        package='robot_state_publisher', executable='robot_state_publisher', output='both',
        parameters=[{'use_sim_time': True}, {'robot_description': robot_description}],
    )
    joint_state_broadcaster = Node(
        package='controller_manager', executable='spawner',
        arguments=['joint_state_broadcaster', '--controller-manager', CONTROLLER_MANAGER],
    )
    gripper_after_broadcaster = RegisterEventHandler(
        event_handler=OnProcessExit(
            target_action=joint_state_broadcaster,
            on_exit=[Node(package='controller_manager', executable='spawner',
                          arguments=['gripper_controller', '-c', CONTROLLER_MANAGER])],
        ),
        condition=IfCondition(LaunchConfiguration('with_gripper')),
    )
    controller_started = Node(
        package='controller_manager', executable='spawner',
        arguments=[controller, '-c', CONTROLLER_MANAGER],
        condition=IfCondition(activate),
    )
    controller_inactive = Node(
        package='controller_manager', executable='spawner',
        arguments=[controller, '-c', CONTROLLER_MANAGER, '--inactive'],
        condition=UnlessCondition(activate),
    )
    simulation = Node(
        package='pan_tilt_sim', executable='sim_node', name='controller_manager',
        output='screen',
        parameters=[{'world': IfElseSubstitution(LaunchConfiguration('scenery'),
                                                 if_value=LaunchConfiguration('world'),
                                                 else_value='empty')}],
    )
    return [robot_state_publisher, joint_state_broadcaster, gripper_after_broadcaster,
            controller_inactive, controller_started, simulation]


def generate_launch_description():
    """Return the arguments and the OpaqueFunction that makes the nodes."""
    return LaunchDescription([
        DeclareLaunchArgument(
            'description_file',
            default_value=PathJoinSubstitution(
                [FindPackageShare('pan_tilt_sim'), 'urdf', 'three_joint_arm.xacro'])),
        DeclareLaunchArgument('initial_joint_controller', default_value='arm_controller',
                              choices=['arm_controller', 'gripper_controller']),
        DeclareLaunchArgument('activate_joint_controller', default_value='true'),
        DeclareLaunchArgument('with_gripper', default_value='true'),
        DeclareLaunchArgument('scenery', default_value='true'),
        DeclareLaunchArgument('world', default_value='targets',
                              choices=['targets', 'ground', 'empty']),
        OpaqueFunction(function=launch_setup),
    ])
