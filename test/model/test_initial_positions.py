"""Start positions: the initial_positions parameter, else <ros2_control> initial_value, else 0."""

import math

import pytest
from robot_fixtures import JointDef, star_robot_urdf, write_text

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model.initial_positions import (
    FROM_DEFAULT,
    FROM_PARAMETER,
    FROM_URDF,
    parse_initial_positions,
    start_positions,
)
from pan_tilt_sim.model.urdf import parse_urdf

ROS2_CONTROL = """<ros2_control name="sys" type="system">
  <hardware><plugin>mock_components/GenericSystem</plugin></hardware>
  <joint name="a"><command_interface name="position"/>
    <state_interface name="position"><param name="initial_value">0.7</param></state_interface>
  </joint>
  <joint name="b"><state_interface name="position">
    <param name="initial_value">5.0</param></state_interface></joint>
</ros2_control>
</robot>"""


def model(tmp_path):
    joints = [JointDef('a'), JointDef('b', lower=-1.0, upper=1.0), JointDef('c', lower=0.2),
              JointDef('d', mimic=('a', 2.0, 0.0))]
    text = star_robot_urdf(joints).replace('</robot>', ROS2_CONTROL)
    path = write_text(tmp_path, 'r.urdf', text)
    return parse_urdf(path.read_text(), path)


def test_parameter_entries_are_joint_colon_equals_value():
    assert parse_initial_positions(['a:=0.5', ' b := -1e-3 ']) == {'a': 0.5, 'b': -0.001}
    assert parse_initial_positions([]) == {}


@pytest.mark.parametrize(('entry', 'problem'), [
    ('a=0.5', "'a=0.5' is not of the form joint:=value"),
    (':=0.5', "':=0.5' is not of the form joint:=value"),
    ('a:=fast', "'fast' is not a finite number"),
    ('a:=nan', "'nan' is not a finite number"),
    ('a:=', "'' is not a finite number"),
])
def test_a_malformed_entry_is_one_line_naming_the_parameter(entry, problem):
    with pytest.raises(ParameterError) as raised:
        parse_initial_positions([entry])
    assert str(raised.value).startswith("parameter 'initial_positions': ")
    assert problem in str(raised.value)


def test_a_joint_given_twice_is_refused():
    with pytest.raises(ParameterError, match="joint 'a' is given more than once"):
        parse_initial_positions(['a:=1', 'a:=2'])


def test_the_parameter_beats_the_urdf_which_beats_zero(tmp_path):
    starts = start_positions(model(tmp_path), {'b': 0.25})
    assert {name: (s.position, s.source) for name, s in starts.items()} == {
        'a': (0.7, FROM_URDF), 'b': (0.25, FROM_PARAMETER), 'c': (0.2, FROM_DEFAULT),
        'd': (0.0, FROM_DEFAULT)}


def test_starts_outside_the_limits_are_clamped_and_say_so(tmp_path):
    starts = start_positions(model(tmp_path))
    b, c = starts['b'], starts['c']
    assert (b.position, b.requested, b.clamped) == (1.0, 5.0, True)
    assert b.describe(-1.0, 1.0) == ("joint 'b': initial position 5 (<ros2_control> "
                                     'initial_value) is outside its limits [-1, 1]; starts at 1')
    assert c.describe(0.2, 1.5) == "joint 'c' starts at 0.2: 0 is outside its limits [0.2, 1.5]"
    assert starts['a'].describe(-1.5, 1.5) == "joint 'a' starts at 0.7 (<ros2_control> " \
                                              'initial_value)'
    assert start_positions(model(tmp_path), {'a': -9.0})['a'].position == -1.5


@pytest.mark.parametrize(('overrides', 'problem'), [
    ({'elbow': 1.0}, "'elbow' is not a movable joint of the robot (movable joints: a, b, c, d)"),
    ({'d': 1.0}, "joint 'd' mimics 'a' and starts where it puts it; give 'a' instead"),
])
def test_unknown_and_mimic_joints_are_refused_by_name(tmp_path, overrides, problem):
    with pytest.raises(ParameterError) as raised:
        start_positions(model(tmp_path), overrides)
    assert str(raised.value) == f"parameter 'initial_positions': {problem}"


def test_without_limits_any_start_is_taken(tmp_path):
    text = star_robot_urdf([JointDef('spin', 'continuous', None, None)])
    path = write_text(tmp_path, 'r.urdf', text)
    starts = start_positions(parse_urdf(text, path), {'spin': 4 * math.pi})
    assert starts['spin'].position == 4 * math.pi and not starts['spin'].clamped
