"""/clock for sim_node: stamps on a grid of sim time, throttled against the wall clock.

:class:`ClockPublisher` decides which /clock stamps leave while the node runs
its batches of physics steps.  Stamps stay on a grid of whole physics steps
nearest 10 ms of sim time (:func:`clock_period_steps`).  They leave through a
token bucket -- one token per wall millisecond, at most CLOCK_BURST held, as
Gazebo's clock publisher throttles -- and the newest grid stamp reached
always leaves at the end of a batch, on a token borrowed if need be.  So up
to 10x real time every stamp leaves; far above it /clock comes about once per
wall millisecond.  Nothing is published while nobody reads /clock.

Design notes: docs/design/ros.md#clock_publisherpy.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

from rosgraph_msgs.msg import Clock

from pan_tilt_sim.ros.pacing import Throttle
from pan_tilt_sim.ros.ros_interfaces import clock_message

CLOCK_TOPIC = '/clock'
CLOCK_PERIOD_S = 0.01  # sim seconds between /clock messages (100 Hz of sim time)
# /clock leaves at most once per this much wall time on average (Gazebo's clock
# publisher throttles the same way), in bursts of up to CLOCK_BURST messages;
# the newest stamp always leaves at the end of each batch, on a token borrowed if need be.
CLOCK_MIN_WALL_PERIOD_S = 0.001
# A tick's worth (20 ms) of bursts: up to 10x real time every 10 ms stamp leaves.
CLOCK_BURST = 20
# Without a token, the stamps a chunk of steps may run past before it looks again
# (one token's worth of wall time at 100x real time, when tokens come one per ms).
CLOCK_STAMPS_SKIPPED = 10


def clock_period_steps(time_step: float) -> int:
    """Return the physics steps between /clock messages: the whole number nearest 10 ms.

    /clock stamps stay on the step grid, so with a time step that does not
    divide 10 ms the period is the nearest whole number of steps (halves
    round up): 9 ms at 0.003 s, 12 ms at 0.004 s, every step from 0.02 s on.
    """
    return max(1, math.floor(CLOCK_PERIOD_S / time_step + 0.5 + 1e-9))


class ClockPublisher:
    """The /clock stamps of one simulation, on ``publisher`` (a ``rosgraph_msgs/Clock`` one).

    ``time_step`` is the physics step (s); ``wall_clock`` the wall time (s)
    the token bucket refills by.
    """

    def __init__(self, publisher: Any, time_step: float,
                 wall_clock: Callable[[], float] = time.monotonic) -> None:
        self.publisher = publisher
        self._time_step = time_step
        # Physics steps between stamps.
        self.every = clock_period_steps(time_step)
        self._message = Clock()
        # Whether anybody reads /clock; True until the first batch asks.
        self.wanted = True
        # A stamp reached in this batch that has not left yet.
        self._pending = False
        self._throttle = Throttle(CLOCK_MIN_WALL_PERIOD_S, CLOCK_BURST, wall_clock)

    def period_line(self) -> str | None:
        """Return the start-up line saying the period, when it is not 10 ms (else None)."""
        period = self.every * self._time_step
        if abs(period - CLOCK_PERIOD_S) <= 1e-9:
            return None
        return (f'/clock every {self.every} steps ({period * 1e3:g} ms of sim time): the '
                'nearest whole number of time_step to 10 ms')

    def refresh_readers(self) -> None:
        """Ask whether anybody reads /clock (see :attr:`wanted`)."""
        self.wanted = self.publisher.get_subscription_count() > 0

    def steps_to_stamp(self, step: int) -> int:
        """Return the steps from ``step`` to the stamp a chunk cut at the stamps ends at.

        The next stamp while a token is there; without one the next stamps
        cannot leave anyway, so CLOCK_STAMPS_SKIPPED more.
        """
        every = self.every
        to_stamp = every - step % every
        return to_stamp if self._throttle.ready() else to_stamp + every * CLOCK_STAMPS_SKIPPED

    def publish_reached(self, step: int, chunk: int, cut_at_stamps: bool) -> None:
        """Publish, as tokens allow, the stamps the ``chunk`` steps after ``step`` reached.

        Cut at the stamps (factor 0), a chunk ends at one -- or runs past a few
        for want of tokens -- and only the newest may leave; paced, each stamp
        it reached may, oldest first.  One held back leaves at :meth:`end_batch`.
        """
        every = self.every
        end = step + chunk
        stamp = step - step % every + every  # the first grid stamp after ``step``
        if stamp > end:
            return
        throttle = self._throttle
        self._pending = True
        if cut_at_stamps:
            if end % every == 0 and throttle.allow():
                self._publish_at(end)
            return
        for grid_steps in range(stamp, end + 1, every):
            if throttle.allow():
                self._publish_at(grid_steps)
            else:
                self._pending = True

    def end_batch(self, steps: int) -> None:
        """At the end of a batch (at step ``steps``), publish the newest stamp still held back.

        It takes a token even if none is there: the next stamps wait for it.
        """
        if self._pending:
            self._throttle.take()
            self.publish_newest(steps)

    def publish_newest(self, steps: int) -> None:
        """Publish the newest grid stamp at or before step ``steps``."""
        self._publish_at(steps - steps % self.every)

    def _publish_at(self, grid_steps: int) -> None:
        self.publisher.publish(clock_message(grid_steps * self._time_step, self._message))
        self._pending = False
