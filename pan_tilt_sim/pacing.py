"""Pacing sim time to wall time, in batches of steps.

rclpy timers cannot tick reliably at the physics rate, so the node ticks
slower and runs, at each tick, as many steps as wall time asks for: at
``real_time_factor`` r, after w wall seconds the simulation should have
run ``r * w / time_step`` steps.  When the machine cannot keep up, the debt
is dropped rather than paid in a burst -- the simulation then runs slower
than asked, as Gazebo does.  At factor 0 every tick runs a fixed batch.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

# Steps per tick at real_time_factor 0: large enough that the executor's
# per-tick cost is small, small enough that commands are picked up often.
FAST_BATCH_STEPS = 100
# Debt beyond this much wall time is dropped instead of caught up.
MAX_CATCH_UP_S = 0.1
# Wall clocks are floats: a step due "exactly now" must not round down.
STEP_EPSILON = 1e-6


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

    def steps_due(self) -> int:
        """Return the steps to run now; the caller runs exactly that many."""
        if self.fast:
            return FAST_BATCH_STEPS
        now = self._clock()
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
