"""ROS command-line arguments read as rcl reads them: sections, -p values, remap rules."""

from __future__ import annotations

import pathlib
import re

import pytest

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model.ros_arguments import expand, node_rules, parse_ros_arguments


def test_only_the_ros_args_sections_count():
    arguments = parse_ros_arguments(
        ['sim_node', '-p', 'not:=ros', '--ros-args', '--params-file', 'a.yaml', '-p', 'x:=1',
         '--', '--params-file', 'not.yaml', '--ros-args', '--log-level', 'debug',
         '--params-file', 'b.yaml'], 'the command line')
    assert arguments.params_files == (pathlib.Path('a.yaml'), pathlib.Path('b.yaml'))
    assert arguments.parameters_for('any') == {'x': 1}


def test_parameter_values_are_yaml_and_a_node_prefix_limits_them():
    arguments = parse_ros_arguments(
        ['-p', 'rate:=50', '-p', 'joints:=[a, b]', '-p', 'name:=arm', '-p', 'arm:gain:=2.5'],
        'args', whole=True)
    assert arguments.parameters_for('arm') == {'rate': 50, 'joints': ['a', 'b'],
                                               'name': 'arm', 'gain': 2.5}
    assert 'gain' not in arguments.parameters_for('other')


@pytest.mark.parametrize(('name', 'expanded'), [
    ('~/cmd_vel', '/ns/ctrl/cmd_vel'),
    ('~', '/ns/ctrl'),
    ('cmd_vel', '/ns/cmd_vel'),
    ('ctrl/commands', '/ns/ctrl/commands'),
    ('/cmd_vel', '/cmd_vel'),
    ('{node}/x', '/ns/ctrl/x'),
])
def test_names_expand_in_the_nodes_namespace(name, expanded):
    assert expand(name, '/ns', 'ctrl') == expanded


def test_names_expand_at_the_root_without_a_namespace():
    assert expand('~/cmd_vel', '', 'ctrl') == '/ctrl/cmd_vel'
    assert expand('cmd_vel', '/', 'ctrl') == '/cmd_vel'


def test_a_remap_renames_the_topic_its_expanded_source_names():
    arguments = parse_ros_arguments(['-r', '~/cmd_vel:=/cmd_vel',
                                     '-r', 'ctrl/commands:=/position_commands',
                                     '-r', 'other:odom:=/odom'], 'args', whole=True)
    assert arguments.remapped('/ns/ctrl/cmd_vel', '/ns', 'ctrl') == '/cmd_vel'
    assert arguments.remapped('/ns/ctrl/commands', '/ns', 'ctrl') == '/position_commands'
    assert arguments.remapped('/ns/odom', '/ns', 'ctrl') == '/ns/odom'  # for node 'other'
    assert arguments.remapped('/ns/odom', '/ns', 'other') == '/odom'
    assert arguments.remapped('/ns/ctrl/state', '/ns', 'ctrl') == '/ns/ctrl/state'


def test_node_renaming_rules_are_found():
    arguments = parse_ros_arguments(['-r', '__node:=x', '-r', '__ns:=/y', '-r', 'a:=b'],
                                    'args', whole=True)
    assert node_rules(arguments, 'ctrl') == ['__node:=x', '__ns:=/y']


@pytest.mark.parametrize(('argv', 'problem'), [
    (['-r', 'nothing'], "args: '-r nothing' is not of the form [node:]name:=value"),
    (['-r', 'a:='], "args: '-r a:=' remaps to nothing"),
    (['-p'], "args: '-p' must be followed by a value"),
    (['cmd_vel:=/x'], "args: 'cmd_vel:=/x' is not a ROS argument"),
])
def test_malformed_arguments_are_named(argv, problem):
    with pytest.raises(ParameterError, match=f'^{re.escape(problem)}'):
        parse_ros_arguments(argv, 'args', whole=True)
