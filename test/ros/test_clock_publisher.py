"""clock_publisher: /clock stamps on a grid of sim time, throttled against the wall clock.

Stamps are whole physics steps nearest 10 ms apart; they leave while tokens
last (one per wall ms, bursts of CLOCK_BURST), and the newest one reached
always leaves at the end of a batch, on a token borrowed if need be.
"""

import pytest

from pan_tilt_sim.ros.clock_publisher import (
    CLOCK_BURST,
    CLOCK_STAMPS_SKIPPED,
    ClockPublisher,
    clock_period_steps,
)

DT = 0.001


class WallClock:
    """A wall clock that moves only when told (s)."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


class RecordingPublisher:
    """Keeps the stamp (s) of every /clock message published; has ``readers`` subscribers."""

    def __init__(self, readers: int = 1) -> None:
        self.sent: list[float] = []
        self.readers = readers

    def publish(self, message) -> None:
        self.sent.append(round(message.clock.sec + message.clock.nanosec * 1e-9, 9))

    def get_subscription_count(self) -> int:
        return self.readers


def clock(time_step: float = DT, readers: int = 1):
    publisher, wall = RecordingPublisher(readers), WallClock()
    return ClockPublisher(publisher, time_step, wall_clock=wall), publisher, wall


def spend_tokens(publisher: ClockPublisher, count: int) -> None:
    """Publish ``count`` stamps cut at the grid, one token each."""
    for stamp in range(count):
        publisher.publish_reached(stamp * publisher.every, publisher.every, cut_at_stamps=True)


@pytest.mark.parametrize(('time_step', 'steps'), [
    (0.001, 10), (0.0005, 20), (0.003, 3), (0.004, 3), (1 / 240, 2), (0.02, 1), (0.1, 1)])
def test_the_clock_period_is_the_whole_number_of_steps_nearest_10_ms(time_step, steps):
    assert clock_period_steps(time_step) == steps


def test_the_period_is_said_only_when_it_is_not_10_ms():
    assert clock(0.001)[0].period_line() is None
    assert clock(0.003)[0].period_line() == (
        '/clock every 3 steps (9 ms of sim time): the nearest whole number of time_step '
        'to 10 ms')


def test_the_newest_stamp_is_the_grid_stamp_at_or_before_the_step():
    publisher, sent, _ = clock()
    publisher.publish_newest(25)
    publisher.publish_newest(30)
    assert sent.sent == [0.02, 0.03]


def test_paced_every_stamp_a_chunk_reached_leaves_oldest_first_and_none_is_held():
    publisher, sent, _ = clock()
    publisher.publish_reached(5, 30, cut_at_stamps=False)
    assert sent.sent == [0.01, 0.02, 0.03]
    publisher.end_batch(35)
    assert sent.sent == [0.01, 0.02, 0.03]


def test_a_chunk_that_reaches_no_stamp_publishes_nothing():
    publisher, sent, _ = clock()
    publisher.publish_reached(11, 8, cut_at_stamps=False)
    publisher.end_batch(19)
    assert sent.sent == []


def test_cut_at_the_stamps_only_a_chunk_ending_on_one_publishes_it():
    publisher, sent, _ = clock()
    publisher.publish_reached(0, 10, cut_at_stamps=True)
    assert sent.sent == [0.01]
    publisher.publish_reached(10, 15, cut_at_stamps=True)  # ran past 0.02 to step 25
    assert sent.sent == [0.01]
    publisher.end_batch(25)  # the stamp held back leaves at the batch's end
    assert sent.sent == [0.01, 0.02]


def test_without_tokens_stamps_are_held_and_the_newest_leaves_on_a_borrowed_token():
    publisher, sent, wall = clock()
    spend_tokens(publisher, CLOCK_BURST)
    assert len(sent.sent) == CLOCK_BURST
    publisher.publish_reached(200, 30, cut_at_stamps=False)
    assert len(sent.sent) == CLOCK_BURST  # no token: 0.21 to 0.23 wait
    publisher.end_batch(230)
    assert sent.sent[-1] == 0.23 and len(sent.sent) == CLOCK_BURST + 1
    wall.now += 0.0015  # 1.5 tokens of wall time: the debt first, then half a token
    publisher.publish_reached(230, 10, cut_at_stamps=False)
    assert sent.sent[-1] == 0.23
    wall.now += 0.001
    publisher.publish_reached(240, 10, cut_at_stamps=False)
    assert sent.sent[-1] == 0.25


def test_a_chunk_cut_at_the_stamps_runs_past_a_few_without_a_token():
    publisher, _, wall = clock()
    assert publisher.steps_to_stamp(3) == 7
    assert publisher.steps_to_stamp(10) == 10
    spend_tokens(publisher, CLOCK_BURST)
    assert publisher.steps_to_stamp(3) == 7 + 10 * CLOCK_STAMPS_SKIPPED
    wall.now += 0.001
    assert publisher.steps_to_stamp(3) == 7


def test_it_is_wanted_until_asked_then_only_while_someone_reads():
    publisher, sent, _ = clock(readers=0)
    assert publisher.wanted
    publisher.refresh_readers()
    assert not publisher.wanted
    sent.readers = 2
    publisher.refresh_readers()
    assert publisher.wanted
