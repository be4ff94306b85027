"""PeriodicSchedule: what is due when, in sim time and in physics steps."""

import pytest

from pan_tilt_sim.schedule import DUE_EPSILON, PeriodicSchedule, steps_per_update


def test_something_is_due_at_once_then_once_per_period():
    schedule = PeriodicSchedule(0.02)
    assert schedule.take(0.0)
    assert not schedule.take(0.019)
    assert schedule.take(0.02)


def test_the_next_step_is_the_first_one_after_the_given_step_at_or_past_the_due_time():
    schedule = PeriodicSchedule(0.02)
    schedule.take(0.0)  # next due at 0.02 s: step 20 of 1 ms
    assert schedule.due_step(0.001) == 20
    assert schedule.next_step(5, 0.001) == 20
    assert schedule.next_step(19, 0.001) == 20
    assert schedule.next_step(20, 0.001) == 21  # never the step already reached
    assert schedule.next_step(35, 0.001) == 36  # overdue: the very next step


def test_the_first_due_step_is_the_one_the_stepping_loop_finds_due():
    for period, time_step in ((0.02, 0.001), (1 / 150, 0.001), (0.1, 0.003), (0.01, 0.01)):
        schedule = PeriodicSchedule(period)
        for now in (0.0, 0.0371, 0.5, 3.9):
            schedule.advance(now)  # next due: the first grid point after ``now``
            first = round(now / time_step)
            expected = next(step for step in range(first, first + 10_000)
                            if step * time_step + DUE_EPSILON >= schedule.next_due)
            assert schedule.first_due_step(first, time_step) == expected
            assert schedule.first_due_step(expected + 3, time_step) == expected + 3  # overdue


@pytest.mark.parametrize(('period', 'time_step', 'steps'), [
    (0.01, 0.001, 10), (1.0 / 1000, 0.001, 1), (1.0 / 300, 0.001, 4), (1.0 / 500, 0.002, 1),
    (1.0 / 3000, 0.001, 1), (0.1, 0.004, 25), (1.0 / 70, 0.001, 15), (0.1 * 3, 0.1, 3),
])
def test_a_clock_updates_at_the_first_step_whose_time_reaches_its_period(period, time_step,
                                                                         steps):
    # (0.1 * 3) / 0.1 is 3.0000000000000004 in floats: still three steps, not four.
    assert steps_per_update(period, time_step) == steps
