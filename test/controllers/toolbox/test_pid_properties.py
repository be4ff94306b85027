"""Properties of the PID, for any valid gains (hypothesis).

For any gains (p, i, d >= 0 up to 1e6, any integral clamp with
i_clamp_min <= i_clamp_max, finite or not), any time step and any sequence
of finite setpoints and measurements of a physical size (|x| <= 1e6): the
output is finite and the integral term stays within its clamp -- also when
the gains are changed between steps, as live tuning does.
"""

from __future__ import annotations

import math

from hypothesis import given, settings
from hypothesis import strategies as st

from pan_tilt_sim.controllers.toolbox.pid import Pid, PidGains

PROPERTY_SETTINGS = settings(max_examples=300, deadline=None)
MAX_GAIN = 1e6
MAX_VALUE = 1e6

values = st.floats(-MAX_VALUE, MAX_VALUE)


@st.composite
def pid_gains(draw) -> PidGains:
    low = draw(st.one_of(values, st.just(-math.inf)))
    high = draw(st.one_of(values, st.just(math.inf)))
    low, high = min(low, high), max(low, high)
    return PidGains(p=draw(st.floats(0, MAX_GAIN)), i=draw(st.floats(0, MAX_GAIN)),
                    d=draw(st.floats(0, MAX_GAIN)), i_clamp_min=low, i_clamp_max=high,
                    antiwindup=draw(st.booleans()))


steps = st.lists(st.tuples(
    values,                                   # setpoint
    values,                                   # measurement
    st.one_of(st.none(), values),             # measured rate, or finite differences
    st.one_of(st.none(), pid_gains()),        # new gains before this step, or none
), min_size=1, max_size=80)


@PROPERTY_SETTINGS
@given(gains=pid_gains(), sequence=steps, dt=st.floats(1e-4, 0.1))
def test_the_output_is_finite_and_the_integral_term_within_its_clamp(gains, sequence, dt):
    pid = Pid(gains)
    for setpoint, measurement, rate, new_gains in sequence:
        if new_gains is not None:
            pid.gains = new_gains
        output = pid.compute(setpoint, measurement, dt, rate)
        assert math.isfinite(output)
        assert math.isfinite(pid.integral_term)
        clamp = pid.gains
        assert clamp.i_clamp_min <= pid.integral_term <= clamp.i_clamp_max


@PROPERTY_SETTINGS
@given(gains=pid_gains(), sequence=steps, dt=st.floats(1e-4, 0.1))
def test_reset_forgets_the_integral(gains, sequence, dt):
    pid = Pid(gains)
    for setpoint, measurement, rate, _ in sequence:
        pid.compute(setpoint, measurement, dt, rate)
    pid.reset()
    # Zero, or the nearer bound when the clamp excludes zero.
    assert pid.integral_term == min(max(0.0, gains.i_clamp_min), gains.i_clamp_max)
