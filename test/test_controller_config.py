"""Reading controller YAML in the seeds' (ROS 1 rosparam) layout."""

import pytest

from pan_tilt_sim.controller_config import load_controllers_config
from pan_tilt_sim.errors import ControllerConfigError


def test_our_config_wraps_the_seeds_controllers_in_the_robot_namespace(repo_root):
    config = load_controllers_config(repo_root / 'config' / 'pan_tilt_control.yaml')
    assert config.namespace == 'ex_urdf_pan_tilt'
    by_name = {spec.name: spec for spec in config.controllers}
    assert by_name['joint_state_controller'].type == 'joint_state_controller/JointStateController'
    assert by_name['joint_state_controller'].params['publish_rate'] == 50
    for name, joint in (('joint1_position_controller', 'pan_joint'),
                        ('joint2_position_controller', 'tilt_joint')):
        assert by_name[name].type == 'position_controllers/JointPositionController'
        assert by_name[name].params['joint'] == joint
        assert by_name[name].params['pid'] == {'p': 100.0, 'i': 0.01, 'd': 10.0}


def test_the_seeds_own_yaml_loads_unchanged_and_matches_ours(seeds_dir, repo_root):
    seed = load_controllers_config(seeds_dir / 'pan_tilt_control.yaml')
    ours = load_controllers_config(repo_root / 'config' / 'pan_tilt_control.yaml')
    assert seed.namespace == ours.namespace
    assert seed.controllers == ours.controllers


def test_controllers_at_the_top_level_have_no_namespace(seeds_dir):
    config = load_controllers_config(seeds_dir / 'joint_controllers.yaml')
    assert config.namespace is None
    assert [spec.name for spec in config.controllers] == ['joint_state_controller',
                                                          'arm_controller']


def test_a_yaml_syntax_error_names_the_file_and_line(tmp_path):
    path = tmp_path / 'bad.yaml'
    path.write_text('ns:\n  ctrl:\n    type: [unclosed\n')
    with pytest.raises(ControllerConfigError, match=r'bad.yaml:\d+: YAML syntax error'):
        load_controllers_config(path)


@pytest.mark.parametrize('text', ['', 'just a string', 'ns:\n  nothing: here\n'])
def test_a_file_without_controllers_is_refused(tmp_path, text):
    path = tmp_path / 'empty.yaml'
    path.write_text(text)
    with pytest.raises(ControllerConfigError, match='no controllers'):
        load_controllers_config(path)


def test_a_missing_file_names_the_file(tmp_path):
    with pytest.raises(ControllerConfigError, match='missing.yaml: no such file'):
        load_controllers_config(tmp_path / 'missing.yaml')
