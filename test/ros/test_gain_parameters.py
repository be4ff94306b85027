"""Live PID tuning: <controller>.pid.{p,i,d,i_clamp_max,i_clamp_min,antiwindup} parameters."""

import math
import re

import pytest
from node_harness import sim_node
from rclpy.parameter import Parameter

from pan_tilt_sim.controllers.toolbox.pid import GainsError, PidGains
from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.ros.gain_parameters import FIELDS, apply_fields, field_values

PAN = 'joint1_position_controller'
TILT = 'joint2_position_controller'
# The pan/tilt example's pan joint: damping 50 N m s/rad, friction 1 N m, velocity limit
# 0.1 rad/s, D 10.
DAMPING, FRICTION, RAMP_SPEED, D_GAIN = 50.0, 1.0, 0.1, 10.0


def ramp_lag(p: float) -> float:
    """Return the pan's steady lag behind a 0.1 rad/s setpoint ramp, by hand.

    At constant speed v the effort p * lag - d * v (derivative on the measured
    velocity) balances damping * v + friction; the integral term (i = 0.01)
    adds well under 1 % over a few seconds.
    """
    return (DAMPING * RAMP_SPEED + FRICTION + D_GAIN * RAMP_SPEED) / p


# --- pure -----------------------------------------------------------------------

@pytest.mark.parametrize('gains', [PidGains(p=1.0, i_clamp_min=-3.0, i_clamp_max=3.0),
                                   PidGains(i_clamp_min=-1.0, i_clamp_max=2.0),
                                   PidGains(p=2.0, antiwindup=True)])
def test_every_pid_has_the_same_six_parameters_whatever_its_gains(gains):
    # As control_toolbox's PidROS: the names never depend on the values.
    values = field_values(gains)
    assert tuple(values) == FIELDS == ('p', 'i', 'd', 'i_clamp_max', 'i_clamp_min',
                                       'antiwindup')
    assert (values['i_clamp_min'], values['i_clamp_max']) == (gains.i_clamp_min,
                                                               gains.i_clamp_max)
    assert apply_fields(PidGains(), values) == gains


@pytest.mark.parametrize('updates', [{'p': -1.0}, {'d': math.nan}, {'i': math.inf},
                                     {'i_clamp_min': 1.0, 'i_clamp_max': -1.0},
                                     {'i_clamp_max': math.nan}, {'antiwindup': 1.0}])
def test_invalid_gains_are_refused(updates):
    with pytest.raises(GainsError):
        apply_fields(PidGains(), updates)


# --- on the node ----------------------------------------------------------------

def test_gains_are_parameters_initialised_from_the_yaml():
    with sim_node() as harness:
        node = harness.node
        values = {field: node.get_parameter(f'{PAN}.pid.{field}').value for field in FIELDS}
        assert sorted(harness.node.gain_parameters.parameter_names()) == sorted(
            f'{controller}.pid.{field}' for controller in (PAN, TILT) for field in FIELDS)
    # The YAML gives p, i, d; the integral is bounded by the URDF effort limit (300).
    assert values == {'p': 100.0, 'i': 0.01, 'd': 10.0, 'i_clamp_max': 300.0,
                      'i_clamp_min': -300.0, 'antiwindup': False}


def test_a_gain_set_live_changes_the_step_response_as_computed_by_hand():
    with sim_node() as harness:
        controller = harness.simulation.controller(PAN)
        start = harness.command_position(PAN, 1.0)
        harness.run_until_sim_time(start + 3.0)
        lag_before = controller.setpoint - harness.simulation.joint_positions()['pan_joint']

        # Held while the service call goes round, so p changes at a known sim
        # time (at factor 0 a batch is ~0.5 s of sim time).
        harness.node.set_paused(True)
        results = harness.set_parameters(**{f'{PAN}.pid.p': 50})  # an integer: accepted
        harness.node.set_paused(False)
        assert results[0].successful, results[0].reason
        assert controller.pid.gains.p == 50.0

        # The lag settles with time constant (damping + d) / p = 1.2 s; the ramp
        # ends at start + 10 s, and a batch may overshoot the target by ~0.5 s.
        harness.run_until_sim_time(start + 8.5)
        lag_after = controller.setpoint - harness.simulation.joint_positions()['pan_joint']
    assert lag_before == pytest.approx(ramp_lag(100.0), rel=0.05)  # 0.07 rad
    assert lag_after == pytest.approx(ramp_lag(50.0), rel=0.05)  # 0.14 rad


def test_a_live_change_keeps_the_integral_term():
    with sim_node() as harness:
        controller = harness.simulation.controller(PAN)
        start = harness.command_position(PAN, 1.0)
        harness.run_until_sim_time(start + 2.0)
        assert harness.set_parameters(paused=True)[0].successful
        integral = controller.pid.integral_term
        assert integral > 0.0
        results = harness.set_parameters(**{f'{PAN}.pid.p': 60.0, f'{PAN}.pid.d': 5.0})
        assert all(result.successful for result in results)
        assert controller.pid.integral_term == integral
        assert (controller.pid.gains.p, controller.pid.gains.d) == (60.0, 5.0)


@pytest.mark.parametrize(('field', 'value', 'reason'), [
    ('p', -1.0, r"'joint1_position_controller.pid.p'.*>= 0"),
    ('d', -3, r"'joint1_position_controller.pid.d'.*>= 0"),
    ('i_clamp_max', -400.0, r"'joint1_position_controller.pid.\*'.*greater than"),
    ('antiwindup', 'yes', r"'joint1_position_controller.pid.antiwindup' must be a bool"),
    ('i', 'fast', r"'joint1_position_controller.pid.i' must be a double"),
    ('p', math.nan, r"'joint1_position_controller.pid.p'.*finite"),
])
def test_invalid_values_are_refused_with_a_reason_and_change_nothing(field, value, reason):
    with sim_node() as harness:
        controller = harness.simulation.controller(PAN)
        before = controller.pid.gains
        results = harness.set_parameters(**{f'{PAN}.pid.{field}': value})
        assert not results[0].successful
        assert re.search(reason, results[0].reason), results[0].reason
        assert controller.pid.gains == before
        assert harness.node.get_parameter(f'{PAN}.pid.{field}').value == field_values(
            before)[field]


@pytest.mark.parametrize('own', [{'paused': True}, {'real_time_factor': 0.5}])
def test_a_refused_atomic_change_applies_nothing_not_even_the_valid_part(own):
    # The gain is refused, so `paused` / `real_time_factor` must not change
    # either: in the node, in its pacing and in the parameter.
    with sim_node() as harness:
        node = harness.node
        name, value = next(iter(own.items()))
        before = node.get_parameter(name).value
        result = node.set_parameters_atomically([
            Parameter(name, value=value), Parameter(f'{PAN}.pid.p', value=-1.0)])
        assert not result.successful
        assert node.get_parameter(name).value == before
        assert node.paused is False
        assert node.real_time_factor == 0.0
        assert harness.simulation.controller(PAN).pid.gains.p == 100.0
        accepted = node.set_parameters_atomically([
            Parameter(name, value=value), Parameter(f'{PAN}.pid.p', value=60.0)])
        assert accepted.successful
        assert node.get_parameter(name).value == value
        assert (node.paused, node.real_time_factor) == (
            own.get('paused', False), own.get('real_time_factor', 0.0))
        assert harness.simulation.controller(PAN).pid.gains.p == 60.0


def test_the_core_runtime_parameters_still_work_beside_the_gains():
    with sim_node() as harness:
        results = harness.set_parameters(real_time_factor=-1.0)
        assert not results[0].successful and 'real_time_factor' in results[0].reason
        results = harness.set_parameters(**{'real_time_factor': 2.0, f'{TILT}.pid.p': 80.0})
        assert all(result.successful for result in results)
        assert harness.simulation.controller(TILT).pid.gains.p == 80.0


def test_a_negative_gain_given_at_start_up_is_a_configuration_error():
    with pytest.raises(ParameterError, match=rf"'{PAN}.pid.p'.*>= 0"), \
            sim_node(**{f'{PAN}.pid.p': -5.0}):
        pass


def test_a_gain_given_at_start_up_replaces_the_yaml_one():
    with sim_node(**{f'{TILT}.pid.d': 20}) as harness:
        assert harness.simulation.controller(TILT).pid.gains.d == 20.0


def test_multi_joint_controllers_get_one_set_of_gains_per_joint(repo_root):
    model = str(repo_root / 'urdf' / 'three_joint_arm.xacro')
    controllers = str(repo_root / 'config' / 'three_joint_arm_controllers.yaml')
    with sim_node(robot_description_file=model, controllers_file=controllers) as harness:
        node = harness.node
        assert node.get_parameter('arm_controller.gains.shoulder_joint.p').value == 100.0
        assert node.get_parameter('arm_controller.gains.wrist_joint.i_clamp_max').value == 0.5
        assert node.get_parameter('arm_controller.gains.wrist_joint.i_clamp_min').value == -0.5
        assert node.get_parameter('gripper_controller.gains.left_finger_joint.p').value == 400.0
        results = harness.set_parameters(**{'arm_controller.gains.extend_joint.d': 50.0,
                                            'gripper_controller.gains.left_finger_joint.i': 2})
        assert all(result.successful for result in results)
        arm = harness.simulation.controller('arm_controller')
        assert [pid.gains.d for pid in arm.pids().values()] == [10.0, 50.0, 0.3]
        gripper = harness.simulation.controller('gripper_controller')
        assert gripper.members[0].pid.gains.i == 2.0
        refused = harness.set_parameters(**{'arm_controller.gains.wrist_joint.p': -1.0})
        assert "'arm_controller.gains.wrist_joint.p'" in refused[0].reason
        # The arm has no tilt_link: no camera unless asked for.
        assert node.features.camera is None
