"""Start the simulated pan/tilt: sim_node plus robot_state_publisher (for RViz and TF).

The ROS 2 form of the seed's gazebo_pan_tilt.launch + pan_tilt_gazebo_control.launch::

    ros2 launch pan_tilt_sim pan_tilt.launch.py
    ros2 launch pan_tilt_sim pan_tilt.launch.py model:=/path/robot.xacro \
        controllers:=/path/controllers.yaml real_time_factor:=1.0 world:=targets gui:=false

sim_node loads the model and controllers, runs the physics and publishes
joint_states, /clock, the camera and robot_description; robot_state_publisher
turns joint_states into TF (use_sim_time), so sim_node's own TF is off.
"""

# ruff: noqa: I001 -- this repository's launch/ folder makes ruff take `launch` for first-party
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from pan_tilt_sim.tools.launch_support import (
    robot_setup,
    robot_state_publisher_parameters,
    sim_node_parameters,
)
from pan_tilt_sim.share import DEFAULT_CONTROLLERS, DEFAULT_DESCRIPTION, package_share

PACKAGE = 'pan_tilt_sim'
TRUE_WORDS = ('true', '1', 'yes')


def generate_launch_description() -> LaunchDescription:
    """Declare the arguments; the nodes are made once the arguments are known."""
    share = package_share()
    return LaunchDescription([
        DeclareLaunchArgument('model', default_value=str(share / DEFAULT_DESCRIPTION),
                              description='.urdf or .xacro file of the robot'),
        DeclareLaunchArgument('controllers', default_value=str(share / DEFAULT_CONTROLLERS),
                              description='controllers YAML'),
        DeclareLaunchArgument('real_time_factor', default_value='1.0',
                              description='sim seconds per wall second; 0 = as fast as possible'),
        DeclareLaunchArgument('world', default_value='targets',
                              description='scenery for the camera: targets or empty'),
        DeclareLaunchArgument('gui', default_value='false',
                              description='open a PyBullet window (needs a display)'),
        OpaqueFunction(function=launch_nodes),
    ])


def launch_nodes(context, *args, **kwargs) -> list:
    """Return sim_node and robot_state_publisher for the arguments given."""
    model = LaunchConfiguration('model').perform(context)
    controllers = LaunchConfiguration('controllers').perform(context)
    setup = robot_setup(model, controllers)
    sim_parameters = sim_node_parameters(
        model, controllers,
        real_time_factor=float(LaunchConfiguration('real_time_factor').perform(context)),
        world=LaunchConfiguration('world').perform(context),
        gui=LaunchConfiguration('gui').perform(context).lower() in TRUE_WORDS)
    return [
        Node(package=PACKAGE, executable='sim_node', name='sim_node', output='screen',
             parameters=[sim_parameters]),
        Node(package='robot_state_publisher', executable='robot_state_publisher',
             name='robot_state_publisher', output='screen',
             parameters=[robot_state_publisher_parameters(setup)],
             remappings=[('joint_states', setup.topic('joint_states'))]),
    ]
