r"""A ros2_control launch file, ros2_control_demos' shape, simulated: sim_node is the control node.

Written as ros2_control_demos writes its bringup files (examples 1, 2 and 15):
the control node with the controllers YAML as its parameters,
robot_state_publisher with the xacro output, a spawner for the broadcaster
and, once it has finished, one for the arm with ``--param-file`` and
``--controller-ros-args``.  Against real hardware the control node would be
``Node(package='controller_manager', executable='ros2_control_node', ...)``;
here its package is pan_tilt_sim -- the one word that changes::

    ros2 launch examples/launch/arm_ros2_control.launch.py
    ros2 topic pub --once /arm/joint_trajectory trajectory_msgs/msg/JointTrajectory \
      "{joint_names: [shoulder_joint, extend_joint, wrist_joint],
        points: [{positions: [0.5, 0.1, 0.3], time_from_start: {sec: 2}}]}"

It needs a ROS 2 install (launch, robot_state_publisher, ros2_control's
spawner); see docs/launch-files.md.
"""

# ruff: noqa: I001 -- this repository's launch/ folder makes ruff take `launch` for first-party
from launch import LaunchDescription
from launch.actions import RegisterEventHandler
from launch.event_handlers import OnProcessExit
from launch.substitutions import Command, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare


def generate_launch_description():
    """Return the control node, robot_state_publisher and the spawners."""
    share = FindPackageShare('pan_tilt_sim')
    controllers = PathJoinSubstitution([share, 'config', 'three_joint_arm_controllers.yaml'])
    robot_description = Command(['xacro ', PathJoinSubstitution([share, 'urdf',
                                                                 'three_joint_arm.xacro'])])
    control_node = Node(
        package='pan_tilt_sim', executable='ros2_control_node',
        parameters=[controllers],
        output='both',
    )
    robot_state_publisher = Node(
        package='robot_state_publisher', executable='robot_state_publisher', output='both',
        parameters=[{'robot_description': robot_description}],
    )
    joint_state_broadcaster = Node(
        package='controller_manager', executable='spawner',
        arguments=['joint_state_broadcaster'],
    )
    arm_controller = Node(
        package='controller_manager', executable='spawner',
        arguments=['arm_controller', '--param-file', controllers,
                   '--controller-ros-args', '-r ~/joint_trajectory:=/arm/joint_trajectory'],
    )
    return LaunchDescription([
        control_node,
        robot_state_publisher,
        joint_state_broadcaster,
        RegisterEventHandler(OnProcessExit(target_action=joint_state_broadcaster,
                                           on_exit=[arm_controller])),
    ])
