"""The PID: gains as a validated value object, integral clamp, derivative on measurement."""

import math

import pytest

from pan_tilt_sim.controllers.toolbox.pid import GainsError, Pid, PidGains

DT = 0.001


def test_p_only_output_is_gain_times_error():
    pid = Pid(PidGains(p=100.0))
    assert pid.compute(setpoint=1.0, measurement=0.25, dt=DT) == pytest.approx(75.0)
    assert pid.compute(setpoint=-1.0, measurement=0.0, dt=DT) == pytest.approx(-100.0)


def test_i_only_integrates_gain_times_error_over_time():
    pid = Pid(PidGains(i=2.0))
    for _ in range(500):
        output = pid.compute(setpoint=1.0, measurement=0.0, dt=DT)
    assert output == pytest.approx(2.0 * 1.0 * 0.5)
    assert pid.integral_term == pytest.approx(1.0)


def test_with_antiwindup_the_accumulator_is_clamped_and_recovers_at_once():
    pid = Pid(PidGains(i=10.0, i_clamp_min=-0.5, i_clamp_max=0.5, antiwindup=True))
    for _ in range(10_000):
        pid.compute(setpoint=1.0, measurement=0.0, dt=DT)
    assert pid.integral_term == pytest.approx(0.5)
    # Without windup one step of negative error already lowers the term.
    pid.compute(setpoint=-1.0, measurement=0.0, dt=DT)
    assert pid.integral_term < 0.5


def test_without_antiwindup_the_contribution_is_clamped_but_the_accumulator_winds_up():
    # control_toolbox's default: the output sees at most i_clamp_max, but the
    # integral keeps growing (here to 10 * 1 * 10 s = 100) and must be unwound.
    pid = Pid(PidGains(i=10.0, i_clamp_min=-0.5, i_clamp_max=0.5))
    for _ in range(10_000):
        output = pid.compute(setpoint=1.0, measurement=0.0, dt=DT)
    assert output == pytest.approx(0.5)
    assert pid.integral_term == pytest.approx(0.5)
    for _ in range(9_000):  # 9 s of negative error: 100 - 90 = 10, still saturated
        pid.compute(setpoint=-1.0, measurement=0.0, dt=DT)
    assert pid.integral_term == pytest.approx(0.5)
    for _ in range(1_000):  # one more second: 10 - 10 = 0
        pid.compute(setpoint=-1.0, measurement=0.0, dt=DT)
    assert pid.integral_term == pytest.approx(0.0, abs=1e-6)


def test_antiwindup_comes_from_the_yaml_and_must_be_a_bool():
    assert PidGains.from_mapping({'p': 1, 'antiwindup': True}).antiwindup is True
    assert PidGains.from_mapping({'p': 1}).antiwindup is False
    with pytest.raises(GainsError, match='antiwindup'):
        PidGains.from_mapping({'p': 1, 'antiwindup': 'yes'})


def test_a_zero_time_step_changes_nothing_and_returns_the_last_output():
    pid = Pid(PidGains(p=2.0, i=1.0))
    first = pid.compute(setpoint=1.0, measurement=0.0, dt=DT)
    integral = pid.integral_term
    assert pid.compute(setpoint=5.0, measurement=0.0, dt=0.0) == first
    assert pid.integral_term == integral


@pytest.mark.parametrize('dt', [-1.0, -DT, math.nan])
def test_a_negative_or_nan_time_step_raises(dt):
    pid = Pid(PidGains(p=1.0, i=1.0))
    with pytest.raises(ValueError, match='dt'):
        pid.compute(setpoint=1.0, measurement=0.0, dt=dt)
    assert pid.integral_term == 0.0


@pytest.mark.parametrize('setpoint, measurement, rate', [
    (math.nan, 0.0, 0.0), (0.0, math.inf, 0.0), (1.0, 0.0, math.nan), (1.0, 0.0, -math.inf)])
def test_a_non_finite_error_or_rate_gives_zero_and_leaves_the_integrator(setpoint, measurement,
                                                                         rate):
    pid = Pid(PidGains(p=1.0, i=1.0, d=1.0))
    pid.compute(setpoint=1.0, measurement=0.0, dt=DT, measurement_rate=0.0)
    integral = pid.integral_term
    assert pid.compute(setpoint, measurement, DT, rate) == 0.0
    assert pid.integral_term == integral


def test_derivative_acts_on_the_measured_rate_not_the_error():
    pid = Pid(PidGains(d=10.0))
    # A setpoint jump with the joint at rest gives no derivative kick.
    assert pid.compute(setpoint=5.0, measurement=0.0, dt=DT, measurement_rate=0.0) == 0.0
    # A moving joint is damped: output = -d * rate.
    assert pid.compute(setpoint=5.0, measurement=0.0, dt=DT, measurement_rate=0.3) == (
        pytest.approx(-3.0))


def test_derivative_without_a_measured_rate_differences_the_measurement():
    pid = Pid(PidGains(d=2.0))
    assert pid.compute(setpoint=0.0, measurement=1.0, dt=DT) == 0.0  # first call: no history
    assert pid.compute(setpoint=9.0, measurement=1.5, dt=DT) == pytest.approx(-2.0 * 0.5 / DT)


def test_reset_forgets_the_integral_and_the_last_measurement():
    pid = Pid(PidGains(i=1.0, d=1.0))
    pid.compute(1.0, 0.0, DT)
    pid.compute(1.0, 0.5, DT)
    pid.reset()
    assert pid.integral_term == 0.0
    assert pid.compute(0.0, 0.0, DT) == 0.0


def test_new_gains_take_effect_without_resetting_the_integral():
    pid = Pid(PidGains(i=1.0))
    pid.compute(1.0, 0.0, 0.5)
    pid.gains = PidGains(p=2.0, i=1.0)
    assert pid.integral_term == pytest.approx(0.5)
    assert pid.compute(1.0, 0.0, DT) == pytest.approx(2.0 + 0.5 + DT)


def test_gains_from_yaml_mapping_with_symmetric_clamp():
    gains = PidGains.from_mapping({'p': 100, 'i': 0.01, 'd': 10.0, 'i_clamp': 3})
    assert (gains.p, gains.i, gains.d) == (100.0, 0.01, 10.0)
    assert (gains.i_clamp_min, gains.i_clamp_max) == (-3.0, 3.0)


def test_explicit_clamp_bounds_win_over_i_clamp():
    gains = PidGains.from_mapping({'i': 1, 'i_clamp': 3, 'i_clamp_min': -1, 'i_clamp_max': 2})
    assert (gains.i_clamp_min, gains.i_clamp_max) == (-1.0, 2.0)


def test_without_clamp_the_default_bound_applies():
    gains = PidGains.from_mapping({'p': 1, 'i': 1})
    assert not gains.has_integral_clamp
    bounded = gains.with_default_clamp(300.0)
    assert (bounded.i_clamp_min, bounded.i_clamp_max) == (-300.0, 300.0)
    assert PidGains(i=1, i_clamp_max=5).with_default_clamp(300.0).i_clamp_max == 5.0


@pytest.mark.parametrize('values, field', [
    ({'p': -1}, 'p'),
    ({'i': 'fast'}, 'i'),
    ({'d': math.nan}, 'd'),
    ({'p': math.inf}, 'p'),
    ({'i_clamp': -2}, 'i_clamp'),
    ({'i_clamp_min': 2, 'i_clamp_max': 1}, 'i_clamp_min'),
    ({'q': 1}, 'q'),
])
def test_invalid_gains_are_refused_naming_the_field(values, field):
    with pytest.raises(GainsError, match=field):
        PidGains.from_mapping(values)


@pytest.mark.parametrize('bounds', [{'i_clamp_min': math.inf},
                                    {'i_clamp_max': -math.inf},
                                    {'i_clamp_min': math.inf, 'i_clamp_max': math.inf}])
def test_an_integral_clamp_pinned_at_infinity_is_refused(bounds):
    with pytest.raises(GainsError, match='must be < inf'):
        PidGains(p=1.0, i=1.0, **bounds)
