"""sim_node's start-up steps, each run alone; and a failed start-up starts nothing."""

import threading

import pytest
import rclpy
from rclpy.node import Node
from rclpy.parameter import Parameter
from topic_based_fixtures import topic_based_urdf_file

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.model.ros_arguments import parse_ros_arguments
from pan_tilt_sim.ros import drop_in, optional_interfaces, parameters, startup, topic_hardware
from pan_tilt_sim.ros.sim_node import SimNode
from pan_tilt_sim.share import package_share

PAN_TILT_URDF = package_share() / 'urdf' / 'pan_tilt.xacro'
PAN_TILT_YAML = package_share() / 'config' / 'pan_tilt_control.yaml'
FORWARD_TYPE = 'forward_command_controller/ForwardCommandController'
NO_ARGUMENTS = parse_ros_arguments([], 'the command line')


def settings_of(node: Node, *, controller_manager: bool = False) -> parameters.SimParameters:
    return parameters.declare_parameters(node, controller_manager=controller_manager)


def choose(node: Node, description, manager_settings=None, **settings) -> startup.ControllersChoice:
    return startup.choose_controllers(node, description, settings_of(node, **settings),
                                      manager_settings, NO_ARGUMENTS)


@pytest.fixture
def pan_tilt():
    return load_description(PAN_TILT_URDF)


def test_the_controllers_file_gives_the_controllers_by_default(context, pan_tilt, tmp_path):
    controllers_file = tmp_path / 'mine.yaml'
    controllers_file.write_text(PAN_TILT_YAML.read_text())
    node = Node('sim_node', context=context, parameter_overrides=[
        Parameter('controllers_file', value=str(controllers_file))])
    try:
        choice = choose(node, pan_tilt)
    finally:
        node.destroy_node()
    assert choice.topic_settings is None
    assert choice.config.label == str(controllers_file)
    assert choice.config.namespace == 'ex_urdf_pan_tilt'
    assert [spec.name for spec in choice.config.controllers] == [
        'joint_state_controller', 'joint1_position_controller', 'joint2_position_controller']
    assert choice.arguments == NO_ARGUMENTS


def test_in_ros2_control_nodes_place_the_nodes_parameters_give_them(context, pan_tilt):
    node = Node(drop_in.NODE_NAME, context=context)
    manager = drop_in.ManagerSettings(50, {'fwd.type': FORWARD_TYPE,
                                           'fwd.joints': ['joint1', 'joint2'],
                                           'fwd.interface_name': 'position'})
    try:
        choice = choose(node, pan_tilt, manager, controller_manager=True)
    finally:
        node.destroy_node()
    assert choice.topic_settings is None
    assert [(spec.name, spec.type) for spec in choice.config.controllers] == [
        ('fwd', FORWARD_TYPE)]
    assert choice.config.update_rate == 50
    assert choice.config.label.endswith(f'the parameters of /{drop_in.NODE_NAME}')


def test_topic_based_hardware_runs_its_own_controllers_before_any_other_source(
        context, tmp_path):
    description = load_description(topic_based_urdf_file(tmp_path, {'j1': ['position']}))
    node = Node(drop_in.NODE_NAME, context=context)
    manager = drop_in.ManagerSettings(50, {'fwd.type': FORWARD_TYPE, 'fwd.joints': ['j1']})
    try:
        choice = choose(node, description, manager, controller_manager=True)
    finally:
        node.destroy_node()
    assert choice.topic_settings is not None
    assert choice.topic_settings.joints == ('j1',)
    assert choice.config.label == str(topic_hardware.SOURCE)
    assert 'fwd' not in [spec.name for spec in choice.config.controllers]


@pytest.mark.parametrize(('node_namespace', 'manager', 'expected'), [
    ('/', False, '/given'),  # robot_namespace comes before the files'
    ('/arm', False, '/arm'),  # the node's namespace comes first
    ('/', True, ''),  # ros2_control_node's: its own namespace and nowhere else
    ('/arm', True, '/arm'),
])
def test_the_robot_namespace(node_namespace, manager, expected):
    assert startup.robot_namespace(node_namespace, 'given', 'from_yaml', 'from_plugin',
                                   is_controller_manager=manager) == expected


def test_without_robot_namespace_the_controllers_file_then_the_plugin_name_it():
    assert startup.robot_namespace('/', '', 'from_yaml', 'from_plugin',
                                   is_controller_manager=False) == '/from_yaml'
    assert startup.robot_namespace('/', '', None, 'from_plugin',
                                   is_controller_manager=False) == '/from_plugin'


def serve_without_manager_messages(context, monkeypatch, *, autostart: bool,
                                   topic_mode: bool = False):
    monkeypatch.setattr(optional_interfaces, 'available',
                        lambda package: package != 'controller_manager_msgs')
    node = Node('sim_node', context=context, parameter_overrides=[
        Parameter('autostart_controllers', value=autostart)])
    try:
        # Nothing is bound or simulated: without the messages no step gets that far.
        return startup.serve_controller_manager(
            node, None, None, None, settings_of(node), NO_ARGUMENTS, '', topic_mode=topic_mode,
            is_controller_manager=False)
    finally:
        node.destroy_node()


def test_without_controller_manager_msgs_no_spawner_could_be_waited_for(context, monkeypatch):
    with pytest.raises(ParameterError, match="'autostart_controllers' is false, but "
                       'controller_manager_msgs is not installed'):
        serve_without_manager_messages(context, monkeypatch, autostart=False)


def test_without_controller_manager_msgs_autostarted_controllers_run_unserved(
        context, monkeypatch):
    assert serve_without_manager_messages(context, monkeypatch, autostart=True) is None


def test_on_topic_based_hardware_the_users_own_controller_manager_serves(context, monkeypatch):
    assert serve_without_manager_messages(context, monkeypatch, autostart=False,
                                          topic_mode=True) is None


def test_a_step_failing_before_the_threads_start_leaves_no_thread_and_no_publisher(
        context, monkeypatch):
    seen = {}

    def failing_report(node, description, controllers):  # the last step before _run
        seen['clock publishers'] = node.count_publishers('/clock')
        seen['physics thread made'] = node._physics_thread is not None
        seen['new threads'] = set(threading.enumerate()) - before
        raise RuntimeError('report failed')

    monkeypatch.setattr(SimNode, '_report', failing_report)
    probe = rclpy.create_node('probe', context=context)
    before = set(threading.enumerate())
    try:
        with pytest.raises(RuntimeError, match='report failed'):
            SimNode(context=context, physics_thread=True, parameter_overrides=[
                Parameter('robot_description_file', value=str(PAN_TILT_URDF)),
                Parameter('controllers_file', value=str(PAN_TILT_YAML))])
        assert seen == {'clock publishers': 1, 'physics thread made': True, 'new threads': set()}
        assert set(threading.enumerate()) - before == set()
        assert probe.count_publishers('/clock') == 0
        assert probe.get_node_names() == ['probe']
    finally:
        probe.destroy_node()


GZ_ROS2_CONTROL = ('<gazebo><plugin filename="gz_ros2_control-system" '
                   'name="gz_ros2_control::GazeboSimROS2ControlPlugin"/></gazebo>')


@pytest.mark.parametrize(('block', 'plugin', 'controllers_file', 'in_its_place', 'expected'), [
    (False, '', False, False, False),  # its Gazebo plugins run it: none, as in Gazebo
    (True, '', False, False, False),  # <ros2_control> alone makes none either
    (True, GZ_ROS2_CONTROL, False, False, True),  # gz_ros2_control's manager
    (False, '', True, False, True),  # the controllers file the user gave
    (False, '', False, True, True),  # sim_node in ros2_control_node's place
])
def test_a_controller_manager_exists_where_upstream_makes_one(
        tmp_path, block, plugin, controllers_file, in_its_place, expected):
    from mobile_fixtures import ROS2_DIFF_DRIVE, rover_urdf

    from pan_tilt_sim.model.controller_config import load_controllers_config

    urdf = tmp_path / 'rover.urdf'
    urdf.write_text(rover_urdf(ros2_control=block, extra=f'<gazebo>{ROS2_DIFF_DRIVE}</gazebo>'
                                                          f'{plugin}'))
    controllers = load_controllers_config([PAN_TILT_YAML] if controllers_file else [])
    assert startup.has_controller_manager(load_description(urdf).model, controllers,
                                          is_controller_manager=in_its_place) is expected


def test_the_pan_tilt_example_keeps_its_controller_manager(context, pan_tilt):
    node = Node('sim_node', context=context)
    try:
        controllers = choose(node, pan_tilt).config
    finally:
        node.destroy_node()
    assert startup.has_controller_manager(pan_tilt.model, controllers,
                                          is_controller_manager=False)
