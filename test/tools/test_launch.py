"""launch/pan_tilt.launch.py: sim_node plus robot_state_publisher, for ROS users."""
# ruff: noqa: I001 -- this repository's launch/ folder makes ruff take `launch` for first-party

import ast
import importlib.util

import pytest

from pan_tilt_sim.tools.launch_support import (
    robot_setup,
    robot_state_publisher_parameters,
    sim_node_parameters,
)
from pan_tilt_sim.share import DEFAULT_CONTROLLERS, DEFAULT_DESCRIPTION, package_share

LAUNCH_FILE = 'pan_tilt.launch.py'
NO_LAUNCH = 'the ROS 2 launch and launch_ros packages are not installed'


@pytest.fixture
def launch_path(repo_root):
    """Return the launch file in the source tree."""
    return repo_root / 'launch' / LAUNCH_FILE


def test_the_launch_file_defines_generate_launch_description(launch_path):
    tree = ast.parse(launch_path.read_text(), str(launch_path))
    functions = {node.name for node in tree.body if isinstance(node, ast.FunctionDef)}
    assert 'generate_launch_description' in functions


def test_robot_state_publisher_gets_the_urdf_and_the_robots_joint_states():
    share = package_share()
    setup = robot_setup(str(share / DEFAULT_DESCRIPTION), str(share / DEFAULT_CONTROLLERS))
    assert setup.namespace == '/ex_urdf_pan_tilt'
    assert setup.topic('joint_states') == '/ex_urdf_pan_tilt/joint_states'
    parameters = robot_state_publisher_parameters(setup)
    assert parameters['use_sim_time'] is True
    assert '<joint name="pan_joint" type="revolute">' in parameters['robot_description']


def test_sim_node_leaves_tf_to_robot_state_publisher_and_keeps_its_own_clock():
    parameters = sim_node_parameters('m.urdf', 'c.yaml', real_time_factor=1.0,
                                     world='targets', gui=False)
    assert parameters['publish_tf'] is False
    assert 'use_sim_time' not in parameters  # sim_node is the clock
    assert (parameters['robot_description_file'], parameters['controllers_file']) == (
        'm.urdf', 'c.yaml')


def require_launch() -> None:
    """Skip unless the real ``launch`` and ``launch_ros`` are importable.

    ``pytest.importorskip('launch')`` is not enough: from the source tree this
    repository's own launch/ folder imports as an empty namespace package.
    """
    try:
        from launch import LaunchDescription  # noqa: F401
        from launch_ros.actions import Node  # noqa: F401
    except ImportError:
        pytest.skip(NO_LAUNCH)


def test_generate_launch_description_starts_sim_node_and_robot_state_publisher(launch_path):
    require_launch()
    from launch import LaunchContext, LaunchDescription
    from launch.actions import DeclareLaunchArgument

    spec = importlib.util.spec_from_file_location('pan_tilt_launch', launch_path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    description = module.generate_launch_description()
    assert isinstance(description, LaunchDescription)
    arguments = [entity for entity in description.entities
                 if isinstance(entity, DeclareLaunchArgument)]
    assert {argument.name for argument in arguments} >= {'model', 'controllers',
                                                         'real_time_factor', 'world', 'gui'}
    context = LaunchContext()
    for argument in arguments:
        argument.visit(context)
    nodes = module.launch_nodes(context)
    assert [(node.node_package, node.node_executable) for node in nodes] == [
        ('pan_tilt_sim', 'sim_node'), ('robot_state_publisher', 'robot_state_publisher')]
