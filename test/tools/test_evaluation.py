"""One evaluation: step_response's metrics, the cost and checks on top, the same anywhere."""

import dataclasses
import math

import pytest

from pan_tilt_sim.controllers.toolbox.pid import PidGains
from pan_tilt_sim.errors import ConfigurationError
from pan_tilt_sim.model.variation import PhysicalVariation
from pan_tilt_sim.sim.engine import make_simulation
from pan_tilt_sim.tools.evaluation import (
    Case,
    Spec,
    evaluate,
    load_scenario,
    meets,
    step_result,
    step_violations,
    violations,
)
from pan_tilt_sim.tools.step_response import StepRecord, record_step, step_metrics

DT = 0.001
PAN_TILT_GAINS = PidGains(p=100.0, i=0.01, d=10.0, i_clamp_min=-300.0, i_clamp_max=300.0)


@pytest.fixture(scope='module')
def scenario(request):
    root = request.config.rootpath
    return load_scenario(root / 'urdf' / 'pan_tilt.xacro',
                         root / 'config' / 'pan_tilt_control.yaml', DT)


def synthetic(positions, setpoints=None, efforts=None, target=1.0, dt=DT):
    times = tuple(index * dt for index in range(len(positions)))
    setpoints = setpoints or (target,) * len(positions)
    efforts = efforts or (0.0,) * len(positions)
    return StepRecord('j', 'c', 0.0, target, math.inf, 'rad', 'N m', times, tuple(positions),
                      tuple(setpoints), tuple(efforts))


def test_the_metrics_are_step_responses_own(scenario, repo_root):
    evaluation = evaluate(scenario, Case('pan_joint', (1.0,)))
    with make_simulation(str(repo_root / 'urdf' / 'pan_tilt.xacro'),
                         str(repo_root / 'config' / 'pan_tilt_control.yaml'), DT) as sim:
        expected = step_metrics(record_step(sim, 'pan_joint', 1.0))
    assert evaluation.steps[0].metrics == expected
    assert evaluation.steps[0].final_error == pytest.approx(0.00995, abs=1e-4)
    assert evaluation.steps[0].duration_s == pytest.approx(15.0)


def test_every_target_starts_from_the_initial_state(scenario):
    both = evaluate(scenario, Case('pan_joint', (1.0, -0.5)))
    alone = evaluate(scenario, Case('pan_joint', (-0.5,)))
    assert [step.initial for step in both.steps] == [0.0, 0.0]
    assert both.steps[1] == alone.steps[0]


def test_the_same_case_gives_the_same_numbers_whatever_ran_before(scenario):
    case = Case('pan_joint', (1.0,), gains=(('pan_joint', dataclasses.replace(PAN_TILT_GAINS,
                                                                               p=900.0)),))
    first = evaluate(scenario, case)
    evaluate(scenario, Case('pan_joint', (0.7,), variation=PhysicalVariation(mass_scale=3.0)))
    assert evaluate(scenario, case).steps == first.steps


def test_gains_and_variations_reach_the_simulation(scenario):
    nominal = evaluate(scenario, Case('pan_joint', (1.0,))).steps[0]
    stiffer = evaluate(scenario, Case('pan_joint', (1.0,), gains=(
        ('pan_joint', dataclasses.replace(PAN_TILT_GAINS, p=1000.0)),))).steps[0]
    sticky = evaluate(scenario, Case('pan_joint', (1.0,), variation=PhysicalVariation(
        friction_scale=5.0))).steps[0]
    # Coulomb friction f holds an error of up to f / p; the pan/tilt example's pan creeps up to that
    # bound from below (0.0099 of 0.01), so five times the friction leaves nearly 0.05.
    assert 0.009 < nominal.final_error <= 1.0 / 100.0
    assert stiffer.final_error <= 1.0 / 1000.0
    assert 0.045 < sticky.final_error <= 5.0 / 100.0


def test_itae_is_the_time_weighted_tracking_error_per_unit_of_step():
    # A first-order lag behind a unit step: integral of t e^(-t/tau) dt = tau^2.
    tau = 0.2
    positions = [1.0 - math.exp(-k * DT / tau) for k in range(int(3.0 / DT))]
    result = step_result(synthetic(positions), 10.0, keep_record=False)
    assert result.itae == pytest.approx(tau * tau, rel=0.01)
    half = step_result(synthetic([0.5 * p for p in positions], setpoints=(0.5,) * len(positions),
                                 target=0.5), 10.0, keep_record=False)
    assert half.itae == pytest.approx(result.itae, rel=1e-9)


def test_the_final_error_is_the_worst_of_the_last_half_second():
    # Ends exactly on target, but swings 0.01 around it until 0.1 s before the end.
    positions = [1.0 + (0.01 if (k // 50) % 2 else -0.01) for k in range(2000)]
    positions[-100:] = [1.0] * 100
    result = step_result(synthetic(positions), 10.0, keep_record=False)
    assert result.metrics.steady_state_error == 0.0
    assert result.final_error == pytest.approx(0.01)


def test_effort_at_the_limit_counts_as_saturated():
    efforts = [5.0] * 1000 + [10.0] * 250 + [-10.0] * 250
    result = step_result(synthetic([1.0] * 1500, efforts=efforts), 10.0, keep_record=False)
    assert result.saturated_s == pytest.approx(0.5)
    assert step_violations(result, Spec())['effort'] > 0.0


def test_a_diverging_joint_is_unstable_and_fails_everything():
    positions = [0.0, 0.5, 0.2, 5.0] + [math.nan] * 10
    result = step_result(synthetic(positions), 10.0, keep_record=False)
    assert not result.stable and result.itae == math.inf
    assert all(value == math.inf for value in step_violations(result, Spec()).values())


def test_a_derivative_gain_too_big_for_the_time_step_chatters_at_the_effort_limit(scenario):
    # d * dt must stay below 2 x the pan's inertia (a few kg m^2): d = 50,000 at 1 ms is
    # far past it, and the effort limit (300 N m) is all that keeps the joint in hand.
    wild = dataclasses.replace(PAN_TILT_GAINS, d=50000.0)
    evaluation = evaluate(scenario, Case('pan_joint', (1.0,), gains=(('pan_joint', wild),),
                                         duration=1.0))
    assert evaluation.steps[0].saturated_s > 0.5
    assert violations(evaluation, Spec())['effort'] > 0.0
    assert not meets(evaluation, Spec())


def test_violations_are_scaled_to_their_bounds(scenario):
    evaluation = evaluate(scenario, Case('pan_joint', (1.0,)))
    # The pan/tilt example's pan: no overshoot, settled at 11.0 s, 0.00995 rad left.
    found = violations(evaluation, Spec(max_overshoot_percent=5.0, max_settling_s=10.0,
                                        max_error=0.005))
    assert found['overshoot'] == pytest.approx(-1.0)
    assert found['settling'] == pytest.approx((11.013 - 10.0) / 10.0, abs=1e-3)
    assert found['error'] == pytest.approx((0.00995 - 0.005) / 0.005, rel=0.01)
    assert found['effort'] < 0.0
    assert not meets(evaluation, Spec(max_error=0.005))
    assert meets(evaluation, Spec(max_error=0.02, max_settling_s=12.0))


def test_an_unknown_joint_or_a_bad_spec_is_a_configuration_error(scenario):
    with pytest.raises(ConfigurationError, match="'elbow'"):
        evaluate(scenario, Case('elbow', (1.0,)))
    with pytest.raises(ConfigurationError, match='--max-error'):
        Spec(max_error=-1.0)
