"""PeriodicSchedule: what is due when, in sim time and in physics steps."""

from pan_tilt_sim.schedule import PeriodicSchedule


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
