"""A drive's body-twist command: taken from its topic, refused when not finite or stale.

The drive controllers and the Gazebo diff-drive plugins take a
``geometry_msgs`` twist on a command topic.  :class:`TwistCommand` keeps the
last accepted one, planar and stamped, and says why the last refused one was
refused (the command topic's problem callback); :class:`TwistCommanded`
gives a unit the two topic callbacks over it.  :func:`twist_references` and
:func:`planar_references` make the reference interfaces a chainable drive
exports.  Pure Python.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from pan_tilt_sim.controllers.framework.base import CommandResult, Reference
from pan_tilt_sim.controllers.framework.surface import StampedTwist

# The reference interfaces of a chainable drive, in upstream's order.
TWIST_AXES = ('linear/x', 'linear/y', 'angular/z')


def twist_references(controller: str) -> dict[str, Reference]:
    """Return ``<controller>/linear/x/velocity``, ``.../linear/y/...``, ``.../angular/z/...``."""
    names = [f'{controller}/{axis}/velocity' for axis in TWIST_AXES]
    return {name: Reference(name) for name in names}


def planar_references(controller: str) -> dict[str, Reference]:
    """Return ``<controller>/linear/velocity`` and ``<controller>/angular/velocity``."""
    names = [f'{controller}/{axis}/velocity' for axis in ('linear', 'angular')]
    return {name: Reference(name) for name in names}


class TwistCommand:
    """The last accepted twist of one command topic, and why the last refused one was refused.

    ``topic``: how refusals name the topic (``cmd_vel``, ``reference``);
    ``sideways``: ``linear.y`` counts (holonomic bases), else it is dropped;
    ``timeout_field``: the parameter named when a stale twist is refused;
    ``stale_at_timeout``: a twist exactly ``timeout`` old is stale too.
    """

    def __init__(self, topic: str, *, sideways: bool = False, timeout_field: str = '',
                 stale_at_timeout: bool = False) -> None:
        self.topic = topic
        self.sideways = sideways
        self.timeout_field = timeout_field
        self.stale_at_timeout = stale_at_timeout
        # (stamp s, (x, y, 0) m/s, (0, 0, z) rad/s); None: none taken since the last reset.
        self.latest: StampedTwist | None = None
        self._problem = ''

    def take(self, value: StampedTwist, now: float = 0.0, timeout: float = 0.0) -> CommandResult:
        """Keep ``value``, or refuse it and say why.

        Refused: a counted part not finite, or, with ``timeout`` > 0 (s of sim
        time), a stamp that long before ``now``.  An unstamped twist gets ``now``.
        """
        linear_x, linear_y, angular = value.linear[0], value.linear[1], value.angular[2]
        parts = (linear_x, linear_y, angular) if self.sideways else (linear_x, angular)
        if not all(math.isfinite(part) for part in parts):
            sideways = f'linear.y {linear_y!r}, ' if self.sideways else ''
            self._problem = (f'ignored {self.topic} (linear.x {linear_x!r}, {sideways}'
                             f'angular.z {angular!r}): not finite numbers')
            return CommandResult.REJECTED
        stamp = value.stamp if value.stamp > 0.0 else now
        age = now - stamp
        if timeout > 0.0 and (age >= timeout if self.stale_at_timeout else age > timeout):
            self._problem = (f'ignored {self.topic} stamped {stamp:.4f} s: {age:.4f} s old at '
                             f'sim time {now:.4f} s, more than {self.timeout_field} '
                             f'({timeout:g} s)')
            return CommandResult.REJECTED
        self.latest = StampedTwist(stamp, (linear_x, linear_y if self.sideways else 0.0, 0.0),
                                   (0.0, 0.0, angular))
        return CommandResult.ACCEPTED

    def planar(self) -> tuple[float, float]:
        """Return the latest twist's ``(linear.x, angular.z)``; (0, 0) if none was taken."""
        latest = self.latest
        return (0.0, 0.0) if latest is None else (latest.linear[0], latest.angular[2])

    def problem(self, value: Any, result: CommandResult) -> str:
        """Describe the last refused twist (the command topic's problem callback)."""
        return self._problem


class TwistCommanded:
    """Mixin of the units whose command topic feeds a :class:`TwistCommand`, ``_command``.

    A twist goes stale after the parameter its ``timeout_field`` names (s of
    sim time; none: never), counted from the unit's last update, ``_time``.
    """

    _command: TwistCommand
    _time: float = 0.0
    params: Mapping[str, Any]

    def set_command(self, value: StampedTwist) -> CommandResult:
        """Take a twist (from the subscription; cheap): refuse non-finite or stale ones."""
        command = self._command
        timeout = self.params[command.timeout_field] if command.timeout_field else 0.0
        result = command.take(value, self._time, timeout)
        if result is CommandResult.ACCEPTED:
            self.twist_taken()
        return result

    def twist_taken(self) -> None:
        """Do nothing; a unit may react to a taken twist here (from the subscription: cheap)."""

    def command_problem(self, value: Any, result: CommandResult) -> str:
        """Describe the last refused twist."""
        return self._command.problem(value, result)
