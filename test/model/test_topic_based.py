"""Reading topic_based_ros2_control's command JointStates: aligned, packed, partial, refused."""

from __future__ import annotations

import math
import pathlib

from robot_fixtures import JointDef, star_robot_urdf
from topic_based_fixtures import topic_based_urdf

from pan_tilt_sim.model.topic_based import (
    CommandReader,
    command_interface,
    declared_interfaces,
    topic_based_system,
)
from pan_tilt_sim.model.urdf import parse_urdf

MIXED = {'a': ['position'], 'b': ['velocity'], 'c': ['effort'], 'd': ['position', 'velocity']}


def _model(interfaces=None):
    return parse_urdf(topic_based_urdf(interfaces or MIXED), pathlib.Path('star.urdf'))


def _reader(model=None):
    model = model or _model()
    commanded = {joint: command_interface(model, joint) for joint in 'abcd'}
    declared = {joint: declared_interfaces(model, joint) for joint in 'abcd'}
    return CommandReader(commanded, declared, ignored=['m'])


def test_the_block_and_each_joints_interface_come_from_the_urdf():
    model = _model()
    assert topic_based_system(model).plugin == 'topic_based_ros2_control/TopicBasedSystem'
    assert [command_interface(model, joint) for joint in 'abcd'] == [
        'position', 'velocity', 'effort', 'position']  # position preferred
    assert command_interface(model, 'b', override='effort') == 'effort'
    assert declared_interfaces(model, 'd') == ('position', 'velocity')


def test_a_robot_without_the_plugin_commands_position():
    model = parse_urdf(star_robot_urdf([JointDef('a')]), pathlib.Path('s.urdf'))
    assert topic_based_system(model) is None
    assert command_interface(model, 'a') == 'position'


def test_the_plugins_packed_arrays_are_unpacked_by_declared_interface():
    # The plugin: name = every joint; each array one value per joint declaring it.
    decoded = _reader().read(['a', 'b', 'c', 'd'], {
        'position': [0.1, 0.4], 'velocity': [0.2, 0.0], 'effort': [0.3]})
    assert decoded.commands == {'a': 0.1, 'b': 0.2, 'c': 0.3, 'd': 0.4}
    assert decoded.problems == []


def test_index_aligned_partial_messages_command_the_joints_they_name():
    reader = _reader()
    assert reader.read(['d'], {'position': [0.7]}).commands == {'d': 0.7}
    decoded = reader.read(['b', 'a'], {'position': [9.0, 0.5], 'velocity': [0.3, 9.0]})
    assert decoded.commands == {'a': 0.5, 'b': 0.3}  # each joint's own interface
    assert decoded.problems == []


def test_refusals_say_why():
    reader = _reader()
    wrong_interface = reader.read(['a'], {'velocity': [1.0]})
    assert wrong_interface.commands == {}
    assert wrong_interface.problems == ["'a' takes position commands; its velocity ignored"]
    bad_length = reader.read(['a', 'b', 'c'], {'position': [1.0, 2.0]})
    assert bad_length.commands == {}
    assert 'position has 2 values for 3 names' in bad_length.problems[0]
    unknown = reader.read(['a', 'zz'], {'position': [1.0, 2.0]})
    assert unknown.commands == {'a': 1.0}
    assert unknown.problems == ["'zz' is not a commanded joint: ignored"]
    twice = reader.read(['a', 'a'], {'position': [1.0, 2.0]})
    assert twice.commands == {} and 'named twice' in twice.problems[0]
    nan = reader.read(['a'], {'position': [math.nan]})
    assert nan.commands == {} and 'not finite' in nan.problems[0]


def test_mimic_joints_may_be_named_and_are_ignored():
    decoded = _reader().read(['a', 'm'], {'position': [0.2, 0.4]})
    assert decoded.commands == {'a': 0.2}
    assert decoded.problems == []
