"""Gains written back into controller YAML: only the gains change, and the loader reads them."""

import pathlib
import textwrap

import pytest
import yaml

from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.controller_config import load_controllers_config
from pan_tilt_sim.model.gains_yaml import (
    GainsUpdate,
    clamp_values,
    gain_fields,
    rewrite_gains,
    yaml_float,
)

ROS1 = textwrap.dedent("""\
    # Controllers of the robot
    robot:
      joint_state_controller:
        type: joint_state_controller/JointStateController
        publish_rate: 50

      # The pan
      pan_controller:
        type: position_controllers/JointPositionController
        joint: pan_joint
        pid: {p: 100.0, i: 0.01, d: 10.0}   # example gains

      tilt_controller:
        type: effort_controllers/JointPositionController
        joint: tilt_joint
        pid:
          p: 50     # hand-tuned
          i: 0.5
          d: 5.0
          i_clamp_min: -2.0
          i_clamp_max: 2.0
    """)

ROS2 = textwrap.dedent("""\
    controller_manager:
      ros__parameters:
        update_rate: 100
        arm_controller:
          type: joint_trajectory_controller/JointTrajectoryController
    /**:
      ros__parameters:
        gains.elbow.p: 5.0
    arm_controller:
      ros__parameters:
        joints:
          - shoulder
          - elbow
        gains:
          # shoulder carries the arm
          shoulder:
            p: 100.0
            i: 1.0
            d: 10.0
          elbow: {p: 1.0, d: 0.1}
        gains.elbow.p: 20.0   # the controller's own wins over /**
    """)


def load(tmp_path: pathlib.Path, text: str):
    path = tmp_path / 'controllers.yaml'
    path.write_text(text)
    return {spec.name: spec.params for spec in load_controllers_config(path).controllers}


def changed_lines(before: str, after: str) -> list[tuple[str, str]]:
    return [(old, new) for old, new in zip(before.splitlines(), after.splitlines(), strict=False)
            if old != new]


@pytest.mark.parametrize(('value', 'text'), [(100.0, '100.0'), (1e-05, '1.0e-05'),
                                             (2.5e20, '2.5e+20'), (0.1762, '0.1762'),
                                             (float('inf'), '.inf')])
def test_floats_are_written_so_yaml_1_1_reads_them_back(value, text):
    assert yaml_float(value) == text
    assert yaml.safe_load(f'x: {text}')['x'] == value


def test_a_flow_pid_gets_new_values_and_a_clamp_on_its_own_line_only(tmp_path):
    update = GainsUpdate('pan_controller', 'pan_joint', 'pid',
                         {'p': 812.3, 'i': 1e-05, 'd': 30.0, **clamp_values(12.5, ['p'])})
    after = rewrite_gains(ROS1, 'f.yaml', [update])
    assert changed_lines(ROS1, after) == [(
        '    pid: {p: 100.0, i: 0.01, d: 10.0}   # example gains',
        '    pid: {p: 812.3, i: 1.0e-05, d: 30.0, i_clamp: 12.5}   # example gains')]
    params = load(tmp_path, after)
    assert params['pan_controller']['pid'] == {'p': 812.3, 'i': 1e-05, 'd': 30.0,
                                               'i_clamp': 12.5}
    assert params['tilt_controller'] == load(tmp_path, ROS1)['tilt_controller']


def test_a_block_pid_keeps_its_comments_and_its_clamp_style(tmp_path):
    existing = gain_fields(ROS1, 'f.yaml', 'tilt_controller', ('pid',))
    assert existing == ['p', 'i', 'd', 'i_clamp_min', 'i_clamp_max']
    update = GainsUpdate('tilt_controller', 'tilt_joint', 'pid',
                         {'p': 75.0, 'i': 0.25, 'd': 4.0, **clamp_values(3.0, existing)})
    after = rewrite_gains(ROS1, 'f.yaml', [update])
    assert changed_lines(ROS1, after) == [
        ('      p: 50     # hand-tuned', '      p: 75.0     # hand-tuned'),
        ('      i: 0.5', '      i: 0.25'), ('      d: 5.0', '      d: 4.0'),
        ('      i_clamp_min: -2.0', '      i_clamp_min: -3.0'),
        ('      i_clamp_max: 2.0', '      i_clamp_max: 3.0')]


def test_ros2_gains_are_written_where_the_loader_reads_them(tmp_path):
    shoulder = GainsUpdate('arm_controller', 'shoulder', 'gains',
                           {'p': 150.0, 'i': 2.0, 'd': 12.0, 'i_clamp': 4.0})
    elbow = GainsUpdate('arm_controller', 'elbow', 'gains',
                        {'p': 30.0, 'i': 0.5, 'd': 0.2, 'i_clamp': 1.0})
    after = rewrite_gains(ROS2, 'f.yaml', [shoulder, elbow])
    gains = load(tmp_path, after)['arm_controller']['gains']
    assert gains == {'shoulder': {'p': 150.0, 'i': 2.0, 'd': 12.0, 'i_clamp': 4.0},
                     'elbow': {'p': 30.0, 'i': 0.5, 'd': 0.2, 'i_clamp': 1.0}}
    # The wildcard's p is not the one in force, so it stays; a new block key is indented
    # like its siblings; new fields follow the last definition in force, in its key form.
    assert '    gains.elbow.p: 5.0\n' in after
    assert '        i: 2.0\n        d: 12.0\n        i_clamp: 4.0\n' in after
    assert '      elbow: {p: 1.0, d: 0.2}\n' in after
    assert after.endswith("    gains.elbow.p: 30.0   # the controller's own wins over /**\n"
                          '    gains.elbow.i: 0.5\n    gains.elbow.i_clamp: 1.0\n')
    assert '# shoulder carries the arm' in after


def test_nothing_but_the_gains_changes_in_the_shipped_arm_file(repo_root, tmp_path):
    text = (repo_root / 'config' / 'three_joint_arm_controllers.yaml').read_text()
    update = GainsUpdate('arm_controller', 'wrist_joint', 'gains',
                         {'p': 12.0, 'i': 0.2, 'd': 0.25, 'i_clamp': 0.75})
    after = rewrite_gains(text, 'arm.yaml', [update])
    assert len(changed_lines(text, after)) == 1
    before, written = load(tmp_path, text), load(tmp_path, after)
    before['arm_controller']['gains']['wrist_joint'] = {'p': 12.0, 'i': 0.2, 'd': 0.25,
                                                        'i_clamp': 0.75}
    assert written == before


def test_gains_that_come_from_an_alias_are_refused():
    text = textwrap.dedent("""\
        defaults: &pid {p: 1.0, i: 0.0, d: 0.1}
        pan_controller:
          type: position_controllers/JointPositionController
          joint: pan_joint
          pid: *pid
        """)
    with pytest.raises(ControllerConfigError, match='alias'):
        rewrite_gains(text, 'f.yaml', [GainsUpdate('pan_controller', 'pan_joint', 'pid',
                                                   {'p': 2.0})])


def test_a_controller_without_gains_in_the_file_is_an_error():
    text = ROS1.replace('    pid: {p: 100.0, i: 0.01, d: 10.0}   # example gains\n', '')
    with pytest.raises(ControllerConfigError, match='no gains in the file'):
        rewrite_gains(text, 'f.yaml', [GainsUpdate('pan_controller', 'pan_joint', 'pid',
                                                   {'p': 2.0})])
    with pytest.raises(ControllerConfigError, match="no controller 'nope'"):
        gain_fields(ROS1, 'f.yaml', 'nope', ('pid',))


def test_a_gain_given_by_a_substitution_is_left_to_the_user():
    text = ROS1.replace('pid: {p: 100.0,', 'pid: {p: $(var pan_p),')
    with pytest.raises(ControllerConfigError, match=r"pid\.p: '\$\(var pan_p\)' is not a number"):
        rewrite_gains(text, 'f.yaml', [GainsUpdate('pan_controller', 'pan_joint', 'pid',
                                                   {'p': 2.0})])


def test_a_ros1_file_of_one_controller_is_that_controller(tmp_path):
    text = 'type: position_controllers/JointPositionController\njoint: pan_joint\n' \
           'pid: {p: 10.0, d: 1.0}\n'
    after = rewrite_gains(text, 'pan.yaml', [GainsUpdate('pan', 'pan_joint', 'pid',
                                                         {'p': 20.0, 'i_clamp': 3.0})])
    assert after == text.replace('{p: 10.0, d: 1.0}', '{p: 20.0, d: 1.0, i_clamp: 3.0}')
