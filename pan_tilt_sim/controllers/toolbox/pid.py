"""A PID controller (after control_toolbox::Pid), with gains as a validated value object.

* The integral term ``i * integral(error dt)`` is kept already multiplied by
  the gain, so changing gains live does not make it jump.  Its contribution
  to the output is always limited to [i_clamp_min, i_clamp_max].  As in
  control_toolbox, ``antiwindup`` says whether the accumulator itself is
  held within those bounds (true: the term recovers as soon as the error
  changes sign) or keeps integrating beyond them (false, control_toolbox's
  default: the term stays saturated until the excess has been integrated
  away).
* As in control_toolbox: a step of ``dt == 0`` changes nothing and returns
  the last output; ``dt < 0`` (or NaN) raises ValueError; a non-finite error
  or rate returns 0 and leaves the integrator untouched.
* The derivative acts on the measurement, not on the error, so a jump of the
  setpoint gives no derivative kick.  Callers that measure the rate directly
  (a joint's velocity for a position loop) pass it in; otherwise the rate is
  the finite difference of successive measurements.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any

GAIN_NAMES = ('p', 'i', 'd')
CLAMP_NAMES = ('i_clamp', 'i_clamp_min', 'i_clamp_max')
ANTIWINDUP = 'antiwindup'
_INF = math.inf


class GainsError(ValueError):
    """Gains that cannot be used; the message names the field."""


@dataclasses.dataclass(frozen=True)
class PidGains:
    """Proportional, integral and derivative gains and the integral clamp."""

    p: float = 0.0
    i: float = 0.0
    d: float = 0.0
    i_clamp_min: float = -math.inf
    i_clamp_max: float = math.inf
    antiwindup: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.antiwindup, bool):
            raise GainsError(f'{ANTIWINDUP}: {self.antiwindup!r} must be true or false')
        for name in GAIN_NAMES:
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise GainsError(f'{name}: {value!r} is not a number')
            if not math.isfinite(value) or value < 0.0:
                raise GainsError(f'{name}: {value!r} must be a finite number >= 0')
            object.__setattr__(self, name, float(value))
        for name in ('i_clamp_min', 'i_clamp_max'):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float) or math.isnan(value):
                raise GainsError(f'{name}: {value!r} is not a number')
            object.__setattr__(self, name, float(value))
        if self.i_clamp_min == math.inf or self.i_clamp_max == -math.inf:
            # The integral term would be pinned at infinity, and the output with it.
            raise GainsError(
                f'i_clamp_min ({self.i_clamp_min}) must be < inf and '
                f'i_clamp_max ({self.i_clamp_max}) > -inf')
        if self.i_clamp_min > self.i_clamp_max:
            raise GainsError(
                f'i_clamp_min ({self.i_clamp_min}) is greater than '
                f'i_clamp_max ({self.i_clamp_max})')

    @property
    def has_integral_clamp(self) -> bool:
        """Whether either bound of the integral term is finite."""
        return math.isfinite(self.i_clamp_min) or math.isfinite(self.i_clamp_max)

    @classmethod
    def from_mapping(cls, values: Mapping[str, Any]) -> PidGains:
        """Read ``{p, i, d, i_clamp | i_clamp_min/i_clamp_max}`` as ROS YAML writes them.

        ``i_clamp`` bounds the integral term symmetrically; the explicit
        ``i_clamp_min``/``i_clamp_max`` win where both are given.  A missing
        gain is zero; ``antiwindup`` (a bool) defaults to false.
        """
        if not isinstance(values, Mapping):
            raise GainsError(f'expected a mapping of gains, got {values!r}')
        known = set(GAIN_NAMES) | set(CLAMP_NAMES) | {ANTIWINDUP}
        unknown = sorted(set(values) - known)
        if unknown:
            raise GainsError(f"unknown field '{unknown[0]}' (known: {', '.join(sorted(known))})")
        fields: dict[str, Any] = {name: values[name] for name in GAIN_NAMES if name in values}
        if 'i_clamp' in values:
            bound = values['i_clamp']
            if isinstance(bound, bool) or not isinstance(bound, int | float) or not bound >= 0:
                raise GainsError(f'i_clamp: {bound!r} must be a number >= 0')
            fields['i_clamp_min'] = -bound
            fields['i_clamp_max'] = bound
        for name in ('i_clamp_min', 'i_clamp_max', ANTIWINDUP):
            if name in values:
                fields[name] = values[name]
        return cls(**fields)

    def with_default_clamp(self, bound: float) -> PidGains:
        """Return these gains, with the integral clamped to +-``bound`` unless a clamp was given."""
        if self.has_integral_clamp:
            return self
        return dataclasses.replace(self, i_clamp_min=-bound, i_clamp_max=bound)


class Pid:
    """PID on ``setpoint - measurement``; derivative on measurement."""

    __slots__ = ('_p', '_i', '_d', '_i_min', '_i_max', '_antiwindup', '_gains', '_integral',
                 '_last_measurement', '_output')

    def __init__(self, gains: PidGains) -> None:
        self.gains = gains
        self._integral = 0.0
        self._last_measurement = math.nan
        self._output = 0.0

    @property
    def gains(self) -> PidGains:
        """The current gains."""
        return self._gains

    @gains.setter
    def gains(self, gains: PidGains) -> None:
        # Plain floats in slots keep compute() free of attribute chains.
        self._gains = gains
        self._p, self._i, self._d = gains.p, gains.i, gains.d
        self._i_min, self._i_max = gains.i_clamp_min, gains.i_clamp_max
        self._antiwindup = gains.antiwindup

    @property
    def integral_term(self) -> float:
        """The integral term's present contribution to the output (within the clamp)."""
        integral = self._integral
        return self._i_min if integral < self._i_min else (
            self._i_max if integral > self._i_max else integral)

    def law_values(self) -> list[float]:
        """Return the gains and the state, for a step law row (:mod:`.step_law`).

        ``[p, i, d, i_clamp_min, i_clamp_max, antiwindup (0.0 / 1.0),
        integral, output, last_measurement]``.
        """
        return [self._p, self._i, self._d, self._i_min, self._i_max,
                1.0 if self._antiwindup else 0.0, self._integral, self._output,
                self._last_measurement]

    def restore(self, integral: float, output: float, last_measurement: float) -> None:
        """Take the state a compiled loop computed (see :meth:`law_values`)."""
        self._integral = integral
        self._output = output
        self._last_measurement = last_measurement

    def reset(self) -> None:
        """Zero the integral and the last output, and forget the last measurement."""
        self._integral = 0.0
        self._last_measurement = math.nan
        self._output = 0.0

    def compute(self, setpoint: float, measurement: float, dt: float,
                measurement_rate: float | None = None) -> float:
        """Return the control output for one step of ``dt`` seconds."""
        if not dt > 0.0:
            if dt == 0.0:
                return self._output
            raise ValueError(f'PID step dt must be >= 0 s, got {dt}')
        error = setpoint - measurement
        if measurement_rate is None:
            last = self._last_measurement
            measurement_rate = 0.0 if last != last else (measurement - last) / dt
            self._last_measurement = measurement
        if not (-_INF < error < _INF and -_INF < measurement_rate < _INF):
            return 0.0  # NaN fails both comparisons: the integrator is left as it was
        integral = self._integral + self._i * error * dt
        low, high = self._i_min, self._i_max
        term = low if integral < low else high if integral > high else integral
        self._integral = term if self._antiwindup else integral
        output = self._p * error + term - self._d * measurement_rate
        self._output = output
        return output
