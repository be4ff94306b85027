"""Properties of the limits, for any command sequence and any valid limits (hypothesis).

Whatever arrives -- NaN, +-Inf, 1e308, in or out of range -- a position
controller's setpoint stays within the joint's limits and moves no more than
velocity * dt per step, every controller's effort stays within the effort
limit, and every output is finite.  The measured state is drawn too, within
what PyBullet reports (finite; |position| <= 1e6, |velocity| <= 100).
"""

from __future__ import annotations

import math

from hypothesis import given, settings
from hypothesis import strategies as st

from pan_tilt_sim.controllers.commands.joint_effort_controller import JointEffortController
from pan_tilt_sim.controllers.commands.joint_position_controller import JointPositionController
from pan_tilt_sim.controllers.commands.joint_velocity_controller import JointVelocityController
from pan_tilt_sim.controllers.framework.base import CommandResult, JointHandle
from pan_tilt_sim.model.robot import JointKind, JointSpec

PROPERTY_SETTINGS = settings(max_examples=200, deadline=None)
LIMIT_RANGE = 1e6  # |lower|, |upper|: metres or radians, generously
MAX_POSITION = 1e6
MAX_SPEED = 100.0  # PyBullet's default joint velocity cap
MAX_GAIN = 1e6
RAMP_TOLERANCE = 1e-9  # relative: floating-point slack on velocity * dt

# Any float at all, with the nasty ones made likely.
commands = st.one_of(
    st.floats(),
    st.sampled_from([math.nan, math.inf, -math.inf, 1e308, -1e308, 1.7976931348623157e308,
                     5e-324, 1e12, 1e13]))
positive_limits = st.one_of(st.just(math.inf), st.floats(1e-3, 1e4))
gains = st.fixed_dictionaries({'p': st.floats(0, MAX_GAIN), 'i': st.floats(0, MAX_GAIN),
                               'd': st.floats(0, MAX_GAIN)})
steps = st.lists(st.tuples(
    st.one_of(st.none(), commands),              # a command this step, or none
    st.floats(-MAX_POSITION, MAX_POSITION),      # measured position
    st.floats(-MAX_SPEED, MAX_SPEED),            # measured velocity
), min_size=1, max_size=60)
time_steps = st.floats(1e-4, 0.1)


@st.composite
def joints(draw) -> JointSpec:
    kind = draw(st.sampled_from([JointKind.REVOLUTE, JointKind.PRISMATIC,
                                 JointKind.CONTINUOUS]))
    fields = {'effort_limit': draw(positive_limits), 'velocity_limit': draw(positive_limits)}
    if kind is not JointKind.CONTINUOUS:
        lower = draw(st.floats(-LIMIT_RANGE, LIMIT_RANGE))
        fields['lower'] = lower
        fields['upper'] = draw(st.floats(lower, LIMIT_RANGE))
    return JointSpec('joint', kind, **fields)


def _bind(controller_type, joint: JointSpec, params: dict):
    handle = JointHandle(joint)
    controller = controller_type('controller', {'joint': joint.name, **params})
    controller.configure({joint.name: handle})
    return controller, handle


def _run(controller, handle, sequence, dt, check_step) -> None:
    for number, (command, position, velocity) in enumerate(sequence):
        if command is not None:
            result = controller.set_command(command)
            if not math.isfinite(command):
                assert result is CommandResult.REJECTED
        handle.position, handle.velocity = position, velocity
        controller.update(number * dt, dt)
        assert math.isfinite(handle.effort)
        assert abs(handle.effort) <= handle.spec.effort_limit
        check_step()


@PROPERTY_SETTINGS
@given(joint=joints(), pid=gains, sequence=steps, dt=time_steps)
def test_the_position_setpoint_keeps_to_limits_and_ramp_and_the_effort_to_its_limit(
        joint, pid, sequence, dt):
    controller, handle = _bind(JointPositionController, joint, {'pid': pid})
    previous = [controller.setpoint]

    def check_step() -> None:
        setpoint = controller.setpoint
        assert math.isfinite(setpoint)
        if joint.has_position_limits:
            assert joint.lower <= setpoint <= joint.upper
        step = abs(setpoint - previous[0])
        # Floating-point slack: one rounding of setpoint + step, in units of its last place.
        slack = 2 * math.ulp(max(abs(setpoint), abs(previous[0])))
        assert step <= joint.velocity_limit * dt * (1 + RAMP_TOLERANCE) + slack
        previous[0] = setpoint

    _run(controller, handle, sequence, dt, check_step)


@PROPERTY_SETTINGS
@given(joint=joints(), pid=gains, sequence=steps, dt=time_steps)
def test_the_velocity_controller_keeps_the_effort_finite_and_within_its_limit(
        joint, pid, sequence, dt):
    controller, handle = _bind(JointVelocityController, joint, {'pid': pid})
    _run(controller, handle, sequence, dt, lambda: None)


@PROPERTY_SETTINGS
@given(joint=joints(), sequence=steps, dt=time_steps)
def test_the_effort_controller_keeps_the_effort_finite_and_within_its_limit(
        joint, sequence, dt):
    controller, handle = _bind(JointEffortController, joint, {})
    _run(controller, handle, sequence, dt, lambda: None)
