"""JointPositionController without a simulator: setpoint, ramp, PID effort, limits."""

import math

import pytest

from pan_tilt_sim.controllers import CommandResult, JointHandle, create_controller
from pan_tilt_sim.model.robot import JointKind, JointSpec

DT = 0.001
PAN = JointSpec('pan_joint', JointKind.REVOLUTE, lower=-3.14, upper=3.14,
                effort_limit=300.0, velocity_limit=0.1)
SEED_PARAMS = {'type': 'position_controllers/JointPositionController', 'joint': 'pan_joint',
               'pid': {'p': 100.0, 'i': 0.01, 'd': 10.0}}


def _controller(params=SEED_PARAMS, spec=PAN):
    handle = JointHandle(spec)
    controller = create_controller('joint1_position_controller', params['type'], params)
    controller.configure({spec.name: handle})
    return controller, handle


def _run(controller, steps):
    """Update the controller ``steps`` times, DT apart, from time 0 (joint state frozen)."""
    for step in range(steps):
        controller.update(step * DT, DT)


def test_before_the_first_command_the_joint_holds_its_start_position():
    controller, handle = _controller()
    handle.position = 0.2
    controller.reset()
    handle.position, handle.velocity = 0.2, 0.0
    controller.update(0.0, DT)
    assert controller.setpoint == 0.2
    assert handle.effort == pytest.approx(0.0)


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


def test_effort_is_clamped_to_the_effort_limit():
    params = dict(SEED_PARAMS, pid={'p': 1e6})
    controller, handle = _controller(params)
    controller.set_command(3.0)
    _run(controller, 100)
    assert handle.effort == 300.0


@pytest.mark.parametrize('value', [math.nan, math.inf, -math.inf])
def test_non_finite_commands_change_nothing(value):
    controller, handle = _controller()
    controller.set_command(0.5)
    assert controller.set_command(value) is CommandResult.REJECTED
    _run(controller, 10_000)
    assert controller.setpoint == pytest.approx(0.5)


def test_commands_beyond_the_limits_are_clamped():
    controller, _handle = _controller()
    assert controller.set_command(10.0) is CommandResult.CLAMPED
    _run(controller, 40_000)
    assert controller.setpoint == pytest.approx(3.14)


def test_a_missing_joint_field_is_a_configuration_error():
    from pan_tilt_sim.errors import ControllerConfigError

    with pytest.raises(ControllerConfigError, match='joint1_position_controller.joint'):
        create_controller('joint1_position_controller',
                          'position_controllers/JointPositionController', {'pid': {'p': 1}})
