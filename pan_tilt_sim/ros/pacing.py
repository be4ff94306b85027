"""Pacing sim time to wall time, in batches of steps.

rclpy timers cannot tick reliably at the physics rate, so the node ticks
slower and runs, at each tick, as many steps as wall time asks for: at
``real_time_factor`` r, after w wall seconds the simulation should have
run ``r * w / time_step`` steps.  When the machine cannot keep up, the debt
is dropped rather than paid in a burst -- the simulation then runs slower
than asked, as Gazebo does.

At factor 0 each tick runs as many steps as fill ``FAST_TICK_S`` of wall
time, judged from the pace of the ticks before: the executor's fixed cost
per tick (~0.1 ms) then stays a few percent whatever the robot costs per
step, and commands and parameter changes are still taken within a few ms.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

# Wall seconds of stepping per tick at real_time_factor 0.
FAST_TICK_S = 0.005
# The first batch at real_time_factor 0, before the pace is known.
FAST_BATCH_STEPS = 100
# A batch at most doubles from one tick to the next, so one fast tick
# (the clock jumping, a quiet moment) cannot make the next one long.
MAX_BATCH_GROWTH = 2
# Debt beyond this much wall time is dropped instead of caught up.
MAX_CATCH_UP_S = 0.1
# Wall clocks are floats: a step due "exactly now" must not round down.
STEP_EPSILON = 1e-6


class Throttle:
    """A token bucket: on average one event per ``period`` of wall time, bursts of ``burst``."""

    def __init__(self, period: float, burst: int,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self._period = period
        self._burst = float(burst)
        self._clock = clock
        self._tokens = self._burst
        self._refilled = clock()

    def ready(self) -> bool:
        """Whether a token is there now (none is taken)."""
        self._refill()
        return self._tokens >= 1.0

    def allow(self) -> bool:
        """Take a token if one is there; return whether the event may happen now."""
        self._refill()
        allowed = self._tokens >= 1.0
        if allowed:
            self._tokens -= 1.0
        return allowed

    def take(self) -> None:
        """Take a token, there or not: a debt that later refills pay off first."""
        self._refill()
        self._tokens -= 1.0

    def _refill(self) -> None:
        now = self._clock()
        self._tokens = min(self._burst, self._tokens + (now - self._refilled) / self._period)
        self._refilled = now


class Pacer:
    """Tells each tick how many physics steps are due."""

    def __init__(self, real_time_factor: float, time_step: float,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self._time_step = time_step
        self._clock = clock
        self.real_time_factor = real_time_factor

    @property
    def real_time_factor(self) -> float:
        """Sim seconds per wall second (0: as fast as possible)."""
        return self._factor

    @real_time_factor.setter
    def real_time_factor(self, factor: float) -> None:
        self._factor = factor
        self.restart()

    @property
    def fast(self) -> bool:
        """Whether steps run as fast as possible."""
        return self._factor == 0.0

    def restart(self) -> None:
        """Forget the past: the next call starts a fresh wall-time reference."""
        self._start: float | None = None
        self._done = 0
        self._batch = 0

    def steps_due(self) -> int:
        """Return the steps to run now; the caller runs exactly that many."""
        now = self._clock()
        if self.fast:
            return self._fast_batch(now)
        if self._start is None:
            self._start = now
        target = math.floor((now - self._start) * self._factor / self._time_step + STEP_EPSILON)
        due = target - self._done
        max_due = max(1, math.ceil(MAX_CATCH_UP_S * self._factor / self._time_step))
        if due > max_due:
            # Behind by more than we should catch up: run the cap, drop the rest.
            self._start = now - (self._done + max_due) * self._time_step / self._factor
            due = max_due
        self._done += max(due, 0)
        return max(due, 0)

    def _fast_batch(self, now: float) -> int:
        # Steps per wall second over the last tick (its batch and the executor's
        # time since), scaled to fill FAST_TICK_S.
        if self._start is None or self._batch == 0:
            batch = FAST_BATCH_STEPS
        else:
            elapsed = now - self._start
            batch = self._batch * MAX_BATCH_GROWTH
            if elapsed > 0.0:
                batch = max(1, min(batch, round(self._batch * FAST_TICK_S / elapsed)))
        self._start = now
        self._batch = batch
        return batch
