"""launch/pan_tilt.launch.py: sim_node plus robot_state_publisher, for ROS users.

The ``launch`` package is not on PyPI, so the launch file's own code runs
here against a small stand-in of the launch API (it records what the file
asks for); :mod:`pan_tilt_sim.tools.launch_support` holds the logic.  Where
the real ``launch`` is installed, the last test runs it for real.
"""
# ruff: noqa: I001 -- this repository's launch/ folder makes ruff take `launch` for first-party

import ast
import importlib.util
import os
import sys
import types

import pytest
from mesh_fixtures import make_ament_prefix
from ros2_control_fixtures import write_arm

from pan_tilt_sim.ros.runner import PARENT_PID_VARIABLE
from pan_tilt_sim.tools.launch_support import (
    bool_argument,
    controller_manager_name,
    has_package,
    list_argument,
    robot_setup,
    robot_state_publisher_parameters,
    sim_node_environment,
    sim_node_parameters,
    spawner_arguments,
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


def test_the_real_launch_starts_sim_node_and_robot_state_publisher_if_installed(launch_path):
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
    assert {argument.name for argument in arguments} >= {
        'model', 'xacro_args', 'controllers', 'controllers_args', 'active_controllers',
        'spawners', 'time_step', 'robot_namespace', 'real_time_factor', 'world', 'gui'}
    context = LaunchContext()
    for argument in arguments:
        argument.visit(context)
    nodes = module.launch_nodes(context)
    expected = [('pan_tilt_sim', 'sim_node')]
    if has_package('robot_state_publisher'):
        expected.append(('robot_state_publisher', 'robot_state_publisher'))
    assert [(node.node_package, node.node_executable) for node in nodes] == expected


# --- launch_support: the launch file's logic, without launch ------------------------------

@pytest.mark.parametrize(('text', 'items'), [
    ("['ur_type:=ur5e', 'name:=ur5e']", ['ur_type:=ur5e', 'name:=ur5e']),
    ('[joint_state_broadcaster, joint_trajectory_controller]',
     ['joint_state_broadcaster', 'joint_trajectory_controller']),
    ('ur_type:=ur5e name:=ur5e', ['ur_type:=ur5e', 'name:=ur5e']),
    ('joint_state_broadcaster,joint_trajectory_controller',
     ['joint_state_broadcaster', 'joint_trajectory_controller']),
    ('', []),
    ('  ', []),
])
def test_list_arguments_are_yaml_lists_or_separated_words(text, items):
    assert list_argument(text) == items


@pytest.mark.parametrize(('text', 'value'), [('true', True), ('True', True), ('1', True),
                                             ('false', False), ('0', False), ('', False)])
def test_bool_arguments(text, value):
    assert bool_argument(text) is value


def test_has_package_asks_the_ament_index(tmp_path, monkeypatch):
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(tmp_path / 'nothing'))
    assert not has_package('robot_state_publisher')
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(make_ament_prefix(tmp_path,
                                                                  'robot_state_publisher')))
    assert has_package('robot_state_publisher')


def test_sim_node_gets_the_lists_given_and_publishes_tf_without_a_state_publisher():
    parameters = sim_node_parameters(
        'ur.urdf.xacro', '', real_time_factor=1.0, world='empty', gui=False,
        xacro_args=['ur_type:=ur5e', 'name:=ur5e'], controllers_args=[],
        active_controllers=['joint_state_broadcaster', 'joint_trajectory_controller'],
        time_step=0.002, robot_namespace='ur', publish_tf=True)
    assert parameters == {
        'robot_description_file': 'ur.urdf.xacro', 'real_time_factor': 1.0, 'world': 'empty',
        'gui': False, 'publish_tf': True, 'xacro_args': ['ur_type:=ur5e', 'name:=ur5e'],
        'active_controllers': ['joint_state_broadcaster', 'joint_trajectory_controller'],
        'time_step': 0.002, 'robot_namespace': 'ur'}


def test_sim_node_is_told_the_launch_process_is_its_parent():
    assert sim_node_environment() == {PARENT_PID_VARIABLE: str(os.getpid())}


def test_robot_setup_reads_the_controllers_the_urdf_names(tmp_path):
    xacro = write_arm(tmp_path)
    setup = robot_setup(str(xacro), '', ['prefix:=left_'], 'arm', ['prefix:=left_'])
    assert setup.namespace == '/arm'
    assert '<joint name="left_joint1" type="revolute">' in setup.urdf_xml


# --- the launch file, run against a stand-in of the launch API ----------------------------

class _Recorded:
    """Stands in for a launch action: keeps its arguments."""

    def __init__(self, *args, **kwargs):
        self.args, self.kwargs = args, kwargs


class _LaunchConfiguration:
    def __init__(self, name):
        self.name = name

    def perform(self, context):
        return context[self.name]


@pytest.fixture
def stand_in_launch(monkeypatch, launch_path):
    """Load the launch file with fake launch / launch_ros modules; return the module."""
    modules = {name: types.ModuleType(name) for name in (
        'launch', 'launch.actions', 'launch.substitutions', 'launch_ros', 'launch_ros.actions')}
    modules['launch'].LaunchDescription = list
    modules['launch.actions'].DeclareLaunchArgument = _Recorded
    modules['launch.actions'].OpaqueFunction = _Recorded
    modules['launch.substitutions'].LaunchConfiguration = _LaunchConfiguration
    modules['launch_ros.actions'].Node = _Recorded
    for name, module in modules.items():
        monkeypatch.setitem(sys.modules, name, module)
    spec = importlib.util.spec_from_file_location('pan_tilt_launch_stand_in', launch_path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _defaults(description):
    return {action.args[0]: action.kwargs['default_value'] for action in description
            if 'default_value' in action.kwargs}


def test_the_launch_file_declares_every_argument(stand_in_launch):
    assert set(_defaults(stand_in_launch.generate_launch_description())) == {
        'model', 'xacro_args', 'controllers', 'controllers_args', 'active_controllers',
        'spawners', 'time_step', 'robot_namespace', 'real_time_factor', 'world', 'gui',
        'paused', 'fixed_base', 'initial_pose'}


def _launch(module, monkeypatch, prefix, **arguments):
    monkeypatch.setenv('AMENT_PREFIX_PATH', os.pathsep.join(
        [str(prefix), *os.environ['AMENT_PREFIX_PATH'].split(os.pathsep)]))
    context = {**_defaults(module.generate_launch_description()), **arguments}
    return module.launch_nodes(context)


def test_a_ur_style_launch_without_robot_state_publisher_starts_sim_node_alone(
        stand_in_launch, monkeypatch, tmp_path):
    xacro = write_arm(tmp_path)
    (sim_node,) = _launch(
        stand_in_launch, monkeypatch, tmp_path / 'none', model=str(xacro),
        xacro_args='prefix:=left_', controllers_args="['prefix:=left_']",
        active_controllers='joint_state_broadcaster joint_trajectory_controller',
        time_step='0.002', robot_namespace='arm')
    assert (sim_node.kwargs['package'], sim_node.kwargs['executable']) == (
        'pan_tilt_sim', 'sim_node')
    (parameters,) = sim_node.kwargs['parameters']
    assert parameters['publish_tf'] is True  # nobody else turns joint_states into TF
    assert parameters['xacro_args'] == parameters['controllers_args'] == ['prefix:=left_']
    assert parameters['active_controllers'] == ['joint_state_broadcaster',
                                                'joint_trajectory_controller']
    assert (parameters['time_step'], parameters['robot_namespace']) == (0.002, 'arm')
    assert 'controllers_file' not in parameters  # sim_node takes the one the URDF names
    assert sim_node.kwargs['additional_env'] == {PARENT_PID_VARIABLE: str(os.getpid())}


def test_with_robot_state_publisher_installed_it_publishes_tf_instead(
        stand_in_launch, monkeypatch, tmp_path):
    prefix = make_ament_prefix(tmp_path, 'robot_state_publisher')
    sim_node, state_publisher = _launch(stand_in_launch, monkeypatch, prefix)
    assert sim_node.kwargs['parameters'][0]['publish_tf'] is False
    assert state_publisher.kwargs['executable'] == 'robot_state_publisher'
    assert state_publisher.kwargs['remappings'] == [
        ('joint_states', '/ex_urdf_pan_tilt/joint_states')]
    assert state_publisher.kwargs['parameters'][0]['use_sim_time'] is True


# --- spawners:=true, the mode for ros2_control launch files -------------------------------

def test_with_spawners_sim_node_starts_no_controller_and_a_spawner_activates_the_list(
        stand_in_launch, monkeypatch, tmp_path):
    xacro = write_arm(tmp_path)
    prefix = make_ament_prefix(tmp_path, 'controller_manager')
    sim_node, spawner = _launch(
        stand_in_launch, monkeypatch, prefix, model=str(xacro), xacro_args='prefix:=left_',
        controllers_args='prefix:=left_', robot_namespace='arm', spawners='true',
        active_controllers='joint_state_broadcaster joint_trajectory_controller')
    (parameters,) = sim_node.kwargs['parameters']
    assert parameters['autostart_controllers'] is False
    assert 'active_controllers' not in parameters  # the spawner's business now
    assert (spawner.kwargs['package'], spawner.kwargs['executable']) == (
        'controller_manager', 'spawner')
    assert spawner.kwargs['arguments'] == [
        'joint_state_broadcaster', 'joint_trajectory_controller',
        '--controller-manager', '/arm/controller_manager']


def test_with_spawners_and_no_list_the_including_launch_file_spawns(
        stand_in_launch, monkeypatch, tmp_path):
    (sim_node,) = _launch(stand_in_launch, monkeypatch, tmp_path / 'none', spawners='true')
    assert sim_node.kwargs['parameters'][0]['autostart_controllers'] is False


def test_spawners_with_a_list_but_no_controller_manager_package_fails_the_launch(
        stand_in_launch, monkeypatch, tmp_path):
    with pytest.raises(RuntimeError, match="needs ros2_control's 'controller_manager' package"):
        _launch(stand_in_launch, monkeypatch, tmp_path / 'none', spawners='true',
                active_controllers='joint_state_controller')


def test_the_spawner_names_the_controller_manager_in_the_robots_namespace():
    share = package_share()
    setup = robot_setup(str(share / DEFAULT_DESCRIPTION), str(share / DEFAULT_CONTROLLERS))
    assert controller_manager_name(setup) == '/ex_urdf_pan_tilt/controller_manager'
    assert spawner_arguments(setup, ['joint_state_controller']) == [
        'joint_state_controller', '--controller-manager', '/ex_urdf_pan_tilt/controller_manager']
    parameters = sim_node_parameters('m.urdf', '', real_time_factor=1.0, world='empty',
                                     gui=False, active_controllers=['a'], spawners=True)
    assert parameters['autostart_controllers'] is False and 'active_controllers' not in parameters


def test_the_spawner_names_the_manager_the_control_plugin_names(tmp_path):
    # gz_ros2_control's <controller_manager_name>arm_manager: sim_node's manager is
    # <ns>/arm_manager, and that node's section of the file lists the controllers.
    from drop_in_fixtures import JSB, MANAGER_YAML

    xacro = write_arm(tmp_path, MANAGER_YAML.replace('controller_manager:', 'arm_manager:'))
    xacro.write_text(xacro.read_text().replace(
        '<parameters>', '<controller_manager_name>arm_manager</controller_manager_name>'
        '<parameters>', 1))
    setup = robot_setup(str(xacro), robot_namespace='arm')
    assert controller_manager_name(setup) == '/arm/arm_manager'
    assert spawner_arguments(setup, [JSB]) == [JSB, '--controller-manager', '/arm/arm_manager']


def test_paused_is_passed_only_when_asked_for():
    assert 'paused' not in sim_node_parameters('m.urdf', '', real_time_factor=1.0,
                                               world='targets', gui=False)
    assert sim_node_parameters('m.urdf', '', real_time_factor=1.0, world='targets', gui=False,
                               paused=True)['paused'] is True


def test_fixed_base_and_initial_pose_are_passed_only_when_given():
    plain = sim_node_parameters('m.urdf', '', real_time_factor=1.0, world='ground', gui=False)
    assert 'fixed_base' not in plain and 'initial_pose' not in plain
    given = sim_node_parameters('m.urdf', '', real_time_factor=1.0, world='ground', gui=False,
                                fixed_base='false', initial_pose=['1', '2', '0', '1.57'])
    assert given['fixed_base'] == 'false'
    assert given['initial_pose'] == [1.0, 2.0, 0.0, 1.57]
    with pytest.raises(ValueError, match="launch argument 'initial_pose': '1 north' is not"):
        sim_node_parameters('m.urdf', '', real_time_factor=1.0, world='ground', gui=False,
                            initial_pose=['1', 'north'])


def test_a_topic_based_robot_needs_no_controllers_file(tmp_path):
    from topic_based_fixtures import topic_based_urdf_file

    urdf = topic_based_urdf_file(tmp_path, {'a': ['position']})
    setup = robot_setup(str(urdf), '', robot_namespace='star')
    assert setup.topic('joint_states') == '/star/joint_states'


def test_the_paused_launch_argument_starts_sim_node_paused(stand_in_launch, monkeypatch,
                                                            tmp_path):
    (sim_node,) = _launch(stand_in_launch, monkeypatch, tmp_path / 'none', paused='true')
    assert sim_node.kwargs['parameters'][0]['paused'] is True
