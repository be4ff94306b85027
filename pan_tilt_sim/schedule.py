"""Periodic sim-time schedules: "publish every period, on the grid 0, period, 2 period...".

One helper for everything that happens at a rate of sim time -- the joint
state broadcaster, the camera, TF -- so that all of them forget their place
the same way when the simulation is reset (:meth:`PeriodicSchedule.reset`).
Due times are computed from the period, never accumulated, so no rounding
error builds up; a small tolerance keeps float sim times from skipping a slot.
No ROS, no PyBullet.
"""

from __future__ import annotations

import math

# Tolerance on "due": a sim time this close below a due time counts as on it.
DUE_EPSILON = 1e-9


class PeriodicSchedule:
    """Due times at 0, period, 2 period, ... of sim time; a missed slot is skipped, not repeated.

    Hot loops may test ``time + DUE_EPSILON < schedule.next_due`` themselves
    and call :meth:`advance` when due; everyone else calls :meth:`take`.
    """

    __slots__ = ('period', 'next_due')

    def __init__(self, period: float) -> None:
        if not (math.isfinite(period) and period > 0.0):
            raise ValueError(f'a schedule needs a finite period > 0 s, got {period}')
        self.period = period
        self.next_due = 0.0

    def is_due(self, time: float) -> bool:
        """Whether something is due at sim ``time``."""
        return time + DUE_EPSILON >= self.next_due

    def advance(self, time: float) -> None:
        """Move the next due time to the first grid point after ``time``."""
        period = self.period
        self.next_due = (math.floor((time + DUE_EPSILON) / period) + 1) * period

    def take(self, time: float) -> bool:
        """Return whether something is due at ``time``; if so, schedule the next one."""
        if time + DUE_EPSILON < self.next_due:
            return False
        self.advance(time)
        return True

    def due_step(self, time_step: float) -> int:
        """Return the first physics step (of ``time_step`` s) at which something is due."""
        return math.ceil((self.next_due - DUE_EPSILON) / time_step)

    def next_step(self, step: int, time_step: float) -> int:
        """Return the first step after ``step`` at or past the next due time."""
        return max(self.due_step(time_step), step + 1)

    def first_due_step(self, step: int, time_step: float) -> int:
        """Return the first step >= ``step`` at whose sim time (``step * time_step``) one is due.

        The step at which a loop testing :meth:`is_due` every step finds it
        due (:data:`DUE_EPSILON` is far above the rounding of either side).
        """
        return max(step, self.due_step(time_step))

    def reset(self) -> None:
        """Start again: the next call is due at once (as at sim time 0)."""
        self.next_due = 0.0


def steps_per_update(period: float, time_step: float) -> int:
    """Return after how many physics steps of ``time_step`` s ``period`` s have passed.

    The first whole number of steps whose time reaches the period (within
    :data:`DUE_EPSILON`), at least one: a controller's clock, as
    gz_ros2_control updates at the first step where the time since the last
    update reaches the control period.
    """
    return max(1, math.ceil((period - DUE_EPSILON) / time_step))
