"""Rates (Hz) a controller, plugin or sensor acts at: each needs a finite period. No ROS.

A rate above 0 may still be so small that its period, 1 / rate, overflows to
infinity (5e-324 Hz): nothing would ever be due.  :func:`rate_problem` says so.
"""

from __future__ import annotations

import math


def rate_problem(value: float, *, zero_allowed: bool = False) -> str | None:
    """Say why ``value`` (Hz) is no rate to act at, or None.

    ``zero_allowed``: 0 is taken too (where it means "every step").
    """
    if zero_allowed and value == 0.0:
        return None
    if not (value > 0.0 and math.isfinite(value) and math.isfinite(1.0 / value)):
        least = ' (or 0)' if zero_allowed else ''
        return f'{value!r} must be a rate > 0 Hz{least} whose period 1 / rate is finite'
    return None
