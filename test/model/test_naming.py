"""Where the robot's topics live: the namespace rule, first that applies."""

import pytest

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model.naming import check_namespace, join, resolve_robot_namespace


def test_node_namespace_wins_over_everything():
    assert resolve_robot_namespace('/lab', 'param', 'yaml', '/plugin') == '/lab'


def test_robot_namespace_parameter_comes_next():
    assert resolve_robot_namespace('/', 'param', 'yaml', '/plugin') == '/param'


def test_yaml_wrapping_key_comes_before_the_plugin():
    assert resolve_robot_namespace('/', '', 'ex_urdf_pan_tilt', '/other') == '/ex_urdf_pan_tilt'


def test_plugin_robot_namespace_is_the_last_resort():
    assert resolve_robot_namespace('/', '', None, '/my_robot') == '/my_robot'
    assert resolve_robot_namespace('/', '', None, None) == ''


def test_topic_names_are_absolute():
    assert join('/ex_urdf_pan_tilt', 'joint1_position_controller', 'command') == (
        '/ex_urdf_pan_tilt/joint1_position_controller/command')
    assert join('', 'joint_states') == '/joint_states'


@pytest.mark.parametrize('namespace', ['', '/', 'robot', '/a/b_2', '_x'])
def test_valid_namespaces_pass(namespace):
    check_namespace('robot_namespace', namespace)


@pytest.mark.parametrize('namespace', ['9lives', '/a//b', 'a-b', '/a/', 'with space'])
def test_invalid_namespaces_are_refused(namespace):
    with pytest.raises(ParameterError, match='robot_namespace'):
        check_namespace('robot_namespace', namespace)
