"""Pacing sim time to wall time, in batches of steps.

rclpy timers cannot tick reliably at the physics rate, so the node ticks
slower and runs, at each tick, as many steps as wall time asks for: at
``real_time_factor`` r, after w wall seconds the simulation should have
run ``r * w / time_step`` steps.  When the machine cannot keep up, the debt
is dropped rather than paid in a burst -- the simulation then runs slower
than asked, as Gazebo does.

At factor 0 each tick runs as many steps as fill ``FAST_TICK_S`` of wall
time, judged from the pace of the ticks before: the executor's fixed cost
per tick then stays a small share of the tick whatever the robot costs per
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
# Sim seconds per wall second at most.  With time steps of 1 us or more, every figure
# below (steps due, the debt dropped) stays a finite number well inside a float's range.
MAX_REAL_TIME_FACTOR = 1000.0
# Steps of one paced tick at most, whatever the factor asks: a factor the machine cannot
# follow then costs ticks of bounded length (commands and services still get their turn)
# instead of one long catch-up batch.
MAX_PACED_BATCH_STEPS = 10_000


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
    """Tells each tick how many physics steps are due.

    ``real_time_factor`` lies in [0, MAX_REAL_TIME_FACTOR] and ``time_step``
    (seconds) is finite and > 0; anything else is a ValueError (the node's
    parameter checks refuse it first, with the parameter's name).
    """

    def __init__(self, real_time_factor: float, time_step: float,
                 clock: Callable[[], float] = time.monotonic) -> None:
        if not (math.isfinite(time_step) and time_step > 0.0):
            raise ValueError(f'time_step must be a finite number > 0, got {time_step}')
        self._time_step = time_step
        self._clock = clock
        self.real_time_factor = real_time_factor

    @property
    def real_time_factor(self) -> float:
        """Sim seconds per wall second (0: as fast as possible)."""
        return self._factor

    @real_time_factor.setter
    def real_time_factor(self, factor: float) -> None:
        if not 0.0 <= factor <= MAX_REAL_TIME_FACTOR:  # NaN fails too
            raise ValueError(
                f'real_time_factor must lie in [0, {MAX_REAL_TIME_FACTOR:g}], got {factor}')
        if not math.isfinite(MAX_CATCH_UP_S * factor / self._time_step):
            raise ValueError(f'real_time_factor {factor} at time_step {self._time_step} s '
                             'asks for more steps per second than a float holds')
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
        max_due = min(MAX_PACED_BATCH_STEPS,
                      max(1, math.ceil(MAX_CATCH_UP_S * self._factor / self._time_step)))
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
