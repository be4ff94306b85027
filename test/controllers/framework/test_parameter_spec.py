"""parameter_spec: a controller's YAML checked against its declared parameters."""

import math

import pytest

from pan_tilt_sim.controllers.framework.parameter_spec import (
    BOOL,
    DOUBLE,
    INT,
    REQUIRED,
    STRING,
    STRING_ARRAY,
    Param,
    ParameterSpec,
    bounds,
    fixed_size,
    gt,
    load_parameters,
    not_empty,
    one_of,
    unique,
)
from pan_tilt_sim.errors import ControllerConfigError

SPEC = ParameterSpec([
    Param('joints', STRING_ARRAY, REQUIRED, 'The joints.', (not_empty(), unique())),
    Param('wheel_separation', DOUBLE, 0.0, 'Distance between the wheels (m).', (gt(-1.0),)),
    Param('wheels_per_side', INT, 1, 'Wheels on each side.', (bounds(1, 8),)),
    Param('open_loop', BOOL, False, 'Odometry from commands.'),
    Param('mode', STRING, 'fast', 'How.', (one_of('fast', 'slow'),)),
    Param('pose_covariance', STRING_ARRAY, None, 'Six entries.', (fixed_size(2),)),
    Param('limits.max_velocity', DOUBLE, math.nan, 'Upper bound (NaN: none).', finite=False),
    Param('gains.__map_joints.p', DOUBLE, None, 'Proportional gain.', (gt(-1e-12),),
          tunable=True),
    Param('constraints.__map_joints.goal', DOUBLE, 0.0, 'Goal tolerance.'),
])


def load(**params):
    return load_parameters(SPEC, {'joints': ['left', 'right'], **params}, 'base', 'file.yaml')


def test_defaults_fill_what_is_not_given():
    loaded = load()
    assert loaded.values['wheel_separation'] == 0.0
    assert loaded.values['wheels_per_side'] == 1
    assert loaded.values['open_loop'] is False
    assert math.isnan(loaded.get('limits.max_velocity'))
    assert loaded.values['constraints'] == {'left': {'goal': 0.0}, 'right': {'goal': 0.0}}
    assert loaded.warnings == []


def test_an_optional_parameter_without_default_stays_absent():
    loaded = load()
    assert 'pose_covariance' not in loaded.values
    assert 'gains' not in loaded.values


def test_given_values_are_kept_nested_as_in_the_yaml():
    loaded = load(gains={'left': {'p': 2}}, limits={'max_velocity': 1.5})
    assert loaded.values['gains'] == {'left': {'p': 2.0}}
    assert isinstance(loaded.values['gains']['left']['p'], float)
    assert loaded.get('limits.max_velocity') == 1.5


@pytest.mark.parametrize(('params', 'field', 'problem'), [
    ({'joints': None}, 'joints', 'missing: The joints'),
    ({'joints': []}, 'joints', 'must not be empty'),
    ({'joints': ['a', 'a']}, 'joints', "'a' is named more than once"),
    ({'joints': 'left'}, 'joints', 'must be a list of strings'),
    ({'wheel_separation': 'wide'}, 'wheel_separation', 'must be a finite number'),
    ({'wheel_separation': math.inf}, 'wheel_separation', 'must be a finite number'),
    ({'wheel_separation': True}, 'wheel_separation', 'must be a finite number'),
    ({'wheel_separation': -2.0}, 'wheel_separation', '-2.0 must be > -1'),
    ({'wheels_per_side': 1.5}, 'wheels_per_side', 'must be an integer'),
    ({'wheels_per_side': 9}, 'wheels_per_side', '9 must be in [1, 8]'),
    ({'open_loop': 1}, 'open_loop', 'must be true or false'),
    ({'mode': 'medium'}, 'mode', "'medium' must be one of fast, slow"),
    ({'pose_covariance': ['a']}, 'pose_covariance', 'must have 2 elements, has 1'),
    ({'gains': {'left': {'p': -1.0}}}, 'gains.left.p', '-1.0 must be > -1e-12'),
    ({'gains': {'middle': {'p': 1.0}}}, 'gains.middle', "'middle' is not one of this "
     "controller's joints (left, right)"),
    ({'gains': [1.0]}, 'gains', 'expected a mapping'),
])
def test_a_wrong_value_names_the_file_the_controller_and_the_field(params, field, problem):
    with pytest.raises(ControllerConfigError) as err:
        load(**params)
    message = str(err.value)
    assert message.startswith(f'file.yaml: base.{field}: '), message
    assert problem in message, message
    assert '\n' not in message


def test_a_misspelt_key_is_named_with_the_closest_known_one():
    loaded = load(wheel_seperation=0.4)
    assert loaded.warnings == ['file.yaml: base.wheel_seperation: unknown parameter, ignored '
                               "(did you mean 'wheel_separation'?)"]
    assert 'wheel_seperation' not in loaded.values
    assert loaded.values['wheel_separation'] == 0.0


def test_a_misspelt_nested_key_is_named_with_the_closest_known_one():
    loaded = load(gains={'left': {'pp': 1.0}})
    assert loaded.warnings == ['file.yaml: base.gains.left.pp: unknown parameter, ignored '
                               "(did you mean 'gains.left.p'?)"]


def test_an_unknown_key_far_from_every_known_one_is_still_named():
    loaded = load(xyzzy=1)
    assert loaded.warnings == ['file.yaml: base.xyzzy: unknown parameter, ignored']


def test_keys_every_ros2_control_controller_takes_are_neither_values_nor_warnings():
    loaded = load(type='x/Y', update_rate=100, use_sim_time=True, is_async=False)
    assert loaded.warnings == []
    assert 'update_rate' not in loaded.values


def test_an_empty_section_the_spec_has_is_not_a_warning():
    assert load(gains={}).warnings == []


def test_a_parameter_that_is_not_simulated_is_named_when_it_asks_for_something():
    spec = SPEC.extend(Param('open_loop_control', BOOL, False, 'Plan open loop.',
                             simulated=False))
    quiet = load_parameters(spec, {'joints': ['a'], 'open_loop_control': False}, 'c')
    assert quiet.warnings == []
    loud = load_parameters(spec, {'joints': ['a'], 'open_loop_control': True}, 'c')
    assert loud.warnings == ['c.open_loop_control: True is accepted but not simulated; '
                             'it has no effect here']


def test_the_tunable_entries_are_listed():
    assert [param.name for param in SPEC.tunable()] == ['gains.__map_joints.p']


def test_a_spec_refuses_an_entry_declared_twice_and_an_unknown_type():
    with pytest.raises(ValueError, match='declared twice'):
        ParameterSpec([Param('a', INT), Param('a', INT)])
    with pytest.raises(ValueError, match='unknown parameter type'):
        Param('a', 'float')


def test_extend_replaces_and_without_removes():
    spec = SPEC.extend(Param('mode', STRING, 'slow')).without('open_loop')
    assert spec['mode'].default == 'slow'
    assert 'open_loop' not in spec
    assert len(spec) == len(SPEC) - 1


ONE_JOINT_SPEC = ParameterSpec([
    Param('joint', STRING, REQUIRED, 'The joint.', (not_empty(),)),
    Param('gains.__map_joint.p', DOUBLE, None, 'Proportional gain.'),
])


def test_a_map_over_a_string_parameter_stands_for_that_one_string():
    loaded = load_parameters(ONE_JOINT_SPEC, {'joint': 'finger', 'gains': {'finger': {'p': 3}}},
                             'gripper', 'file.yaml')
    assert loaded.values['gains'] == {'finger': {'p': 3.0}}
    assert loaded.warnings == []
    with pytest.raises(ControllerConfigError, match=r"^file\.yaml: gripper\.gains\.thumb: "
                                                    r"'thumb' is not one of this controller's "
                                                    r'joint \(finger\)$'):
        load_parameters(ONE_JOINT_SPEC, {'joint': 'finger', 'gains': {'thumb': {'p': 3}}},
                        'gripper', 'file.yaml')


def test_the_example_holds_required_entries_and_optional_ones_with_an_example():
    spec = ParameterSpec([
        Param('gpios', STRING_ARRAY, REQUIRED, 'gpios', example=['io']),
        Param('sensor_name', STRING, '', 'one of two', example='fts'),
        Param('frame_id', STRING, '', 'no example'),
        Param('command_interfaces.__map_gpios.interfaces', STRING_ARRAY, [], 'per gpio',
              example=['out']),
    ])
    assert spec.example() == {'gpios': ['io'], 'sensor_name': 'fts',
                              'command_interfaces': {'io': {'interfaces': ['out']}}}
