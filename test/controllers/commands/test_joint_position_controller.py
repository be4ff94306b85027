"""JointPositionController (position_ and effort_controllers/), without a simulator.

Parameters, the lifecycle through the controller manager, the setpoint, the
PID effort or the ideal actuator's velocity target, and every limit it
enforces:

* position commands are clamped to the joint's [lower, upper] (not on a
  continuous joint); NaN, Inf and magnitudes beyond MAX_COMMAND_MAGNITUDE
  are rejected;
* with a PID: the setpoint ramps at no more than the velocity limit, the
  effort is clamped to +-effort limit, and the integral term is bounded by
  the effort limit unless the YAML gives a clamp;
* without (the ideal actuator): the setpoint moves no faster than the
  velocity limit, speeds up and slows down at SETPOINT_ACCELERATION and
  never leaves the position limits, not even braking for a reversed command;
  the velocity target is clamped to +-velocity limit.
"""

import copy
import math

import pytest
from controller_fixtures import DT, loaded, raises_naming, step

from pan_tilt_sim.controllers import CommandKind, CommandResult, JointHandle, create_controller
from pan_tilt_sim.controllers.framework.base import MAX_COMMAND_MAGNITUDE, ActuatorKind
from pan_tilt_sim.controllers.framework.manager import ACTIVE, INACTIVE, UNCONFIGURED
from pan_tilt_sim.controllers.toolbox.actuator import SETPOINT_ACCELERATION
from pan_tilt_sim.model.robot import JointKind, JointSpec, Mimic

POSITION_TYPE = 'position_controllers/JointPositionController'
EFFORT_TYPE = 'effort_controllers/JointPositionController'
PAN = JointSpec('pan_joint', JointKind.REVOLUTE, lower=-3.14, upper=3.14,
                effort_limit=300.0, velocity_limit=0.1)
PAN_TILT_PARAMS = {'type': POSITION_TYPE, 'joint': 'pan_joint',
               'pid': {'p': 100.0, 'i': 0.01, 'd': 10.0}}
# A joint fast enough for the ideal actuator's ramp to show both of its limits.
ARM = JointSpec('arm', JointKind.REVOLUTE, lower=-1.0, upper=1.0, effort_limit=30.0,
                velocity_limit=0.5)
WHEEL = JointSpec('wheel', JointKind.CONTINUOUS)  # no limits at all


def _controller(params=PAN_TILT_PARAMS, spec=PAN):
    handle = JointHandle(spec)
    controller = create_controller('joint1_position_controller', params['type'], params)
    controller.configure({spec.name: handle})
    return controller, handle


def _ideal(spec=ARM):
    """A position controller without gains on ``spec``: the ideal actuator drives it."""
    controller, handle = _controller({'type': POSITION_TYPE, 'joint': spec.name}, spec)
    assert controller.ideal
    return controller, handle


def _with_pid(pid, spec=ARM):
    return _controller({'type': POSITION_TYPE, 'joint': spec.name, 'pid': pid}, spec)


def _run(controller, steps):
    """Update the controller ``steps`` times, DT apart, from time 0 (joint state frozen)."""
    for step_number in range(steps):
        controller.update(step_number * DT, DT)


def _setpoints(controller, steps, start=0):
    """Update ``steps`` times (joint state frozen); return the setpoint before and after each."""
    setpoints = [controller.setpoint]
    for step_number in range(start, start + steps):
        controller.update(step_number * DT, DT)
        setpoints.append(controller.setpoint)
    return setpoints


def _rates(values):
    return [(after - before) / DT for before, after in zip(values, values[1:], strict=False)]


# --- parameters ----------------------------------------------------------------------------

def test_a_missing_joint_field_is_a_configuration_error():
    with raises_naming('joint1_position_controller.joint'):
        create_controller('joint1_position_controller', POSITION_TYPE, {'pid': {'p': 1}})


@pytest.mark.parametrize('joint', ['', ['pan_joint'], 3])
def test_a_joint_that_is_not_one_name_is_a_configuration_error(joint):
    with raises_naming('c.joint'):
        create_controller('c', POSITION_TYPE, {'joint': joint})


@pytest.mark.parametrize('pid', [{'p': -1.0}, {'p': 'high'}, [1.0], {'i_clamp': -2}])
def test_invalid_pid_gains_are_a_configuration_error(pid):
    with raises_naming('c.pid'):
        create_controller('c', POSITION_TYPE, {'joint': 'pan_joint', 'pid': pid})


def test_an_unknown_pid_field_is_named_in_a_warning_and_ignored():
    controller = create_controller('c', POSITION_TYPE, {'joint': 'pan_joint',
                                                        'pid': {'p': 2.0, 'q': 1.0}})
    assert controller.config_warnings == [
        "c.pid.q: unknown parameter, ignored (did you mean 'pid.p'?)"]


def test_a_joint_the_robot_lacks_fails_at_configure_naming_the_joint_field():
    controller = create_controller('c', POSITION_TYPE, {'joint': 'elbow'})
    with raises_naming('c.joint'):
        controller.configure({'pan_joint': JointHandle(PAN)})


def test_a_mimic_joint_cannot_be_commanded():
    follower = JointSpec('follower', JointKind.REVOLUTE, -1.0, 1.0, mimic=Mimic('pan_joint'))
    controller = create_controller('c', POSITION_TYPE, {'joint': 'follower'})
    with raises_naming('c.joint'):
        controller.configure({'pan_joint': JointHandle(PAN), 'follower': JointHandle(follower)})


# --- interfaces and lifecycle --------------------------------------------------------------

@pytest.mark.parametrize(('type_name', 'interface'), [(POSITION_TYPE, 'position'),
                                                      (EFFORT_TYPE, 'effort')])
def test_takes_float64_on_command_and_claims_its_packages_interface(type_name, interface):
    controller = create_controller('c', type_name, {'joint': 'pan_joint'})
    assert controller.command_topic == 'command'
    assert controller.command_kind is CommandKind.FLOAT64
    assert controller.joint_names == ('pan_joint',)
    assert controller.command_interfaces() == {'pan_joint': (interface,)}


def test_the_manager_configures_activates_and_cleans_it_up_and_it_holds_where_activated():
    handles = {'arm': JointHandle(ARM)}
    manager = loaded('c', POSITION_TYPE, {'joint': 'arm'}, handles)
    assert manager.state('c') == UNCONFIGURED
    controller = manager.configure('c')
    assert manager.state('c') == INACTIVE and manager.updates == []
    handles['arm'].position = 0.3
    manager.switch(activate=['c'])
    assert manager.state('c') == ACTIVE
    assert controller.setpoints() == {'arm': 0.3}  # holds where the joint is
    assert controller.set_command(0.5) is CommandResult.ACCEPTED
    step(manager, 1000)
    assert controller.setpoints() == {'arm': 0.5}
    manager.switch(deactivate=['c'])
    target = handles['arm'].velocity_target
    controller.set_command(-0.5)  # an inactive controller's updates do not run
    step(manager, 100, start=1000)
    assert (controller.setpoint, handles['arm'].velocity_target) == (0.5, target)
    manager.cleanup('c')
    assert manager.state('c') == UNCONFIGURED


def test_without_gains_the_position_type_drives_the_ideal_actuator():
    controller, _handle = _ideal()
    assert controller.pids() == {}
    assert controller.actuators()['arm'].kind is ActuatorKind.IDEAL_POSITION


def test_with_gains_it_drives_a_position_pid_on_effort():
    controller, _handle = _with_pid({'p': 5.0, 'i': 1.0, 'd': 0.5})
    assert controller.actuators()['arm'].kind is ActuatorKind.POSITION_PID
    assert controller.pids()['arm'].gains.p == 5.0


# --- setpoint and effort -------------------------------------------------------------------

def test_before_the_first_command_the_joint_holds_its_start_position():
    controller, handle = _controller()
    handle.position = 0.2
    controller.reset()
    handle.position, handle.velocity = 0.2, 0.0
    controller.update(0.0, DT)
    assert controller.setpoint == 0.2
    assert handle.effort == pytest.approx(0.0)


def test_the_ramp_lands_exactly_on_a_near_command_and_runs_both_ways():
    controller, handle = _controller()
    handle.position = 0.99995
    controller.reset()
    controller.set_command(1.0)
    controller.update(0.0, DT)
    assert controller.setpoint == 1.0
    controller.set_command(-1.0)
    controller.update(DT, DT)
    assert controller.setpoint == pytest.approx(1.0 - 0.1 * DT)


def test_effort_is_pid_on_position_error_with_damping_from_velocity():
    controller, handle = _controller()
    handle.position, handle.velocity = 0.0, 0.05
    controller.set_command(1.0)
    controller.update(0.0, DT)
    expected = 100.0 * (0.1 * DT) + 0.01 * (0.1 * DT) * DT - 10.0 * 0.05
    assert handle.effort == pytest.approx(expected)


def test_reset_forgets_the_command_and_holds_where_the_joint_is():
    controller, handle = _ideal()
    controller.set_command(0.8)
    _run(controller, 200)
    handle.position = -0.25
    controller.reset()
    _run(controller, 200)
    assert controller.setpoint == -0.25


# --- limits: the position command ----------------------------------------------------------

def test_commands_beyond_the_limits_are_clamped():
    controller, _handle = _controller()
    assert controller.set_command(10.0) is CommandResult.CLAMPED
    _run(controller, 40_000)
    assert controller.setpoint == pytest.approx(3.14)


@pytest.mark.parametrize('gains', [None, {'p': 100.0}], ids=['ideal', 'pid'])
@pytest.mark.parametrize(('command', 'limit'), [(2.5, 1.0), (-7.0, -1.0)])
def test_the_setpoint_stops_at_the_position_limit_the_command_exceeds(gains, command, limit):
    controller, _handle = _ideal() if gains is None else _with_pid(gains)
    assert controller.set_command(command) is CommandResult.CLAMPED
    setpoints = _setpoints(controller, 4000)
    assert setpoints[-1] == limit
    assert max(map(abs, setpoints)) == 1.0


@pytest.mark.parametrize('value', [math.nan, math.inf, -math.inf])
def test_non_finite_commands_change_nothing(value):
    controller, handle = _controller()
    controller.set_command(0.5)
    assert controller.set_command(value) is CommandResult.REJECTED
    _run(controller, 10_000)
    assert controller.setpoint == pytest.approx(0.5)


def test_a_continuous_joint_takes_any_sane_position_and_rejects_beyond_the_magnitude_bound():
    controller, _handle = _ideal(WHEEL)
    assert controller.set_command(MAX_COMMAND_MAGNITUDE) is CommandResult.ACCEPTED
    assert controller.set_command(25.0) is CommandResult.ACCEPTED
    assert controller.set_command(-10 * MAX_COMMAND_MAGNITUDE) is CommandResult.REJECTED
    _run(controller, 10)
    assert controller.setpoints()['wheel'] > 0.0  # still heading for 25, not for -1e13


# --- limits: with a PID --------------------------------------------------------------------

def test_the_setpoint_ramps_toward_the_command_at_the_velocity_limit():
    controller, handle = _controller()
    assert controller.set_command(1.0) is CommandResult.ACCEPTED
    _run(controller, 1000)
    assert controller.setpoint == pytest.approx(0.1, abs=1e-9)


def test_one_radian_takes_ten_seconds_no_step_faster_than_the_limit():
    controller, _handle = _controller()
    controller.set_command(1.0)
    previous, steps = controller.setpoint, 0
    while controller.setpoint < 1.0:
        controller.update(steps * DT, DT)
        assert controller.setpoint - previous <= 0.1 * DT + 1e-15
        previous, steps = controller.setpoint, steps + 1
    # 1 rad at 0.1 rad/s takes 10 s of sim time.
    assert steps * DT == pytest.approx(10.0, abs=0.002)


@pytest.mark.parametrize('command', [3.0, -3.0])
def test_effort_is_clamped_to_the_effort_limit(command):
    params = dict(PAN_TILT_PARAMS, pid={'p': 1e6})
    controller, handle = _controller(params)
    controller.set_command(command)
    _run(controller, 100)
    assert handle.effort == math.copysign(300.0, command)


def _windup_then_overshoot(controller, handle):
    """Hold the joint 0.2 short of a setpoint at 0 for a second, then put it 0.5 past it."""
    handle.position = -0.2
    _run(controller, 1000)
    handle.position = 0.5
    controller.update(1.0, DT)
    return handle.effort


def test_the_integral_term_is_bounded_by_the_effort_limit_unless_the_yaml_clamps_it():
    # i 1e4 integrates 2 N*m per step: without a bound the term would reach 2000 N*m,
    # and still outweigh the proportional -20 N*m once the joint overshoots.
    controller, handle = _with_pid({'p': 40.0, 'i': 1e4})
    assert _windup_then_overshoot(controller, handle) == pytest.approx(-20.0 + 30.0)
    assert controller.pid.integral_term == 30.0
    controller, handle = _with_pid({'p': 40.0, 'i': 1e4, 'i_clamp': 5.0})
    assert _windup_then_overshoot(controller, handle) == pytest.approx(-20.0 + 5.0)


# --- limits: the ideal actuator (no gains) -------------------------------------------------

@pytest.mark.parametrize('command', [1.0, -1.0])
def test_without_gains_the_setpoint_moves_no_faster_than_the_velocity_limit(command):
    controller, _handle = _ideal()
    controller.set_command(command)
    speeds = _rates(_setpoints(controller, 3000))
    assert controller.setpoint == command
    assert max(map(abs, speeds)) == pytest.approx(0.5)
    assert max(map(abs, speeds)) <= 0.5 * (1 + 1e-9)


def test_without_gains_the_setpoint_speeds_up_and_slows_down_at_setpoint_acceleration():
    controller, _handle = _ideal()
    controller.set_command(0.8)
    setpoints = _setpoints(controller, 1000)
    controller.set_command(-0.8)  # turn around at full speed
    setpoints += _setpoints(controller, 4000, start=1000)[1:]
    arrival = setpoints.index(-0.8)
    speeds = [0.0, *_rates(setpoints[:arrival])]  # the step that lands may stop shorter
    changes = [abs(after - before) / DT for before, after in zip(speeds, speeds[1:],
                                                                 strict=False)]
    assert speeds[1] == pytest.approx(SETPOINT_ACCELERATION * DT)
    assert max(changes) == pytest.approx(SETPOINT_ACCELERATION)
    assert max(changes) <= SETPOINT_ACCELERATION * (1 + 1e-6)


@pytest.mark.parametrize('period', [0.001, 0.004])
@pytest.mark.parametrize('sign', [1.0, -1.0], ids=['upper', 'lower'])
def test_without_gains_a_command_reversed_near_a_limit_never_carries_the_setpoint_past_it(
        sign, period):
    controller, _handle = _ideal()
    controller.set_command(5.0 * sign)  # clamped: toward the limit at 1 rad * sign
    furthest, step_number = 0.0, 0
    while abs(controller.setpoint) < 1.0:  # reverse the command after every step of the way
        controller.update(step_number * period, period)
        step_number += 1
        reversed_ = copy.deepcopy(controller)
        reversed_.set_command(0.0)
        for later in range(round(0.06 / period)):  # braking from 0.5 rad/s takes 50 ms
            reversed_.update((step_number + later) * period, period)
            furthest = max(furthest, sign * reversed_.setpoint)
    assert furthest <= 1.0


@pytest.mark.parametrize(('start', 'command', 'target'), [(0.0, 1.0, 0.5), (0.9, -1.0, -0.5)])
def test_without_gains_the_velocity_target_is_clamped_to_the_velocity_limit(start, command,
                                                                            target):
    controller, handle = _ideal()
    handle.position = start
    controller.reset()
    controller.set_command(command)
    targets = []
    for step_number in range(1000):  # the joint stays where it is: the error keeps growing
        controller.update(step_number * DT, DT)
        targets.append(handle.velocity_target)
    assert targets[-1] == target
    assert max(map(abs, targets)) == 0.5
    assert handle.effort == 0.0
