"""Value, rate and jerk limits of one velocity, as control_toolbox's RateLimiter (jazzy).

diff_drive_controller's SpeedLimiter limits the commanded linear and angular
velocity with it.  A limit that is NaN is off.  An unset lower bound is
minus the upper one.  The rate limits depend on the direction of travel:
while the previous value ``v0`` is positive the change per second lies in
[``max_deceleration``, ``max_acceleration``]; while it is negative in
[``max_acceleration_reverse``, ``max_deceleration_reverse``]; at zero in
[``max_acceleration_reverse``, ``max_acceleration``].  An unset deceleration
is the acceleration of its direction (``max_deceleration`` = minus
``max_acceleration``...); an unset reverse bound mirrors the forward one.
The jerk limit applies only while the change grows in the direction of
motion (control_toolbox's guard against closed-loop oscillation).  Pure
Python.
"""

from __future__ import annotations

import dataclasses
import math


def _given(value: float) -> bool:
    return not math.isnan(value)


def _clamp(value: float, lower: float, upper: float) -> float:
    return lower if value < lower else upper if value > upper else value


class InvalidLimitsError(ValueError):
    """The limits contradict each other (a lower bound above its upper bound)."""


@dataclasses.dataclass(frozen=True)
class RateLimits:
    """The limits as diff_drive_controller's parameters give them (NaN: not given).

    Units: the value's (m/s or rad/s), per second, per second squared.
    """

    min_velocity: float = math.nan
    max_velocity: float = math.nan
    max_acceleration_reverse: float = math.nan
    max_acceleration: float = math.nan
    max_deceleration: float = math.nan
    max_deceleration_reverse: float = math.nan
    min_jerk: float = math.nan
    max_jerk: float = math.nan


class RateLimiter:
    """Limits one velocity command step by step (see the module docstring).

    Raises :class:`InvalidLimitsError`, naming the pair, when a lower bound
    exceeds its upper bound.
    """

    def __init__(self, limits: RateLimits) -> None:
        self.limits = limits
        self._values = _given(limits.max_velocity)
        low_value = limits.min_velocity if _given(limits.min_velocity) else -limits.max_velocity
        if self._values and low_value > limits.max_velocity:
            raise InvalidLimitsError(f'min_velocity {low_value:g} > max_velocity '
                                f'{limits.max_velocity:g}')
        self._low_value, self._high_value = low_value, limits.max_velocity
        self._rates = _given(limits.max_acceleration)
        accelerate = limits.max_acceleration
        reverse = (limits.max_acceleration_reverse if _given(limits.max_acceleration_reverse)
                   else -accelerate)
        if self._rates and reverse > accelerate:
            raise InvalidLimitsError(f'max_acceleration_reverse {reverse:g} > max_acceleration '
                                f'{accelerate:g}')
        decelerate_reverse = (limits.max_deceleration_reverse
                              if _given(limits.max_deceleration_reverse) else accelerate)
        decelerate = limits.max_deceleration if _given(limits.max_deceleration) else reverse
        if self._rates and decelerate > decelerate_reverse:
            raise InvalidLimitsError(f'max_deceleration {decelerate:g} > max_deceleration_reverse '
                                f'{decelerate_reverse:g}')
        # (lower, upper) change per second while moving forward, backward, from rest.
        self._forward = (decelerate, accelerate)
        self._backward = (reverse, decelerate_reverse)
        self._from_rest = (reverse, accelerate)
        self._jerks = _given(limits.max_jerk)
        low_jerk = limits.min_jerk if _given(limits.min_jerk) else -limits.max_jerk
        if self._jerks and low_jerk > limits.max_jerk:
            raise InvalidLimitsError(f'min_jerk {low_jerk:g} > max_jerk {limits.max_jerk:g}')
        self._low_jerk, self._high_jerk = low_jerk, limits.max_jerk

    def limit(self, value: float, previous: float, before: float, dt: float) -> float:
        """Return ``value`` limited: jerk, then rate, then value (control_toolbox's order).

        ``previous`` and ``before`` are the limited values of the last two
        steps, ``dt`` the step (s).
        """
        if self._jerks:
            change, last_change = value - previous, previous - before
            if (change - last_change) * change > 0.0:
                squared = dt * dt
                value = previous + last_change + _clamp(
                    change - last_change, self._low_jerk * squared, self._high_jerk * squared)
        if self._rates:
            lower, upper = (self._forward if previous > 0.0 else self._backward
                            if previous < 0.0 else self._from_rest)
            value = previous + _clamp(value - previous, lower * dt, upper * dt)
        if self._values:
            value = _clamp(value, self._low_value, self._high_value)
        return value
