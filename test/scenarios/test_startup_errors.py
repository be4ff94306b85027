"""Start-up errors: every bad file, parameter or argument gets one line naming it, exit code 2.

Most cases build SimNode in-process (fast) and read the ConfigurationError it
raises: the right kind, one line, naming the file/field/parameter and what is
wrong.  A few run sim_node as a program to prove the contract end to end:
exit code 2, exactly one line on stderr (no traceback, no PyBullet banner, no
rcl log lines) and nothing on stdout -- and the traceback only with
``--ros-args --log-level debug``.
"""

from __future__ import annotations

import os
import pathlib

import pytest
import rclpy
import sim_process
from mobile_fixtures import P3D, ROS2_DIFF_DRIVE, plugin_rover_urdf
from rclpy.parameter import Parameter

from pan_tilt_sim.errors import (
    ConfigurationError,
    ControllerConfigError,
    DescriptionError,
    ParameterError,
)
from pan_tilt_sim.model.world_file import WorldFileError
from pan_tilt_sim.ros.sim_node import SimNode
from pan_tilt_sim.share import package_share

EXIT_CONFIGURATION_ERROR = 2
PAN_TILT_URDF = package_share() / 'urdf' / 'pan_tilt.xacro'
PAN_TILT_YAML = package_share() / 'config' / 'pan_tilt_control.yaml'

_INERTIAL = ('<inertial><mass value="1"/>'
             '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>')
_XACRO_HEAD = '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'



def _link(name: str, mass: str = '1') -> str:
    return (f'<link name="{name}"><inertial><origin xyz="0.1 0 0"/><mass value="{mass}"/>'
            '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>')


def _joint(name: str, parent: str, child: str, kind: str = 'revolute', axis: str = '0 1 0',
           origin: str = '0 0 0.1') -> str:
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{origin}"/><axis xyz="{axis}"/>'
            '<limit lower="-3" upper="3" effort="10" velocity="2"/></joint>')


def _mimicking(joint: str, leader: str) -> str:
    return joint.replace('</joint>', f'<mimic joint="{leader}"/></joint>')


def _robot(*parts: str) -> str:
    return '<?xml version="1.0"?>\n<robot name="r">\n' + '\n'.join(parts) + '\n</robot>\n'


_AB = (_link('a'), _link('b'))
_ABC = (*_AB, _link('c'))

# Files the cases below point at, written into a temporary folder per test.
FILES = {
    'not_xml.urdf': 'hello, this is not XML\n',
    'mjcf.urdf': '<mujoco model="m"/>\n',
    'old.sdf': '<sdf version="1.3"><model name="m"><link name="a"/></model></sdf>\n',
    'two_models.sdf': '<sdf version="1.9"><model name="m"><link name="a"/></model>'
                      '<model name="n"><link name="b"/></model></sdf>\n',
    'ghost_link.sdf': '<sdf version="1.9"><model name="m"><link name="a"/>'
                      '<joint name="j" type="revolute"><parent>a</parent><child>ghost</child>'
                      '</joint></model></sdf>\n',
    'missing_include.sdf': '<sdf version="1.9"><model name="m"><link name="a"/><include>'
                           '<uri>model://no_such_model</uri></include></model></sdf>\n',
    'bad_world.sdf': '<sdf version="1.9"><world name="w"><physics><max_step_size>zero'
                     '</max_step_size></physics></world></sdf>\n',
    'binary.urdf': b'\xff\xfe\x00\x01binary',
    'syntax.xacro': _XACRO_HEAD + '<link name="a">\n</robot>\n',
    'undefined_property.xacro': _XACRO_HEAD + '<link name="${no_such_property}"/>\n</robot>\n',
    'undefined_arg.xacro': _XACRO_HEAD + '<link name="$(arg no_such_arg)"/>\n</robot>\n',
    'no_joints.urdf': '<?xml version="1.0"?>\n<robot name="r"><link name="a"/></robot>\n',
    'fixed.urdf': f'''<?xml version="1.0"?>
<robot name="r">
  <link name="a">{_INERTIAL}</link><link name="b">{_INERTIAL}</link>
  <link name="c">{_INERTIAL}</link>
  <joint name="hinge" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
  <joint name="weld" type="fixed"><parent link="b"/><child link="c"/></joint>
</robot>
''',
    'bad_plugin_namespace.urdf': f'''<?xml version="1.0"?>
<robot name="r">
  <link name="a">{_INERTIAL}</link><link name="b">{_INERTIAL}</link>
  <joint name="hinge" type="continuous"><parent link="a"/><child link="b"/></joint>
  <gazebo><plugin name="gazebo_ros_control" filename="libgazebo_ros_control.so">
    <robotNamespace>/my robot</robotNamespace></plugin></gazebo>
</robot>
''',
    'bad_diff_drive.urdf': plugin_rover_urdf(
        ROS2_DIFF_DRIVE.replace('<wheel_separation>0.3<', '<wheel_separation>wide<')),
    'bad_p3d.urdf': plugin_rover_urdf(ground_truth=P3D.replace('>base_link<', '>chassis<')),
    'weld.yaml': 'weld_controller: {type: effort_controllers/JointEffortController, '
                 'joint: weld}\n',
    'yaml_syntax.yaml': 'a:\n  type: [unclosed\n  joint: pan_joint\n',
    'empty.yaml': '',
    'list.yaml': '- a\n- b\n',
    'no_type.yaml': 'a: {joint: pan_joint}\n',
    'unknown_type.yaml': 'a: {type: foo_controllers/Bar, joint: pan_joint}\n',
    'no_joint.yaml': 'a: {type: position_controllers/JointPositionController}\n',
    'number_joint.yaml': 'a: {type: position_controllers/JointPositionController, joint: 5}\n',
    'unknown_joint.yaml': 'a: {type: position_controllers/JointPositionController, '
                          'joint: elbow_joint}\n',
    'twice.yaml': 'a: {type: position_controllers/JointPositionController, joint: pan_joint}\n'
                  'b: {type: effort_controllers/JointEffortController, joint: pan_joint}\n',
    'negative_rate.yaml': 'j: {type: joint_state_controller/JointStateController, '
                          'publish_rate: -5}\n',
    'zero_rate.yaml': 'j: {type: joint_state_controller/JointStateController, publish_rate: 0}\n',
    'text_rate.yaml': 'j: {type: joint_state_controller/JointStateController, '
                      'publish_rate: fast}\n',
    'text_gain.yaml': 'a: {type: position_controllers/JointPositionController, joint: pan_joint, '
                      'pid: {p: high, i: 0, d: 0}}\n',
    'negative_gain.yaml': 'a: {type: position_controllers/JointPositionController, '
                          'joint: pan_joint, pid: {p: 1, i: 0, d: -2}}\n',
    'negative_clamp.yaml': 'a: {type: position_controllers/JointPositionController, '
                           'joint: pan_joint, pid: {p: 1, i_clamp: -3}}\n',
    'infinite_clamp.yaml': 'a: {type: position_controllers/JointPositionController, '
                           'joint: pan_joint, pid: {p: 1, i: 1, i_clamp_min: .inf}}\n',
    'bad_namespace_key.yaml': 'my robot:\n  a: {type: position_controllers/'
                              'JointPositionController, joint: pan_joint}\n',
    'bad_controller_name.yaml': '"pan controller": {type: position_controllers/'
                                'JointPositionController, joint: pan_joint}\n',
    'plugin_gains.yaml': 'a: {type: position_controllers/JointPositionController, '
                         'joint: pan_joint}\ngazebo_ros_control: {pid_gains: {elbow: {p: 1}}}\n',
    'self_alias.yaml': 'a: &a [*a]\n',
    'deep.yaml': '[' * 500 + ']' * 500 + '\n',
    'laughs.yaml': 'a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]\n' + ''.join(
        f"a{level}: &a{level} [{', '.join([f'*a{level - 1}'] * 9)}]\n" for level in range(1, 10)),
    # Descriptions PyBullet crashes on or cannot integrate, and controllers for their joint j1:
    # a PID on effort (PyBullet's mass matrix is computed for it), or the ideal actuator.
    'j1_pid.yaml': 'c: {type: effort_controllers/JointPositionController, joint: j1, '
                   'pid: {p: 100.0, i: 0.0, d: 1.0}}\n',
    'j1_ideal.yaml': 'c: {type: position_controllers/JointPositionController, joint: j1}\n',
    'long_name.urdf': _robot(*_AB, _joint('j' * 2000, 'a', 'b')),
    'two_parents.urdf': _robot(*_ABC, _joint('j1', 'a', 'b'), _joint('j2', 'a', 'c'),
                               _joint('j3', 'b', 'c')),
    'cycle_off_root.urdf': _robot(*_ABC, _joint('j1', 'a', 'b'), _joint('j2', 'b', 'c'),
                                  _joint('j3', 'c', 'b')),
    'cycle_off_nothing.urdf': _robot(*_ABC, _link('d'), _joint('j1', 'a', 'b'),
                                     _joint('j2', 'c', 'd'), _joint('j3', 'd', 'c')),
    'mimic_cycle.urdf': _robot(*_ABC, _mimicking(_joint('j1', 'a', 'b'), 'j2'),
                               _mimicking(_joint('j2', 'b', 'c'), 'j1')),
    'mimic_of_fixed.urdf': _robot(*_ABC, _joint('j1', 'a', 'b', 'fixed'),
                                  _mimicking(_joint('j2', 'b', 'c'), 'j1')),
    'root_cycle_orphan.urdf': _robot(*_ABC, _joint('j1', 'a', 'b'), _joint('j2', 'b', 'a')),
    'own_parent.urdf': _robot(*_AB, _joint('j1', 'a', 'b'), _joint('j2', 'b', 'b')),
    'joint_twice.urdf': _robot(*_ABC, _joint('j1', 'a', 'b'), _joint('j1', 'b', 'c')),
    'zero_axis.urdf': _robot(*_AB, _joint('j1', 'a', 'b', axis='0 0 0')),
    'tiny_axis.urdf': _robot(*_AB, _joint('j1', 'a', 'b', axis='0 0 1e-300')),
    'planar.urdf': _robot(*_ABC, _joint('j1', 'a', 'b'), _joint('j2', 'b', 'c', 'planar')),
    'negative_mass.urdf': _robot(_link('a'), _link('b', '-1'), _link('c'), _joint('j1', 'a', 'b'),
                                 _joint('j2', 'b', 'c')),
    'huge_mass.urdf': _robot(_link('a'), _link('b', '1e308'), _joint('j1', 'a', 'b')),
    'far_out.urdf': _robot(*_ABC, _joint('j1', 'a', 'b'),
                           _joint('j2', 'b', 'c', origin='1e155 0 0')),
}


def _case(case_id, overrides, error, *expected):
    return pytest.param(overrides, error, expected, id=case_id)


# (overrides, error class, substrings of the message); '{dir}' is the files' folder.
CASES = [
    # Gazebo's drive plugins in the description.
    _case('diff drive plugin element not a number',
          {'robot_description_file': '{dir}/bad_diff_drive.urdf'}, DescriptionError,
          "{dir}/bad_diff_drive.urdf: plugin 'diff_drive' (libgazebo_ros_diff_drive.so): "
          "<wheel_separation> 'wide' is not a number"),
    _case('p3d plugin of a link the robot lacks',
          {'robot_description_file': '{dir}/bad_p3d.urdf'}, DescriptionError,
          "plugin 'ground_truth' (libgazebo_ros_p3d.so): <body_name> 'chassis' is not a link"),
    # The description file.
    _case('description missing', {'robot_description_file': '{dir}/missing.urdf'},
          DescriptionError, '{dir}/missing.urdf', 'no such file'),
    _case('description is a folder', {'robot_description_file': '{dir}'},
          DescriptionError, '{dir}', 'is a directory'),
    _case('description not XML', {'robot_description_file': '{dir}/not_xml.urdf'},
          DescriptionError, '{dir}/not_xml.urdf:1', 'not well-formed XML'),
    _case('description neither URDF nor SDF', {'robot_description_file': '{dir}/mjcf.urdf'},
          DescriptionError, '{dir}/mjcf.urdf', 'not a URDF', '<mujoco>'),
    # SDF robots and worlds.
    _case('SDF version not supported', {'robot_description_file': '{dir}/old.sdf'},
          DescriptionError, '{dir}/old.sdf: <sdf version="1.3">: SDFormat version 1.3 is not '
          'supported'),
    _case('SDF with several models', {'robot_description_file': '{dir}/two_models.sdf'},
          DescriptionError, '{dir}/two_models.sdf: <sdf>: a robot is one top-level <model>, '
          'found 2'),
    _case('SDF joint naming a missing link', {'robot_description_file': '{dir}/ghost_link.sdf'},
          DescriptionError, '{dir}/ghost_link.sdf: <joint name="j">: <child>ghost</child> is '
          'not a link of the model'),
    _case('SDF include of a missing model',
          {'robot_description_file': '{dir}/missing_include.sdf'}, DescriptionError,
          "{dir}/missing_include.sdf: <include><uri>model://no_such_model</uri>: model "
          "'no_such_model' is in no model path"),
    _case('SDF world physics not a number', {'world': '{dir}/bad_world.sdf'},
          WorldFileError, '{dir}/bad_world.sdf: <physics name="">: <max_step_size>zero'),
    _case('description unreadable bytes', {'robot_description_file': '{dir}/binary.urdf'},
          DescriptionError, '{dir}/binary.urdf', 'cannot read'),
    _case('xacro syntax error', {'robot_description_file': '{dir}/syntax.xacro'},
          DescriptionError, '{dir}/syntax.xacro:4', 'not well-formed XML'),
    _case('xacro undefined property',
          {'robot_description_file': '{dir}/undefined_property.xacro'},
          DescriptionError, '{dir}/undefined_property.xacro', 'no_such_property'),
    _case('xacro undefined argument', {'robot_description_file': '{dir}/undefined_arg.xacro'},
          DescriptionError, '{dir}/undefined_arg.xacro', 'no_such_arg'),
    _case('xacro mapping malformed', {'xacro_args': ['no_separator']},
          DescriptionError, 'xacro_args', "'no_separator'", 'name:=value'),
    _case('no joints to control', {'robot_description_file': '{dir}/no_joints.urdf'},
          DescriptionError, '{dir}/no_joints.urdf', 'no movable joints'),
    _case('plugin namespace invalid',
          {'robot_description_file': '{dir}/bad_plugin_namespace.urdf'},
          DescriptionError, '{dir}/bad_plugin_namespace.urdf', "'/my robot'",
          'not a valid ROS namespace'),
    # The controllers file.
    _case('controllers missing', {'controllers_file': '{dir}/missing.yaml'},
          ControllerConfigError, '{dir}/missing.yaml', 'no such file'),
    _case('controllers YAML syntax', {'controllers_file': '{dir}/yaml_syntax.yaml'},
          ControllerConfigError, '{dir}/yaml_syntax.yaml:3', 'YAML syntax error'),
    _case('controllers empty', {'controllers_file': '{dir}/empty.yaml'},
          ControllerConfigError, '{dir}/empty.yaml', 'no controllers'),
    _case('controllers a list', {'controllers_file': '{dir}/list.yaml'},
          ControllerConfigError, '{dir}/list.yaml', 'no controllers'),
    _case('controller without type', {'controllers_file': '{dir}/no_type.yaml'},
          ControllerConfigError, '{dir}/no_type.yaml', 'no controllers', "'type'"),
    _case('controller type unknown', {'controllers_file': '{dir}/unknown_type.yaml'},
          ControllerConfigError, 'a.type', "'foo_controllers/Bar'",
          'supported: ackermann_steering_controller/AckermannSteeringController',
          'diff_drive_controller/DiffDriveController',
          'effort_controllers/JointEffortController',
          'position_controllers/JointPositionController'),
    _case('controller without joint', {'controllers_file': '{dir}/no_joint.yaml'},
          ControllerConfigError, '{dir}/no_joint.yaml', 'a.joint', 'missing'),
    _case('controller joint not a name', {'controllers_file': '{dir}/number_joint.yaml'},
          ControllerConfigError, 'a.joint', '5 must be a string'),
    _case('joint not in the URDF', {'controllers_file': '{dir}/unknown_joint.yaml'},
          ControllerConfigError, 'a.joint', "'elbow_joint'", 'pan_joint, tilt_joint'),
    _case('fixed joint commanded', {'robot_description_file': '{dir}/fixed.urdf',
                                    'controllers_file': '{dir}/weld.yaml'},
          ControllerConfigError, '{dir}/weld.yaml', 'weld_controller', "'weld'", 'fixed joint'),
    _case('joint claimed twice', {'controllers_file': '{dir}/twice.yaml'},
          ControllerConfigError, '{dir}/twice.yaml', "'pan_joint'", "both 'a' and 'b'"),
    _case('publish_rate negative', {'controllers_file': '{dir}/negative_rate.yaml'},
          ControllerConfigError, 'j.publish_rate', '-5', '> 0'),
    _case('publish_rate zero', {'controllers_file': '{dir}/zero_rate.yaml'},
          ControllerConfigError, 'j.publish_rate', '0', '> 0'),
    _case('publish_rate text', {'controllers_file': '{dir}/text_rate.yaml'},
          ControllerConfigError, 'j.publish_rate', "'fast'"),
    _case('PID gain text', {'controllers_file': '{dir}/text_gain.yaml'},
          ControllerConfigError, 'a.pid.p', "'high' must be a finite number"),
    _case('PID gain negative', {'controllers_file': '{dir}/negative_gain.yaml'},
          ControllerConfigError, 'a.pid', 'd: -2', '>= 0'),
    _case('PID clamp negative', {'controllers_file': '{dir}/negative_clamp.yaml'},
          ControllerConfigError, 'a.pid', 'i_clamp: -3'),
    _case('PID clamp pinned at infinity', {'controllers_file': '{dir}/infinite_clamp.yaml'},
          ControllerConfigError, 'a.pid', 'i_clamp_min (inf) must be < inf'),
    _case('namespace key invalid', {'controllers_file': '{dir}/bad_namespace_key.yaml'},
          ControllerConfigError, '{dir}/bad_namespace_key.yaml', "'my robot'",
          'not a valid ROS namespace'),
    _case('controller name invalid', {'controllers_file': '{dir}/bad_controller_name.yaml'},
          ControllerConfigError, "'pan controller'", 'not a valid ROS name'),
    _case('controllers alias inside its anchor', {'controllers_file': '{dir}/self_alias.yaml'},
          ControllerConfigError, '{dir}/self_alias.yaml:1: an alias refers to the node'),
    _case('controllers nested 500 levels', {'controllers_file': '{dir}/deep.yaml'},
          ControllerConfigError, '{dir}/deep.yaml:1: nested deeper than 64 levels'),
    _case('controllers billion laughs', {'controllers_file': '{dir}/laughs.yaml'},
          ControllerConfigError, '{dir}/laughs.yaml:', 'aliases expand it to more than'),
    _case('controllers /dev/null', {'controllers_file': '/dev/null'},
          ControllerConfigError, 'controllers file /dev/null: not a regular file'),
    _case('controllers /dev/zero', {'controllers_file': '/dev/zero'},
          ControllerConfigError, 'controllers file /dev/zero: not a regular file'),
    # Parameters: values.
    _case('time_step zero', {'time_step': 0.0}, ParameterError, "'time_step'", '> 0', '0.0'),
    _case('time_step negative', {'time_step': -0.001}, ParameterError, "'time_step'", '-0.001'),
    _case('time_step above 0.1', {'time_step': 0.2}, ParameterError, "'time_step'", '<= 0.1'),
    _case('time_step NaN', {'time_step': float('nan')}, ParameterError, "'time_step'", 'nan'),
    _case('real_time_factor negative', {'real_time_factor': -1.0},
          ParameterError, "'real_time_factor'", '>= 0', '-1.0'),
    _case('real_time_factor infinite', {'real_time_factor': float('inf')},
          ParameterError, "'real_time_factor'", 'finite', 'inf'),
    _case('real_time_factor NaN', {'real_time_factor': float('nan')},
          ParameterError, "'real_time_factor'", 'finite', 'nan'),
    _case('real_time_factor 1e308', {'real_time_factor': 1e308},
          ParameterError, "'real_time_factor' must be <= 1000", '1e+308'),
    _case('time_step below a microsecond', {'time_step': 5e-324},
          ParameterError, "'time_step' must be >= 1e-06 s", '5e-324'),
    _case('solver_iterations zero', {'solver_iterations': 0},
          ParameterError, "'solver_iterations' must be a whole number from 1 to 10000, got 0"),
    _case('erp above 1', {'erp': 1.5}, ParameterError, "'erp' must be from 0 to 1", '1.5'),
    _case('cfm negative', {'cfm': -0.1}, ParameterError, "'cfm' must be >= 0, got -0.1"),
    _case('contact_slop NaN', {'contact_slop': float('nan')},
          ParameterError, "'contact_slop' must be a finite number", 'nan'),
    _case('split_impulse a string', {'split_impulse': 'yes'},
          ParameterError, "'split_impulse' must be a bool", "'yes'"),
    _case('robot_namespace starts with a digit', {'robot_namespace': '1robot'},
          ParameterError, "'robot_namespace'", "'1robot'", 'not a valid ROS namespace'),
    _case('robot_namespace with a space', {'robot_namespace': 'my robot'},
          ParameterError, "'robot_namespace'", "'my robot'"),
    # Parameters: types (integers for doubles are accepted: test_sim_node.py).
    _case('time_step a string', {'time_step': 'fast'},
          ParameterError, "'time_step' must be a double", "string 'fast'"),
    _case('time_step a bool', {'time_step': True},
          ParameterError, "'time_step' must be a double", 'bool True'),
    _case('paused an integer', {'paused': 1},
          ParameterError, "'paused' must be a bool", 'integer 1'),
    _case('gui a string', {'gui': 'maybe'}, ParameterError, "'gui' must be a bool"),
    _case('xacro_args a string', {'xacro_args': 'a:=1'},
          ParameterError, "'xacro_args' must be a string array", "string 'a:=1'"),
    _case('robot_description_file an integer', {'robot_description_file': 5},
          ParameterError, "'robot_description_file' must be a string", 'integer 5'),
    _case('robot_namespace a list', {'robot_namespace': ['a', 'b']},
          ParameterError, "'robot_namespace' must be a string"),
    # Start positions.
    _case('initial_positions not joint:=value', {'initial_positions': ['pan_joint=1']},
          ParameterError, "parameter 'initial_positions'", "'pan_joint=1' is not of the form"),
    _case('initial_positions not a number', {'initial_positions': ['pan_joint:=left']},
          ParameterError, "parameter 'initial_positions'", "'left' is not a finite number"),
    _case('initial_positions unknown joint', {'initial_positions': ['elbow:=1']},
          ParameterError, "parameter 'initial_positions': 'elbow' is not a movable joint",
          'pan_joint, tilt_joint'),
    _case('initial_positions a string', {'initial_positions': 'pan_joint:=1'},
          ParameterError, "'initial_positions' must be a string array"),
    # Descriptions PyBullet cannot take (those it crashes on: as a program, below).
    _case('cycle off nothing', {'robot_description_file': '{dir}/cycle_off_nothing.urdf',
                                'controllers_file': '{dir}/j1_pid.yaml'},
          DescriptionError, '{dir}/cycle_off_nothing.urdf', "'j3', 'j2' form a cycle"),
    _case('mimic cycle', {'robot_description_file': '{dir}/mimic_cycle.urdf',
                          'controllers_file': '{dir}/j1_ideal.yaml'},
          DescriptionError, '{dir}/mimic_cycle.urdf: mimic joints form a cycle: j1 -> j2 -> j1'),
    _case('mimic of a fixed joint', {'robot_description_file': '{dir}/mimic_of_fixed.urdf',
                                     'controllers_file': '{dir}/j1_ideal.yaml'},
          DescriptionError, "{dir}/mimic_of_fixed.urdf: joint 'j2' mimics 'j1', which is not a "
          'movable joint of this robot'),
    _case('zero axis, PID', {'robot_description_file': '{dir}/zero_axis.urdf',
                             'controllers_file': '{dir}/j1_pid.yaml'},
          DescriptionError, "joint 'j1'", '<axis xyz="0 0 0"> has no direction'),
    _case('zero axis, ideal actuator', {'robot_description_file': '{dir}/zero_axis.urdf',
                                        'controllers_file': '{dir}/j1_ideal.yaml'},
          DescriptionError, "joint 'j1'", '<axis xyz="0 0 0"> has no direction'),
    _case('near-zero axis, PID', {'robot_description_file': '{dir}/tiny_axis.urdf',
                                  'controllers_file': '{dir}/j1_pid.yaml'},
          DescriptionError, "joint 'j1'", '<axis xyz="0 0 1e-300"> has no direction'),
    _case('planar joint, PID on another', {'robot_description_file': '{dir}/planar.urdf',
                                           'controllers_file': '{dir}/j1_pid.yaml'},
          DescriptionError, "joint 'j2'", 'planar is not simulated'),
    _case('negative mass, PID', {'robot_description_file': '{dir}/negative_mass.urdf',
                                 'controllers_file': '{dir}/j1_pid.yaml'},
          DescriptionError, "link 'b'", '<mass value="-1"> must be >= 0 kg'),
    _case('mass 1e308, ideal actuator', {'robot_description_file': '{dir}/huge_mass.urdf',
                                         'controllers_file': '{dir}/j1_ideal.yaml'},
          DescriptionError, "link 'b'", '<mass value="1e308"> is above 1e+06 kg'),
    _case('unstable from the first step', {'robot_description_file': '{dir}/far_out.urdf',
                                           'controllers_file': '{dir}/j1_ideal.yaml'},
          DescriptionError, '{dir}/far_out.urdf', "joint 'j2' has a non-finite position",
          "likely cause: joint 'j2' <origin xyz> 1e+155"),
    # gazebo_ros_control's PID gains.
    _case('pid_gains for a joint the robot lacks', {'controllers_file': '{dir}/plugin_gains.yaml'},
          ControllerConfigError, '{dir}/plugin_gains.yaml: gazebo_ros_control.pid_gains.elbow: ',
          'not a movable joint'),
]


@pytest.fixture
def files(tmp_path: pathlib.Path) -> pathlib.Path:
    for name, content in FILES.items():
        path = tmp_path / name
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)
    return tmp_path


def _fill(value, directory):
    if isinstance(value, str):
        return value.replace('{dir}', str(directory))
    if isinstance(value, list):
        return [_fill(item, directory) for item in value]
    return value


def _overrides(values: dict) -> list[Parameter]:
    values = {'robot_description_file': str(PAN_TILT_URDF),
              'controllers_file': str(PAN_TILT_YAML), 'real_time_factor': 0.0, **values}
    return [Parameter(name, value=value) for name, value in values.items()]


@pytest.mark.parametrize(('overrides', 'error', 'expected'), CASES)
def test_a_bad_start_up_input_raises_one_line_naming_it(context, files, overrides, error,
                                                        expected):
    overrides = {name: _fill(value, files) for name, value in overrides.items()}
    with pytest.raises(ConfigurationError) as raised:
        node = SimNode(context=context, parameter_overrides=_overrides(overrides))
        node.destroy_node()
    message = str(raised.value)
    assert isinstance(raised.value, error), f'{type(raised.value).__name__}: {message}'
    assert '\n' not in message
    for part in expected:
        assert _fill(part, files) in message


def test_a_fifo_or_a_16_mb_controllers_file_is_refused_at_once(context, tmp_path):
    fifo = tmp_path / 'fifo.yaml'
    os.mkfifo(fifo)
    huge = tmp_path / 'huge.yaml'
    huge.write_text('c: {type: position_controllers/JointPositionController, joint: pan_joint}\n'
                    * (16 * 1024 * 1024 // 70))
    for path, problem in ((fifo, 'not a regular file (a FIFO)'), (huge, 'larger than')):
        with pytest.raises(ControllerConfigError) as raised:
            SimNode(context=context, parameter_overrides=_overrides(
                {'controllers_file': str(path)}))
        assert str(raised.value).startswith(f'controllers file {path}: {problem}')


@pytest.mark.parametrize('overrides', [
    {'time_step': -1.0},  # the first parameter read
    {'controllers_file': '/no/such/controllers.yaml'},  # after the description
    {'simulation_interfaces.namespace': '9sim'},  # the last thing built
], ids=['parameters', 'controllers file', 'simulation_interfaces'])
def test_a_start_up_error_leaves_no_node_behind(context, overrides):
    # An in-process caller (a test, an embedding program) gets the error and
    # nothing else: no sim_node or controller_manager left on its context, even
    # while it holds the error (whose traceback holds the half-built node).
    probe = rclpy.create_node('probe', context=context)
    try:
        with pytest.raises(ConfigurationError) as raised:
            SimNode(context=context, parameter_overrides=_overrides(overrides))
        assert sorted(probe.get_node_names()) == ['probe'], raised.value
    finally:
        probe.destroy_node()


@pytest.mark.skipif(os.geteuid() == 0, reason='root reads files whatever their mode')
def test_an_unreadable_description_names_the_file(context, files):
    path = files / 'fixed.urdf'
    path.chmod(0)
    with pytest.raises(DescriptionError, match='cannot read'):
        SimNode(context=context, parameter_overrides=_overrides(
            {'robot_description_file': str(path)}))


# --- as a program: exit code 2, one line, nothing else ----------------------------------

def _assert_one_line_exit_2(result, *expected: str) -> str:
    assert result.returncode == EXIT_CONFIGURATION_ERROR, result.stderr
    assert result.stdout == ''
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    line = lines[0]
    assert line.startswith('sim_node: error: ')
    for part in expected:
        assert part in line
    return line


@pytest.mark.parametrize(('ros_args', 'expected'), [
    pytest.param(['-p', 'time_step:=fast'], ["parameter 'time_step' must be a double"],
                 id='wrong parameter type'),
    pytest.param(['-p', 'paused:=1'], ["parameter 'paused' must be a bool"],
                 id='integer for a bool'),
    pytest.param(['-p', 'robot_description_file:={dir}/syntax.xacro'],
                 ['{dir}/syntax.xacro:4', 'not well-formed'], id='xacro syntax error'),
    pytest.param(['-p', 'robot_description_file:={dir}/fixed.urdf',
                  '-p', 'controllers_file:={dir}/weld.yaml'], ["'weld'", 'fixed joint'],
                 id='fixed joint (after PyBullet loaded the robot)'),
    pytest.param(['-p', 'robot_description_file:={dir}/bad_diff_drive.urdf'],
                 ["plugin 'diff_drive' (libgazebo_ros_diff_drive.so): <wheel_separation>"],
                 id='diff drive plugin element not a number'),
    pytest.param(['-p', 'controllers_file:={dir}/bad_controller_name.yaml'],
                 ["'pan controller'"], id='controller name not a ROS name'),
    pytest.param(['-p', 'controllers_file:={dir}/laughs.yaml'],
                 ['{dir}/laughs.yaml:', 'aliases expand it'], id='billion laughs'),
    pytest.param(['-p', "initial_positions:=['tilt_joint:=-2.0', 'roll:=1']"],
                 ["parameter 'initial_positions': 'roll' is not a movable joint"],
                 id='initial position of an unknown joint (after PyBullet loaded the robot)'),
    # Descriptions PyBullet crashes on (segmentation fault, double free): refused before it.
    *(pytest.param(['-p', f'robot_description_file:={{dir}}/{urdf}',
                    '-p', 'controllers_file:={dir}/j1_ideal.yaml'], [f'{{dir}}/{urdf}', *parts],
                   id=case) for case, urdf, parts in (
        ('a name of 2000 characters', 'long_name.urdf',
         ['the name is 2000 bytes long', 'at most 1023']),
        ('two joints with one child', 'two_parents.urdf',
         ["link 'c' is the child of two joints, 'j2' and 'j3'"]),
        ('a cycle off the root', 'cycle_off_root.urdf',
         ["link 'b' is the child of two joints, 'j1' and 'j3'"]),
        ('a cycle through the root and an orphan link', 'root_cycle_orphan.urdf',
         ["joints 'j2', 'j1' form a cycle (b -> a -> b)"]),
        ('a joint whose parent is its child', 'own_parent.urdf',
         ["joint 'j2': link 'b' is both its parent and its child"]),
        ('the same joint twice', 'joint_twice.urdf', ["joint 'j1' is declared twice"]))),
])
def test_the_program_prints_one_line_and_exits_2(files, ros_args, expected):
    result = sim_process.run(*(_fill(arg, files) for arg in ros_args))
    _assert_one_line_exit_2(result, *(_fill(part, files) for part in expected))


@pytest.mark.parametrize(('ros_args', 'expected'), [
    pytest.param(['-p', 'time_step'], ["'-p time_step'"], id='override without :='),
    pytest.param(['--no-such-flag'], ["unknown ROS argument '--no-such-flag'"],
                 id='unknown flag'),
    pytest.param(['-r', '__ns:=bad//ns'], ["'-r __ns:=bad//ns'", 'found: bad//ns'],
                 id='invalid namespace remap'),
    pytest.param(['--params-file', '{dir}/missing.yaml'], ['{dir}/missing.yaml'],
                 id='missing params file'),
    pytest.param(['--log-level', 'loud'], ["'--log-level loud'", 'severity'],
                 id='unknown log level'),
])
def test_malformed_ros_arguments_get_one_line_not_rcl_noise(files, ros_args, expected):
    result = sim_process.run(*(_fill(arg, files) for arg in ros_args))
    line = _assert_one_line_exit_2(result, 'ROS arguments: ', *(_fill(p, files) for p in expected))
    assert '[rcl]' not in line and '.c:' not in line


def test_log_level_debug_adds_the_traceback_before_the_line():
    result = sim_process.run('-p', 'time_step:=0', '--log-level', 'debug')
    assert result.returncode == EXIT_CONFIGURATION_ERROR
    assert 'Traceback (most recent call last)' in result.stderr
    assert 'ParameterError' in result.stderr
    ours = [line for line in result.stderr.splitlines() if not line.startswith('[DEBUG]')]
    assert ours[-1] == "sim_node: error: parameter 'time_step' must be > 0 and <= 0.1 s, got 0.0"
