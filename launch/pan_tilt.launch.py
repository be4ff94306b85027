"""Start the simulated robot: sim_node, plus robot_state_publisher where it is installed.

The ROS 2 form of the pan/tilt example's gazebo_pan_tilt.launch + pan_tilt_gazebo_control.launch::

    ros2 launch pan_tilt_sim pan_tilt.launch.py
    ros2 launch pan_tilt_sim pan_tilt.launch.py model:=/path/robot.xacro \
        controllers:=/path/controllers.yaml real_time_factor:=1.0 world:=targets gui:=false \
        paused:=false
    ros2 launch pan_tilt_sim pan_tilt.launch.py \
        model:=$(ros2 pkg prefix ur_description)/share/ur_description/urdf/ur.urdf.xacro \
        xacro_args:='ur_type:=ur5e name:=ur5e' controllers:=.../ur_controllers.yaml \
        active_controllers:='joint_state_broadcaster joint_trajectory_controller'
    ros2 launch pan_tilt_sim pan_tilt.launch.py spawners:=true \
        active_controllers:='joint_state_broadcaster joint_trajectory_controller'

List arguments (``xacro_args``, ``controllers_args``, ``active_controllers``)
take items separated by spaces or commas, or a YAML list as ``-p`` takes it.
``controllers`` empty: the file the URDF's control plugin names.  sim_node
loads the model and controllers, runs the physics and publishes
joint_states, /clock, the camera and robot_description.  With
robot_state_publisher installed, it turns joint_states into TF (on sim
time) and sim_node's own TF is off; without it, sim_node publishes TF
itself.  sim_node stops when this launch process dies, however it dies.

``spawners:=true`` is the mode for ros2_control launch files: sim_node starts
with no controller loaded (as gz_ros2_control), and spawners -- the
including launch file's own, or the one this file starts for
``active_controllers`` (ros2_control's ``controller_manager`` package must be
installed) -- load and activate them through its controller_manager.
"""

# ruff: noqa: I001 -- this repository's launch/ folder makes ruff take `launch` for first-party
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from pan_tilt_sim.tools.launch_support import (
    CONTROLLER_MANAGER_PACKAGE,
    ROBOT_STATE_PUBLISHER,
    SPAWNER,
    bool_argument,
    has_package,
    list_argument,
    robot_setup,
    robot_state_publisher_parameters,
    sim_node_environment,
    sim_node_parameters,
    spawner_arguments,
)
from pan_tilt_sim.share import DEFAULT_DESCRIPTION, package_share

PACKAGE = 'pan_tilt_sim'


def generate_launch_description() -> LaunchDescription:
    """Declare the arguments; the nodes are made once the arguments are known."""
    share = package_share()
    return LaunchDescription([
        DeclareLaunchArgument('model', default_value=str(share / DEFAULT_DESCRIPTION),
                              description='.urdf or .xacro file of the robot'),
        DeclareLaunchArgument('xacro_args', default_value='',
                              description="xacro mappings, e.g. 'ur_type:=ur5e name:=ur5e'"),
        DeclareLaunchArgument('controllers', default_value='',
                              description="controllers YAML; empty = the one the URDF's "
                              'control plugin names (the pan/tilt model: its own)'),
        DeclareLaunchArgument('controllers_args', default_value='',
                              description="values of the YAML's $(var name), e.g. "
                              "'joint_prefix:=joint'"),
        DeclareLaunchArgument('active_controllers', default_value='',
                              description='controllers to activate; empty = all of them '
                              '(with spawners:=true: the ones a spawner here activates)'),
        DeclareLaunchArgument('spawners', default_value='false',
                              description='true: no controller starts until a ros2_control '
                              'spawner loads it, as with gz_ros2_control'),
        DeclareLaunchArgument('time_step', default_value='0.001',
                              description='physics step, s of sim time'),
        DeclareLaunchArgument('robot_namespace', default_value='',
                              description="namespace of the robot's topics; empty = derived"),
        DeclareLaunchArgument('real_time_factor', default_value='1.0',
                              description='sim seconds per wall second; 0 = as fast as possible'),
        DeclareLaunchArgument('world', default_value='targets',
                              description='scenery: targets, ground or empty, or a YAML '
                              'world file of objects to spawn'),
        DeclareLaunchArgument('paused', default_value='false',
                              description='start paused (simulation_interfaces: STOPPED)'),
        DeclareLaunchArgument('gui', default_value='false',
                              description='open a PyBullet window (needs a display)'),
        DeclareLaunchArgument('fixed_base', default_value='auto',
                              description='weld the base to the world: auto (unless a drive '
                              'controller will be active), true or false'),
        DeclareLaunchArgument('initial_pose', default_value='',
                              description="the base's start, 'x y z yaw' (m, m, m, rad)"),
        OpaqueFunction(function=launch_nodes),
    ])


def launch_nodes(context, *args, **kwargs) -> list:
    """Return sim_node, robot_state_publisher if installed, and a spawner if asked for."""
    def argument(name: str) -> str:
        return LaunchConfiguration(name).perform(context)

    model, controllers = argument('model'), argument('controllers')
    xacro_args = list_argument(argument('xacro_args'))
    controllers_args = list_argument(argument('controllers_args'))
    robot_namespace = argument('robot_namespace')
    # Read here first, as sim_node will: a bad file fails the launch before any node starts.
    setup = robot_setup(model, controllers, xacro_args, robot_namespace, controllers_args)
    with_state_publisher = has_package(ROBOT_STATE_PUBLISHER)
    spawners = bool_argument(argument('spawners'))
    active = list_argument(argument('active_controllers'))
    if spawners and active and not has_package(CONTROLLER_MANAGER_PACKAGE):
        raise RuntimeError(
            f"spawners:=true with active_controllers needs ros2_control's "
            f"'{CONTROLLER_MANAGER_PACKAGE}' package (its spawner); it is not installed")
    sim_parameters = sim_node_parameters(
        model, controllers,
        real_time_factor=float(argument('real_time_factor')),
        world=argument('world'), gui=bool_argument(argument('gui')),
        xacro_args=xacro_args, controllers_args=controllers_args,
        active_controllers=active,
        time_step=float(argument('time_step')), robot_namespace=robot_namespace,
        publish_tf=not with_state_publisher, spawners=spawners,
        paused=bool_argument(argument('paused')), fixed_base=argument('fixed_base'),
        initial_pose=list_argument(argument('initial_pose')))
    nodes = [Node(package=PACKAGE, executable='sim_node', name='sim_node', output='screen',
                  parameters=[sim_parameters], additional_env=sim_node_environment())]
    if with_state_publisher:
        nodes.append(Node(package=ROBOT_STATE_PUBLISHER, executable=ROBOT_STATE_PUBLISHER,
                          name=ROBOT_STATE_PUBLISHER, output='screen',
                          parameters=[robot_state_publisher_parameters(setup)],
                          remappings=[('joint_states', setup.topic('joint_states'))]))
    if spawners and active:
        nodes.append(Node(package=CONTROLLER_MANAGER_PACKAGE, executable=SPAWNER,
                          arguments=spawner_arguments(setup, active), output='screen'))
    return nodes
