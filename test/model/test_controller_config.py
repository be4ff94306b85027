"""Reading controller YAML: the examples' ROS 1 (rosparam) layout and ros2_control's."""

import dataclasses
import math
import os
import textwrap

import pytest
from mesh_fixtures import make_ament_prefix
from ros2_control_fixtures import ARM_XACRO, CONTROLLERS_FILE, HEAD_YAML, UR_STYLE_YAML, write

from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.controller_config import (
    DEFAULT_UPDATE_RATE,
    controllers_files_for,
    load_controllers_config,
    node_parameters,
    parse_controllers_args,
)
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.share import package_share
from pan_tilt_sim.sim.engine import make_simulation


@pytest.fixture
def write_yaml(tmp_path):
    def write(text, name='controllers.yaml'):
        path = tmp_path / name
        path.write_text(textwrap.dedent(text), encoding='utf-8')
        return path
    return write


def by_name(config):
    return {spec.name: spec for spec in config.controllers}


# --- ROS 1 style (the examples') ---------------------------------------------------------------

def test_our_config_wraps_the_pan_tilt_examples_controllers_in_the_robot_namespace(repo_root):
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


def test_the_original_examples_yaml_loads_unchanged_and_matches_ours(original_examples, repo_root):
    original = load_controllers_config(original_examples / 'pan_tilt_control.yaml')
    ours = load_controllers_config(repo_root / 'config' / 'pan_tilt_control.yaml')
    assert original.namespace == ours.namespace
    assert original.controllers == ours.controllers


def test_controllers_at_the_top_level_have_no_namespace(original_examples):
    config = load_controllers_config(original_examples / 'joint_controllers.yaml')
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

def test_ros1_files_get_no_update_rate(original_examples):
    # publish_rate stays the only rate of a ROS 1 file's joint_state_controller.
    config = load_controllers_config(original_examples / 'joint_controllers.yaml')
    assert all('update_rate' not in spec.params for spec in config.controllers)


# --- ros2_control style ---------------------------------------------------------------------

ROS2_FILE = """
    controller_manager:
      ros__parameters:
        update_rate: 250
        joint_state_broadcaster:
          type: joint_state_broadcaster/JointStateBroadcaster
        arm_controller:
          type: joint_trajectory_controller/JointTrajectoryController
        gripper_controller:
          type: forward_command_controller/ForwardCommandController

    arm_controller:
      ros__parameters:
        joints: [shoulder_joint, elbow_joint]
        command_interfaces: [effort]
        gains:
          shoulder_joint: {p: 100.0, i: 0.01, d: 10.0, i_clamp: 1.0}

    gripper_controller:
      ros__parameters:
        joints: [finger_joint]
        interface_name: position
    """


def test_ros2_controllers_come_from_the_controller_manager_in_file_order(write_yaml):
    config = load_controllers_config(write_yaml(ROS2_FILE))
    assert [(spec.name, spec.type) for spec in config.controllers] == [
        ('joint_state_broadcaster', 'joint_state_broadcaster/JointStateBroadcaster'),
        ('arm_controller', 'joint_trajectory_controller/JointTrajectoryController'),
        ('gripper_controller', 'forward_command_controller/ForwardCommandController'),
    ]


def test_ros2_controller_takes_the_parameters_of_its_node(write_yaml):
    specs = by_name(load_controllers_config(write_yaml(ROS2_FILE)))
    arm = specs['arm_controller'].params
    assert arm['joints'] == ['shoulder_joint', 'elbow_joint']
    assert arm['gains'] == {'shoulder_joint': {'p': 100.0, 'i': 0.01, 'd': 10.0, 'i_clamp': 1.0}}
    assert specs['gripper_controller'].params['interface_name'] == 'position'


def test_ros2_list_of_mappings_is_read_as_the_mappings_merged_as_rcl_reads_it(write_yaml):
    # ros2_controllers' gpio_command_controller documents its interfaces this way.
    config = load_controllers_config(write_yaml("""\
        controller_manager:
          ros__parameters:
            gpio_controller: {type: gpio_controllers/GpioCommandController}
        gpio_controller:
          ros__parameters:
            gpios: [flange_vacuum, io]
            command_interfaces:
              flange_vacuum:
                - interfaces:
                  - vacuum
              io:
                - interfaces: [out1]
                - state_note: kept
        """))
    params = by_name(config)['gpio_controller'].params
    assert params['gpios'] == ['flange_vacuum', 'io']
    assert params['command_interfaces'] == {
        'flange_vacuum': {'interfaces': ['vacuum']},
        'io': {'interfaces': ['out1'], 'state_note': 'kept'}}


def test_ros2_file_gives_no_namespace(write_yaml):
    assert load_controllers_config(write_yaml(ROS2_FILE)).namespace is None


def test_ros2_controllers_inherit_the_manager_update_rate(write_yaml):
    specs = by_name(load_controllers_config(write_yaml(ROS2_FILE)))
    assert {spec.params['update_rate'] for spec in specs.values()} == {250.0}


def test_a_manager_named_otherwise_takes_its_update_rate_from_its_own_section(write_yaml):
    # gz_ros2_control's <controller_manager_name>arm_manager: that node reads arm_manager's.
    path = write_yaml("""\
        controller_manager:
          ros__parameters:
            update_rate: 250
        arm_manager:
          ros__parameters:
            update_rate: 25
            jsb:
              type: joint_state_broadcaster/JointStateBroadcaster
        """)
    assert load_controllers_config(path, manager='arm_manager').update_rate == 25.0
    assert load_controllers_config(path).update_rate == 250.0
    with pytest.raises(ControllerConfigError, match=r'arm_manager\.ros__parameters\.update_rate'):
        load_controllers_config(write_yaml(ROS2_FILE.replace('controller_manager:', 'arm_manager:')
                                           .replace('update_rate: 250', 'update_rate: -1')),
                                manager='arm_manager')


def test_ros2_update_rate_defaults_to_ros2_control_default(write_yaml):
    config = load_controllers_config(write_yaml("""
        controller_manager:
          ros__parameters:
            joint_state_broadcaster:
              type: joint_state_broadcaster/JointStateBroadcaster
        """))
    assert config.controllers[0].params['update_rate'] == DEFAULT_UPDATE_RATE == 100.0


def test_ros2_controller_own_update_rate_wins(write_yaml):
    config = load_controllers_config(write_yaml("""
        controller_manager:
          ros__parameters:
            update_rate: 200
            joint_state_broadcaster:
              type: joint_state_broadcaster/JointStateBroadcaster
        joint_state_broadcaster:
          ros__parameters:
            update_rate: 20
        """))
    assert config.controllers[0].params['update_rate'] == 20


def test_ros2_wildcard_parameters_reach_every_node_under_their_own(write_yaml):
    specs = by_name(load_controllers_config(write_yaml("""
        /**:
          ros__parameters:
            use_sim_time: true
            interface_name: velocity
        controller_manager:
          ros__parameters:
            fwd:
              type: forward_command_controller/ForwardCommandController
            other:
              type: forward_command_controller/ForwardCommandController
        fwd:
          ros__parameters:
            joints: [a]
            interface_name: effort
        other:
          ros__parameters:
            joints: [b]
        """)))
    assert specs['fwd'].params['use_sim_time'] is True
    assert specs['fwd'].params['interface_name'] == 'effort'
    assert specs['other'].params['interface_name'] == 'velocity'


def test_ros2_namespaced_node_keys_are_matched_by_node_name(write_yaml):
    config = load_controllers_config(write_yaml("""
        /robot/controller_manager:
          ros__parameters:
            update_rate: 50
            arm_controller:
              type: position_controllers/JointGroupPositionController
        robot:
          arm_controller:
            ros__parameters:
              joints: [a, b]
        """))
    assert config.namespace is None
    (arm,) = config.controllers
    assert arm.params['joints'] == ['a', 'b']
    assert arm.params['update_rate'] == 50


def test_ros2_dotted_parameter_names_mean_nested_mappings(write_yaml):
    (arm,) = load_controllers_config(write_yaml("""
        controller_manager:
          ros__parameters:
            arm_controller.type: joint_trajectory_controller/JointTrajectoryController
        arm_controller:
          ros__parameters:
            joints: [a]
            gains.a.p: 50.0
            gains.a.d: 5.0
        """)).controllers
    assert arm.type == 'joint_trajectory_controller/JointTrajectoryController'
    assert arm.params['gains'] == {'a': {'p': 50.0, 'd': 5.0}}


def test_ros2_type_may_sit_among_the_controller_own_parameters(write_yaml):
    (fwd,) = load_controllers_config(write_yaml("""
        controller_manager:
          ros__parameters:
            update_rate: 100
        fwd:
          ros__parameters:
            type: forward_command_controller/ForwardCommandController
            joints: [a]
            interface_name: effort
        """)).controllers
    assert (fwd.name, fwd.type) == ('fwd', 'forward_command_controller/ForwardCommandController')


@pytest.mark.parametrize('rate', ['0', '-5', '.nan', 'fast', 'true'])
def test_ros2_bad_update_rate_names_the_field(write_yaml, rate):
    path = write_yaml(f"""
        controller_manager:
          ros__parameters:
            update_rate: {rate}
            jsb:
              type: joint_state_broadcaster/JointStateBroadcaster
        """)
    with pytest.raises(ControllerConfigError,
                       match=r'controller_manager\.ros__parameters\.update_rate'):
        load_controllers_config(path)


def test_ros2_file_without_controllers_says_what_it_expected(write_yaml):
    path = write_yaml("""
        controller_manager:
          ros__parameters:
            update_rate: 100
        """)
    with pytest.raises(ControllerConfigError, match=r'no controllers.*ros2_control style') as err:
        load_controllers_config(path)
    assert str(path) in str(err.value)


def test_ros2_parameters_must_be_a_mapping(write_yaml):
    with pytest.raises(ControllerConfigError, match=r'arm_controller\.ros__parameters'):
        load_controllers_config(write_yaml("""
            arm_controller:
              ros__parameters: [1, 2]
            """))


def test_shipped_three_joint_arm_controllers_load(repo_root):
    config = load_controllers_config(repo_root / 'config' / 'three_joint_arm_controllers.yaml')
    specs = by_name(config)
    assert config.namespace is None
    assert specs['arm_controller'].params['joints'] == [
        'shoulder_joint', 'extend_joint', 'wrist_joint']
    assert specs['gripper_controller'].type == 'position_controllers/JointGroupPositionController'
    assert math.isclose(specs['joint_state_broadcaster'].params['update_rate'], 100.0)


# --- the same robot, both styles ------------------------------------------------------------

ARM_GAINS = {'shoulder_joint': '{p: 100.0, i: 1.0, d: 10.0, i_clamp: 5.0}',
             'extend_joint': '{p: 1000.0, i: 10.0, d: 60.0, i_clamp: 10.0}',
             'wrist_joint': '{p: 10.0, i: 0.1, d: 0.3, i_clamp: 0.5}'}
ARM_TARGETS = {'shoulder_joint': 0.8, 'extend_joint': 0.15, 'wrist_joint': -4.0}


def ros1_arm_yaml():
    lines = ['three_joint_arm:',
             '  joint_state_controller:',
             '    type: joint_state_controller/JointStateController',
             '    publish_rate: 100']
    for joint, gains in ARM_GAINS.items():
        lines += [f'  {joint}_position_controller:',
                  '    type: effort_controllers/JointPositionController',
                  f'    joint: {joint}',
                  f'    pid: {gains}']
    return '\n'.join(lines) + '\n'


def ros2_arm_yaml():
    gains = ''.join(f'\n                  {joint}: {value}' for joint, value in ARM_GAINS.items())
    return f"""
        controller_manager:
          ros__parameters:
            update_rate: 1000  # the physics rate, at which ROS 1 ran every controller
            joint_state_broadcaster:
              type: joint_state_broadcaster/JointStateBroadcaster
            arm_controller:
              type: position_controllers/JointGroupPositionController
        arm_controller:
          ros__parameters:
            joints: [{', '.join(ARM_GAINS)}]
            gains:{gains}
        """


def arm_motion(repo_root, controllers_file, command):
    """Command the arm's targets and record every joint's position each 10 ms for 3 s."""
    with make_simulation(str(repo_root / 'urdf' / 'three_joint_arm.xacro'),
                         str(controllers_file), 0.001) as simulation:
        command(simulation)
        samples = []
        for _ in range(300):
            simulation.advance(10)
            samples.append(simulation.joint_positions())
    return samples


def test_ros1_and_ros2_control_yaml_give_the_same_motion(repo_root, write_yaml):
    def per_joint(simulation):
        for joint, target in ARM_TARGETS.items():
            simulation.controller(f'{joint}_position_controller').set_command(target)

    def as_group(simulation):
        simulation.controller('arm_controller').set_command(
            [ARM_TARGETS[joint] for joint in ARM_GAINS])

    ros1 = arm_motion(repo_root, write_yaml(ros1_arm_yaml(), 'ros1.yaml'), per_joint)
    ros2 = arm_motion(repo_root, write_yaml(ros2_arm_yaml(), 'ros2.yaml'), as_group)
    assert ros1 == ros2
    assert ros1[-1]['wrist_joint'] == pytest.approx(-4.0, abs=0.01)
    assert ros1[-1]['shoulder_joint'] == pytest.approx(0.8, abs=0.01)


# --- gazebo_ros_control's own PID gains ----------------------------------------------------

@pytest.mark.parametrize('wrapped', [False, True], ids=['top-level', 'in-namespace'])
def test_gazebo_ros_control_pid_gains_are_kept_beside_the_controllers(write_yaml, wrapped):
    text = """\
        pan_controller:
          type: position_controllers/JointPositionController
          joint: pan_joint
        gazebo_ros_control:
          pid_gains:
            pan_joint: {p: 50.0, i: 0.1, d: 2.0}
        """
    if wrapped:
        text = 'robot:\n' + textwrap.indent(textwrap.dedent(text), '  ')
    config = load_controllers_config(write_yaml(text))
    assert config.pid_gains == {'pan_joint': {'p': 50.0, 'i': 0.1, 'd': 2.0}}
    assert [spec.name for spec in config.controllers] == ['pan_controller']


def test_without_gazebo_ros_control_there_are_no_plugin_gains(repo_root):
    config = load_controllers_config(repo_root / 'config' / 'pan_tilt_control.yaml')
    assert config.pid_gains == {}


@pytest.mark.parametrize('plugin', ['{pid_gains: [1, 2]}', 'on'])
def test_pid_gains_that_are_no_mapping_name_the_field(write_yaml, plugin):
    path = write_yaml(f"""\
        c:
          type: effort_controllers/JointEffortController
          joint: j
        gazebo_ros_control: {plugin}
        """)
    with pytest.raises(ControllerConfigError,
                       match=r'gazebo_ros_control\.pid_gains: expected a mapping'):
        load_controllers_config(path)


# --- launch substitutions: $(var ...) and friends -------------------------------------------

RRBOT_STYLE = """
    joint_state_broadcaster:
      ros__parameters:
        type: joint_state_broadcaster/JointStateBroadcaster

    forward_position_controller:
      ros__parameters:
        type: forward_command_controller/ForwardCommandController
        joints:
          - $(var joint_prefix)1
          - $(var joint_prefix)2
        interface_name: position
    """


def test_var_substitutions_take_the_values_given(write_yaml):
    specs = by_name(load_controllers_config(write_yaml(RRBOT_STYLE), {'joint_prefix': 'joint'}))
    assert specs['forward_position_controller'].params['joints'] == ['joint1', 'joint2']


def test_an_unset_var_is_an_error_naming_it_its_line_and_the_parameter(write_yaml):
    path = write_yaml(RRBOT_STYLE)
    with pytest.raises(ControllerConfigError) as caught:
        load_controllers_config(path, {'other': 'x'})
    assert str(caught.value) == (
        f"{path}:10: $(var joint_prefix) is not set: give it in the parameter "
        "'controllers_args' as 'joint_prefix:=<value>' (a launch file would fill it from its "
        'arguments)')


def test_a_var_default_an_arg_and_env_substitutions_expand(write_yaml, monkeypatch):
    monkeypatch.setenv('PAN_TILT_SIM_TEST_RATE', '25')
    monkeypatch.delenv('PAN_TILT_SIM_TEST_UNSET', raising=False)
    (spec,) = load_controllers_config(write_yaml("""
        $(var name ctrl):
          type: position_controllers/JointPositionController
          joint: $(arg prefix)pan_joint$(optenv PAN_TILT_SIM_TEST_UNSET)
          publish_rate: $(env PAN_TILT_SIM_TEST_RATE)
        """), {'prefix': 'my_'}).controllers
    assert (spec.name, spec.params['joint']) == ('ctrl', 'my_pan_joint')
    assert spec.params['publish_rate'] == 25  # expanded before the YAML is read, as launch does


def test_a_substitution_in_a_comment_is_no_error(write_yaml):
    (spec,) = load_controllers_config(write_yaml("""
        # joints are $(var prefix)N in the upstream file
        a: {type: effort_controllers/JointEffortController, joint: pan_joint}
        """)).controllers
    assert spec.params['joint'] == 'pan_joint'


@pytest.mark.parametrize(('text', 'message'), [
    ('joint: $(env PAN_TILT_SIM_TEST_UNSET)',
     '$(env PAN_TILT_SIM_TEST_UNSET): the environment variable PAN_TILT_SIM_TEST_UNSET is not '
     'set'),
    ('joint: $(dirname)/x', '$(dirname) is a launch substitution sim_node does not expand'),
    ('joint: $(find-pkg-share no_such_package_here)/x',
     "$(find-pkg-share no_such_package_here): package 'no_such_package_here' is not in the "
     'ament index'),
])
def test_substitutions_that_cannot_be_expanded_say_why(write_yaml, monkeypatch, text, message):
    monkeypatch.delenv('PAN_TILT_SIM_TEST_UNSET', raising=False)
    path = write_yaml(f'a:\n  type: effort_controllers/JointEffortController\n  {text}\n')
    with pytest.raises(ControllerConfigError) as caught:
        load_controllers_config(path)
    assert str(caught.value).startswith(f'{path}:3: {message}')


def test_find_pkg_share_expands_through_the_ament_index(write_yaml):
    (spec,) = load_controllers_config(write_yaml("""
        a:
          type: effort_controllers/JointEffortController
          joint: $(find-pkg-share pan_tilt_sim)/x
        """)).controllers
    assert spec.params['joint'] == f'{package_share()}/x'


@pytest.mark.parametrize('item', ['no_separator', ':=value'])
def test_controllers_args_must_be_name_value_mappings(item):
    with pytest.raises(ControllerConfigError,
                       match=rf"^parameter 'controllers_args': '{item}' is not of the form "
                             'name:=value$'):
        parse_controllers_args([item], "parameter 'controllers_args'")
    assert parse_controllers_args(['a:=1', 'b:=x:=y', 'c:=']) == {'a': '1', 'b': 'x:=y', 'c': ''}


# --- ROS 1 files with one controller; several files -----------------------------------------

def test_a_ros1_file_with_one_controller_names_it_after_the_file(write_yaml):
    config = load_controllers_config(write_yaml(HEAD_YAML, name='head.yaml'))
    (spec,) = config.controllers
    assert (spec.name, spec.type, spec.params['joint']) == (
        'head', 'position_controllers/JointPositionController', 'joint1')
    assert config.namespace is None


def test_a_file_name_that_is_no_ros_name_gives_a_valid_controller_name(write_yaml):
    (spec,) = load_controllers_config(write_yaml(HEAD_YAML, name='2-head.yaml')).controllers
    assert spec.name == '_2_head'


def test_several_ros2_files_are_read_in_order_later_ones_winning(write_yaml):
    declarations = write_yaml("""
        controller_manager:
          ros__parameters:
            update_rate: 50
            arm: {type: position_controllers/JointGroupPositionController}
        arm:
          ros__parameters: {joints: [a]}
        """, name='manager.yaml')
    own = write_yaml("""
        arm:
          ros__parameters: {joints: [a, b]}
        """, name='arm.yaml')
    config = load_controllers_config([declarations, own])
    (arm,) = config.controllers
    assert arm.params['joints'] == ['a', 'b']
    assert config.update_rate == 50.0
    assert config.sources == (declarations, own)
    assert config.label == f'{declarations} + {own}'


def test_ros1_files_have_no_update_rate_and_ros2_files_their_managers(write_yaml, repo_root):
    assert load_controllers_config(repo_root / 'config' / 'pan_tilt_control.yaml'
                                   ).update_rate is None
    assert load_controllers_config(write_yaml(ROS2_FILE)).update_rate == 250.0


# --- which controllers file: the parameter, the URDF's plugin, the default -----------------

def _description(tmp_path, controllers_file=CONTROLLERS_FILE, text=UR_STYLE_YAML):
    tmp_path.mkdir(parents=True, exist_ok=True)
    write(tmp_path, CONTROLLERS_FILE, text)
    xacro = write(tmp_path, 'two_link_arm.urdf.xacro', ARM_XACRO)
    return load_description(xacro, [f'controllers:={controllers_file}'])


def test_the_file_the_urdf_plugin_names_is_used_relative_to_the_urdf(tmp_path):
    description = _description(tmp_path)
    assert controllers_files_for('', description) == (tmp_path / CONTROLLERS_FILE,)


def test_a_given_controllers_file_wins_over_the_urdf(tmp_path, monkeypatch):
    description = _description(tmp_path)
    monkeypatch.chdir(tmp_path)
    assert controllers_files_for('other.yaml', description) == (tmp_path / 'other.yaml',)


def test_the_plugin_may_name_a_package_uri(tmp_path, monkeypatch):
    prefix = make_ament_prefix(tmp_path, 'arm_bringup',
                               {'config/controllers.yaml': UR_STYLE_YAML})
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(prefix))
    description = _description(tmp_path / 'src', 'package://arm_bringup/config/controllers.yaml')
    assert controllers_files_for('', description) == (
        prefix / 'share' / 'arm_bringup' / 'config' / 'controllers.yaml',)


def test_a_relative_plugin_path_found_only_from_the_current_folder_is_taken_from_there(
        tmp_path, monkeypatch):
    description = _description(tmp_path / 'robot', 'config/c.yaml')
    (tmp_path / 'config').mkdir()
    write(tmp_path / 'config', 'c.yaml', HEAD_YAML)
    monkeypatch.chdir(tmp_path)
    assert controllers_files_for('', description) == (tmp_path / 'config' / 'c.yaml',)


def test_a_plugin_file_that_does_not_exist_says_where_it_was_named(tmp_path):
    description = _description(tmp_path, 'missing.yaml')
    with pytest.raises(ControllerConfigError) as caught:
        controllers_files_for('', description)
    assert str(caught.value) == (
        f"{description.source}: the gz_ros2_control-system plugin's <parameters> names "
        f"'missing.yaml' (resolved to {tmp_path / 'missing.yaml'}): no such file")


def test_the_default_model_gets_the_default_controllers(repo_root, original_examples):
    for model in (repo_root / 'urdf' / 'pan_tilt.xacro', original_examples / 'pan_tilt.xacro'):
        assert controllers_files_for('', load_description(model)) == (
            package_share() / 'config' / 'pan_tilt_control.yaml',)


def test_a_robot_that_names_no_controllers_file_is_told_exactly_that(repo_root):
    description = load_description(repo_root / 'test' / '..' / 'urdf' / 'three_joint_arm.xacro')
    bare = dataclasses.replace(description, model=dataclasses.replace(
        description.model, control_plugins=()))
    with pytest.raises(ControllerConfigError) as caught:
        controllers_files_for('', bare)
    assert str(caught.value) == (
        f"{description.source}: no controllers file: the parameter 'controllers_file' is not "
        'set and the URDF names none (no gz_ros2_control, ign_ros2_control or '
        "gazebo_ros2_control plugin with <parameters>); give the controller YAML with the "
        "parameter 'controllers_file'")


def test_the_shipped_arm_names_its_controllers_in_its_plugin(repo_root):
    description = load_description(repo_root / 'urdf' / 'three_joint_arm.xacro')
    assert controllers_files_for('', description) == (
        package_share() / 'config' / 'three_joint_arm_controllers.yaml',)


def test_a_given_controllers_file_may_be_a_package_uri_and_a_bad_one_names_the_parameter(
        tmp_path):
    description = _description(tmp_path)
    assert controllers_files_for('package://pan_tilt_sim/config/pan_tilt_control.yaml',
                                 description) == (
        package_share() / 'config' / 'pan_tilt_control.yaml',)
    with pytest.raises(ControllerConfigError,
                       match=r"^the parameter 'controllers_file': resource "
                             r"'package://no_such_package_here/c.yaml': package "
                             r"'no_such_package_here' is not in the ament index"):
        controllers_files_for('package://no_such_package_here/c.yaml', description)


# --- one node's parameters, as --params-file gives them (the spawner's params_file) --------

def test_node_parameters_merge_wildcards_then_the_nodes_own_section_over_files(write_yaml):
    first = write_yaml("""
        /**:
          ros__parameters: {use_sim_time: true, gains: {j: {p: 1.0}}}
        arm:
          ros__parameters: {joints: [j], gains: {j: {d: 2.0}}}
        other:
          ros__parameters: {joints: [k]}
        """, name='first.yaml')
    second = write_yaml("""
        /robot/arm:
          ros__parameters:
            gains.j.p: 5.0
        """, name='second.yaml')
    assert node_parameters([first, second], 'arm') == {
        'use_sim_time': True, 'joints': ['j'], 'gains': {'j': {'p': 5.0, 'd': 2.0}}}
    assert node_parameters([first], 'nobody') == {'use_sim_time': True,
                                                  'gains': {'j': {'p': 1.0}}}


def test_node_parameters_expand_substitutions_and_name_the_file(write_yaml):
    path = write_yaml("""
        arm:
          ros__parameters: {joints: ['$(var prefix)j']}
        """, name='subst.yaml')
    assert node_parameters([path], 'arm', {'prefix': 'left_'}) == {'joints': ['left_j']}
    with pytest.raises(ControllerConfigError, match=r'subst.yaml:3: \$\(var prefix\) is not set'):
        node_parameters([path], 'arm')


# --- hostile or surprising files ------------------------------------------------------------

LAUGHS = 'a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]\n' + ''.join(
    f"a{level}: &a{level} [{', '.join([f'*a{level - 1}'] * 9)}]\n" for level in range(1, 10))


@pytest.mark.parametrize(('text', 'problem'), [
    ('a: &a [*a]\n', ':1: an alias refers to the node that holds it'),
    ('a: &a {type: x, joint: *a}\n', ':1: an alias refers to the node that holds it'),
    ('[' * 500 + ']' * 500 + '\n', ':1: nested deeper than 64 levels'),
    (''.join(f"{'  ' * level}k{level}:\n" for level in range(500)), ': nested deeper than'),
    (LAUGHS, 'its aliases expand it to more than 1,000,000 values'),
], ids=['alias in itself', 'alias in a controller', '500 flow levels', '500 block levels',
        'billion laughs'])
def test_a_hostile_file_is_one_line_naming_it(write_yaml, text, problem):
    path = write_yaml(text)
    with pytest.raises(ControllerConfigError) as raised:
        load_controllers_config(path)
    message = str(raised.value)
    assert message.startswith(f'{path}:')
    assert problem in message
    assert '\n' not in message
    with pytest.raises(ControllerConfigError, match='nested deeper|alias|expand it'):
        node_parameters([path], 'arm_controller')


@pytest.mark.parametrize('device', ['/dev/null', '/dev/zero'])
def test_a_device_is_not_a_regular_file_not_a_missing_one(device):
    with pytest.raises(ControllerConfigError,
                       match=f'controllers file {device}: not a regular file'):
        load_controllers_config(device)


def test_a_fifo_is_refused_without_waiting_for_a_writer(tmp_path):
    fifo = tmp_path / 'controllers.yaml'
    os.mkfifo(fifo)
    with pytest.raises(ControllerConfigError, match=r'not a regular file \(a FIFO\)'):
        load_controllers_config(fifo)


def test_a_16_mb_file_is_refused_by_its_size(write_yaml):
    line = 'c{}: {{type: position_controllers/JointPositionController, joint: pan_joint}}\n'
    path = write_yaml(''.join(line.format(index) for index in range(16 * 1024 * 1024 // 72)))
    with pytest.raises(ControllerConfigError, match=f'{path}: larger than 1048576 bytes'):
        load_controllers_config(path)


ANCHOR_BESIDE_THE_ROBOT = """
    base: &base
      type: position_controllers/JointPositionController
      joint: pan_joint
      pid: {p: 100.0, i: 0.01, d: 10.0}
    my_robot:
      pan_controller: *base
      tilt_controller: {<<: *base, joint: tilt_joint}
    """


def test_a_block_of_controllers_beside_top_level_ones_is_named_in_a_warning(write_yaml):
    path = write_yaml(ANCHOR_BESIDE_THE_ROBOT)
    config = load_controllers_config(path)
    assert [spec.name for spec in config.controllers] == ['base']
    warning, = config.warnings
    assert warning.startswith(f"{path}: top-level key 'my_robot' holds controllers "
                              "('pan_controller', 'tilt_controller') that are not loaded")
    assert "('base')" in warning


def test_the_warning_reaches_the_simulations_start_up_report(write_yaml):
    path = write_yaml(ANCHOR_BESIDE_THE_ROBOT)
    messages = []
    with make_simulation(str(package_share() / 'urdf' / 'pan_tilt.xacro'), str(path), 0.001,
                         logger=_ListLogger(messages)):
        pass
    assert any("top-level key 'my_robot' holds controllers" in line for line in messages)


class _ListLogger:
    """A logger keeping warning lines."""

    def __init__(self, lines):
        self.lines = lines

    def warning(self, message):
        self.lines.append(message)

    def info(self, message):
        pass


def test_one_namespace_key_or_top_level_controllers_alone_warn_of_nothing(repo_root,
                                                                          original_examples):
    assert load_controllers_config(repo_root / 'config' / 'pan_tilt_control.yaml').warnings == ()
    assert load_controllers_config(original_examples / 'joint_controllers.yaml').warnings == ()


def test_several_blocks_of_controllers_and_none_at_the_top_are_an_error(write_yaml):
    path = write_yaml("""
        defaults: &defaults
          pan_controller: {type: position_controllers/JointPositionController, joint: pan_joint}
        my_robot:
          <<: *defaults
          tilt_controller: {type: position_controllers/JointPositionController,
                            joint: tilt_joint}
        """)
    with pytest.raises(ControllerConfigError,
                       match=f"{path}: several top-level keys hold controllers "
                             r"\('defaults', 'my_robot'\)"):
        load_controllers_config(path)


def test_a_ros2_file_names_a_block_of_controllers_it_ignores(write_yaml):
    path = write_yaml("""
        common: &common
          type: position_controllers/JointGroupPositionController
        controller_manager:
          ros__parameters:
            arm_controller: *common
        arm_controller:
          ros__parameters:
            joints: [pan_joint]
        """)
    config = load_controllers_config(path)
    assert [spec.name for spec in config.controllers] == ['arm_controller']
    warning, = config.warnings
    assert warning.startswith(f"{path}: top-level key 'common' holds a controller")
    assert "no 'ros__parameters'" in warning


# --- a controller_manager's own parameters (sim_node in ros2_control_node's place) --------

def test_a_controller_managers_parameters_declare_its_controllers():
    from pan_tilt_sim.model.controller_config import controller_manager_config

    sections = {'forward': {'joints': ['joint1'], 'interface_name': 'position'}}
    config = controller_manager_config(
        {'forward.type': 'forward_command_controller/ForwardCommandController',
         'forward.params_file': '/x.yaml', 'jsb': {'type': 'joint_state_broadcaster/'
                                                          'JointStateBroadcaster'}},
        lambda name: sections.get(name, {}), update_rate=50.0,
        source='the parameters of /controller_manager')
    assert [(spec.name, spec.type) for spec in config.controllers] == [
        ('forward', 'forward_command_controller/ForwardCommandController'),
        ('jsb', 'joint_state_broadcaster/JointStateBroadcaster')]
    forward = config.controllers[0].params
    assert forward['joints'] == ['joint1'] and forward['update_rate'] == 50.0
    assert config.update_rate == 50.0
    assert config.label == 'the parameters of /controller_manager'


def test_a_controller_manager_may_declare_none_and_refuses_a_type_that_is_no_string():
    from pan_tilt_sim.model.controller_config import controller_manager_config

    assert controller_manager_config({}, dict, update_rate=100.0, source='cm').controllers == ()
    with pytest.raises(ControllerConfigError,
                       match="^cm: parameter 'forward.type' must be a string, got 3$"):
        controller_manager_config({'forward.type': 3}, lambda name: {}, update_rate=100.0,
                                  source='cm')


def test_a_launch_argument_left_in_another_nodes_section_does_not_stop_this_node(tmp_path):
    from pan_tilt_sim.model.controller_config import node_parameters

    path = write(tmp_path, 'rrbot_controllers.yaml', """\
        joint_state_broadcaster:
          ros__parameters:
            type: joint_state_broadcaster/JointStateBroadcaster
        forward_position_controller:
          ros__parameters:
            joints: [$(var joint_prefix)1]
        """)
    assert node_parameters([path], 'joint_state_broadcaster') == {
        'type': 'joint_state_broadcaster/JointStateBroadcaster'}
    with pytest.raises(ControllerConfigError, match=r':6: \$\(var joint_prefix\) is not set'):
        node_parameters([path], 'forward_position_controller')
