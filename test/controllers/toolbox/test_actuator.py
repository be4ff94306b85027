"""The ideal actuator's setpoint ramp and velocity target (pure Python, hypothesis for any input).

Whatever arrives, a position controller without gains keeps its setpoint
within the joint's limits, moves it no faster than the velocity limit and
changes its speed no faster than SETPOINT_ACCELERATION, lands exactly on the
command, and asks the physics for a finite velocity within the limit.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_limits_properties import joints, steps, time_steps

from pan_tilt_sim.controllers.commands.joint_position_controller import JointPositionController
from pan_tilt_sim.controllers.commands.joint_velocity_controller import JointVelocityController
from pan_tilt_sim.controllers.framework.base import ActuatorKind, CommandResult, Drive, JointHandle
from pan_tilt_sim.controllers.toolbox.actuator import SETPOINT_ACCELERATION, TRACKING_GAIN, ramp
from pan_tilt_sim.model.robot import JointKind, JointSpec

DT = 0.001
TOLERANCE = 1e-9


def profile(command, max_velocity=2.0, steps=5000, start=0.0):
    setpoints, rate = [start], 0.0
    for _ in range(steps):
        setpoint, rate = ramp(setpoints[-1], rate, command, DT, max_velocity)
        setpoints.append(setpoint)
    return setpoints


@pytest.mark.parametrize('command', [0.5, -2.0, 0.0123, 1e-7, 3.0])
def test_the_ramp_is_a_trapezoid_that_lands_exactly(command):
    setpoints = profile(command)
    assert setpoints[-1] == command
    speeds = [(b - a) / DT for a, b in zip(setpoints, setpoints[1:], strict=False)]
    changes = [(b - a) / DT for a, b in zip(speeds, speeds[1:], strict=False)]
    assert max(map(abs, speeds)) <= 2.0 * (1 + TOLERANCE)
    assert max(map(abs, changes)) <= SETPOINT_ACCELERATION * 1.1  # the last step may round
    # No time lost: within a few steps of the ideal trapezoid's duration.
    distance = abs(command)
    ideal = (2 * math.sqrt(distance / SETPOINT_ACCELERATION) if distance < 2.0 ** 2 /
             SETPOINT_ACCELERATION else distance / 2.0 + 2.0 / SETPOINT_ACCELERATION)
    arrival = setpoints.index(command) * DT
    assert arrival == pytest.approx(ideal, abs=0.005)


def test_a_new_command_while_moving_turns_around_smoothly():
    setpoint, rate = 0.0, 0.0
    for _ in range(300):
        setpoint, rate = ramp(setpoint, rate, 1.0, DT, 2.0)
    assert rate == 2.0  # at full speed toward 1.0
    previous = rate
    for _ in range(3000):
        setpoint, rate = ramp(setpoint, rate, -0.5, DT, 2.0)
        # The step that lands may stop from up to twice a * dt; every other one from a * dt.
        limit = (2 if (setpoint, rate) == (-0.5, 0.0) else 1) * SETPOINT_ACCELERATION * DT
        assert abs(rate - previous) <= limit * (1 + TOLERANCE)
        previous = rate
    assert (setpoint, rate) == (-0.5, 0.0)


def test_a_position_controller_without_gains_asks_for_a_velocity_and_says_why():
    spec = JointSpec('j', JointKind.REVOLUTE, -1.0, 1.0, effort_limit=30.0, velocity_limit=0.5)
    handle = JointHandle(spec, initial_position=0.002)
    controller = JointPositionController(
        'c', {'type': 'position_controllers/JointPositionController', 'joint': 'j'})
    controller.configure({'j': handle})
    assert controller.ideal and controller.pid is None and controller.pids() == {}
    actuator = controller.actuators()['j']
    assert actuator.drive is Drive.VELOCITY
    assert actuator.describe(spec) == (
        'ideal position actuator (c), a velocity motor with at most 30 N*m: no PID gains for '
        'it in the YAML')
    controller.update(0.0, DT)  # no command yet: hold the start (0.002)
    assert handle.velocity_target == 0.0
    handle.position = 0.001
    controller.update(DT, DT)
    assert handle.velocity_target == pytest.approx(TRACKING_GAIN / DT * 0.001)


def test_the_effort_controllers_types_keep_a_pid_without_gains():
    spec = JointSpec('j', JointKind.PRISMATIC, 0.0, 1.0, effort_limit=30.0, velocity_limit=0.5)
    for controller_type, kind in ((JointPositionController, ActuatorKind.POSITION_PID),
                                  (JointVelocityController, ActuatorKind.VELOCITY_PID)):
        handle = JointHandle(spec)
        controller = controller_type('c', {
            'type': controller_type.type_names[1], 'joint': 'j'})
        controller.type_name = controller_type.type_names[1]  # as the registry sets it
        controller.configure({'j': handle})
        actuator = controller.actuators()['j']
        assert actuator.kind is kind and actuator.drive is Drive.EFFORT
        assert controller.pid.gains == controller_type.default_gains.with_default_clamp(30.0)


@settings(max_examples=200, deadline=None)
@given(joint=joints(), sequence=steps, dt=time_steps)
def test_the_ideal_position_setpoint_and_target_keep_to_every_limit(joint, sequence, dt):
    handle = JointHandle(joint)
    controller = JointPositionController('c', {'joint': joint.name})
    controller.configure({joint.name: handle})
    previous_setpoint = controller.setpoint
    for number, (command, position, velocity) in enumerate(sequence):
        if command is not None:
            result = controller.set_command(command)
            if not math.isfinite(command):
                assert result is CommandResult.REJECTED
        handle.position, handle.velocity = position, velocity
        controller.update(number * dt, dt)
        setpoint, target = controller.setpoint, handle.velocity_target
        assert math.isfinite(setpoint) and math.isfinite(target)
        assert abs(target) <= joint.velocity_limit
        if joint.has_position_limits:
            assert joint.lower <= setpoint <= joint.upper
        rate = (setpoint - previous_setpoint) / dt
        slack = 4 * math.ulp(max(abs(setpoint), abs(previous_setpoint), 1.0)) / dt
        assert abs(rate) <= joint.velocity_limit * (1 + TOLERANCE) + slack
        previous_setpoint = setpoint
        assert handle.effort == 0.0


@settings(max_examples=200, deadline=None)
@given(command=st.floats(-1.0, 1.0), max_velocity=st.floats(0.1, 100.0),
       acceleration=st.floats(1.0, 1e6), dt=st.floats(1e-3, 0.1))
def test_the_ramp_always_arrives_and_stops(command, max_velocity, acceleration, dt):
    setpoint, rate, steps = 0.0, 0.0, 0
    # Accelerating, cruising and braking take at most this long, plus a step or two.
    bound = abs(command) / max_velocity + 2 * max_velocity / acceleration + 2 * math.sqrt(
        abs(command) / acceleration) + 3 * dt
    while (setpoint, rate) != (command, 0.0):
        setpoint, rate = ramp(setpoint, rate, command, dt, max_velocity, acceleration)
        steps += 1
        assert steps * dt <= bound
