"""Pacing: steps per tick follow wall time times the real-time factor."""

import math

import pytest

from pan_tilt_sim.ros.pacing import (
    FAST_BATCH_STEPS,
    FAST_TICK_S,
    MAX_CATCH_UP_S,
    MAX_PACED_BATCH_STEPS,
    MAX_REAL_TIME_FACTOR,
    Pacer,
    Throttle,
)


class FakeClock:
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


def _started(factor):
    """Return a pacer at ``factor`` on a fake clock, past its first tick, and the clock."""
    clock = FakeClock()
    pacer = Pacer(factor, 0.001, clock)
    pacer.steps_due()
    return pacer, clock


def test_factor_zero_starts_with_a_fixed_batch():
    assert Pacer(0.0, 0.001).steps_due() == FAST_BATCH_STEPS


def test_factor_zero_batches_grow_to_fill_a_tick_of_wall_time():
    clock = FakeClock()
    pacer = Pacer(0.0, 0.001, clock)
    batches = [pacer.steps_due()]
    for _ in range(6):
        clock.now += batches[-1] / 100_000  # this machine runs 100k steps/s
        batches.append(pacer.steps_due())
    # Doubling at most per tick, up to what fits in FAST_TICK_S.
    fitting = round(100_000 * FAST_TICK_S)
    assert batches == [FAST_BATCH_STEPS, 2 * FAST_BATCH_STEPS, 4 * FAST_BATCH_STEPS,
                       fitting, fitting, fitting, fitting]


def test_factor_zero_batches_shrink_for_an_expensive_robot():
    pacer, clock = _started(0.0)
    clock.now += FAST_BATCH_STEPS / 1000  # 1000 steps/s
    assert pacer.steps_due() == round(1000 * FAST_TICK_S)


def test_factor_zero_runs_at_least_one_step_per_tick():
    pacer, clock = _started(0.0)
    clock.now += 60.0  # a long stall
    assert pacer.steps_due() == 1


def test_restart_at_factor_zero_starts_again_from_the_fixed_batch():
    pacer, clock = _started(0.0)
    clock.now += 10.0
    pacer.restart()
    assert pacer.steps_due() == FAST_BATCH_STEPS


def test_real_time_runs_one_step_per_time_step_of_wall_time():
    clock = FakeClock()
    pacer = Pacer(1.0, 0.001, clock)
    assert pacer.steps_due() == 0
    total = 0
    for _ in range(100):
        clock.now += 0.01
        total += pacer.steps_due()
    assert abs(total - 1000) <= 1


def test_faster_than_real_time_factor_scales_the_steps():
    pacer, clock = _started(2.5)
    clock.now += 0.01
    assert pacer.steps_due() == 25


def test_a_stall_is_not_paid_back_in_one_burst():
    pacer, clock = _started(1.0)
    clock.now += 5.0
    assert pacer.steps_due() == round(MAX_CATCH_UP_S / 0.001)
    clock.now += 0.01
    assert pacer.steps_due() == 10


def test_restart_forgets_time_spent_paused():
    pacer, clock = _started(1.0)
    clock.now += 3.0
    pacer.restart()
    assert pacer.steps_due() == 0
    clock.now += 0.02
    assert pacer.steps_due() == 20


@pytest.mark.parametrize('factor', [1e308, MAX_REAL_TIME_FACTOR * 1.001, math.inf, math.nan,
                                    -1.0])
def test_a_factor_outside_the_bound_is_a_value_error_not_an_overflow_later(factor):
    pacer = Pacer(1.0, 0.001)
    with pytest.raises(ValueError, match='real_time_factor'):
        pacer.real_time_factor = factor
    assert pacer.real_time_factor == 1.0


def test_a_tick_at_the_highest_factor_and_smallest_step_runs_a_bounded_batch():
    clock = FakeClock()
    pacer = Pacer(MAX_REAL_TIME_FACTOR, 1e-6, clock)
    pacer.steps_due()
    clock.now += 1.0  # wants 1e9 steps
    assert pacer.steps_due() == MAX_PACED_BATCH_STEPS
    clock.now += 1e-6  # the debt was dropped: only this microsecond's steps are due
    assert pacer.steps_due() in (999, 1000)  # float wall times: a step may fall either side


def test_a_time_step_whose_rate_overflows_is_refused():
    with pytest.raises(ValueError, match='more steps per second than a float holds'):
        Pacer(1.0, 5e-324)


# --- the /clock throttle: one per wall millisecond on average, in bursts ----------------

def test_the_throttle_allows_a_burst_then_one_event_per_period():
    clock = FakeClock()
    throttle = Throttle(0.001, 20, clock)
    assert sum(throttle.allow() for _ in range(100)) == 20  # the burst, at one instant
    clock.now += 0.0105
    assert sum(throttle.allow() for _ in range(100)) == 10  # 10.5 ms: 10 whole tokens
    assert not throttle.allow()
    clock.now += 0.0006
    assert throttle.allow()  # the half token left and a bit more than half a period


def test_the_throttle_lets_a_real_time_tick_through_whole():
    # At real_time_factor 1 a 20 ms tick reaches two or three /clock stamps at once.
    clock = FakeClock()
    throttle = Throttle(0.001, 20, clock)
    for _ in range(50):
        clock.now += 0.02
        assert all(throttle.allow() for _ in range(3))


def test_a_token_taken_without_one_there_is_a_debt_refills_pay_first():
    clock = FakeClock()
    throttle = Throttle(0.001, 2, clock)
    assert throttle.allow() and throttle.allow()
    throttle.take()  # one more than the bucket held
    clock.now += 0.0015
    assert not throttle.ready()  # 1.5 tokens came: 1 paid the debt
    clock.now += 0.0006  # (not 0.0005: the sum of float refills may fall just short of 1)
    assert throttle.allow() and not throttle.ready()


def test_asking_whether_the_throttle_is_ready_takes_no_token():
    clock = FakeClock()
    throttle = Throttle(0.001, 2, clock)
    assert all(throttle.ready() for _ in range(10))
    assert throttle.allow() and throttle.allow()
    assert not throttle.ready()
    clock.now += 0.001
    assert throttle.ready() and throttle.allow() and not throttle.ready()
