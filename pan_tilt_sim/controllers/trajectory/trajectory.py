"""Joint trajectories as plain values, and their interpolation in sim time.

:class:`JointTrajectory` is what a ``trajectory_msgs/msg/JointTrajectory``
becomes on its way to a controller (the node converts; nothing here knows
rclpy).  :class:`TrajectoryPlan` is a trajectory fixed in sim time, with
one knot per point, that the controller samples every physics step:

* between knots that all carry velocities, by cubic Hermite interpolation
  (positions and velocities both match at every knot);
* otherwise linearly (constant velocity on each segment);
* after the last knot it holds the last positions at zero velocity.

Sampling fills caller-owned lists and keeps its place between calls, so a
step costs a few float operations per joint and allocates no containers.
"""

from __future__ import annotations

import dataclasses
from collections.abc import MutableSequence, Sequence


@dataclasses.dataclass(frozen=True)
class TrajectoryPoint:
    """One waypoint: positions (and optionally velocities) at ``time_from_start`` s.

    Accelerations and efforts are carried for validation only: interpolation
    uses positions and velocities.
    """

    time_from_start: float
    positions: tuple[float, ...]
    velocities: tuple[float, ...] = ()
    accelerations: tuple[float, ...] = ()
    efforts: tuple[float, ...] = ()


@dataclasses.dataclass(frozen=True)
class JointTrajectory:
    """Waypoints for named joints, starting at sim time ``start_time`` (None: now)."""

    joint_names: tuple[str, ...]
    points: tuple[TrajectoryPoint, ...]
    start_time: float | None = None


class TrajectoryPlan:
    """Knots at absolute sim times; velocities per knot, or None for linear segments."""

    __slots__ = ('times', 'positions', 'velocities', '_segment', '_joints')

    def __init__(self, times: Sequence[float], positions: Sequence[Sequence[float]],
                 velocities: Sequence[Sequence[float]] | None) -> None:
        self.times = list(times)
        self.positions = [list(knot) for knot in positions]
        self.velocities = None if velocities is None else [list(knot) for knot in velocities]
        self._segment = 0
        self._joints = range(len(self.positions[0]))

    @property
    def end_time(self) -> float:
        """Sim time of the last knot."""
        return self.times[-1]

    def sample(self, time: float, positions: MutableSequence[float],
               velocities: MutableSequence[float]) -> None:
        """Write the desired positions and velocities at ``time`` into the given lists."""
        times = self.times
        last = len(times) - 1
        if time >= times[last] or time < times[0]:
            self._hold(last if time >= times[last] else 0, positions, velocities)
            return
        segment = self._segment
        if time < times[segment]:  # time went back (a reset): search from the start
            segment = 0
        while time >= times[segment + 1]:
            segment += 1
        self._segment = segment
        t0 = times[segment]
        duration = times[segment + 1] - t0
        p0 = self.positions[segment]
        p1 = self.positions[segment + 1]
        if self.velocities is None:
            for joint in self._joints:
                slope = (p1[joint] - p0[joint]) / duration
                positions[joint] = p0[joint] + slope * (time - t0)
                velocities[joint] = slope
            return
        v0 = self.velocities[segment]
        v1 = self.velocities[segment + 1]
        s = (time - t0) / duration
        s2 = s * s
        s3 = s2 * s
        # Cubic Hermite basis functions of s, and their derivatives d/ds.
        h00 = 2.0 * s3 - 3.0 * s2 + 1.0
        h10 = s3 - 2.0 * s2 + s
        h11 = s3 - s2
        d00 = 6.0 * (s2 - s)
        d10 = 3.0 * s2 - 4.0 * s + 1.0
        d11 = 3.0 * s2 - 2.0 * s
        for joint in self._joints:
            start, end = p0[joint], p1[joint]
            positions[joint] = (h00 * start + (1.0 - h00) * end
                                + duration * (h10 * v0[joint] + h11 * v1[joint]))
            velocities[joint] = (d00 * (start - end) / duration
                                 + d10 * v0[joint] + d11 * v1[joint])

    def at(self, time: float) -> tuple[list[float], list[float], list[float]]:
        """Return the desired positions, velocities and accelerations at ``time``.

        Leaves :meth:`sample`'s place alone (a query between updates).  Before
        the first knot and from the last on, the knot's positions at rest;
        linear segments have no acceleration.
        """
        times = self.times
        last = len(times) - 1
        count = len(self._joints)
        if time >= times[last] or time < times[0]:
            knot = last if time >= times[last] else 0
            return list(self.positions[knot]), [0.0] * count, [0.0] * count
        segment = self._segment if time >= times[self._segment] else 0  # sample's place: a hint
        while time >= times[segment + 1]:
            segment += 1
        positions, velocities = [0.0] * count, [0.0] * count
        saved, self._segment = self._segment, segment
        self.sample(time, positions, velocities)
        self._segment = saved
        if self.velocities is None:
            return positions, velocities, [0.0] * count
        t0 = times[segment]
        duration = times[segment + 1] - t0
        s = (time - t0) / duration
        p0, p1 = self.positions[segment], self.positions[segment + 1]
        v0, v1 = self.velocities[segment], self.velocities[segment + 1]
        # Second derivatives d2/ds2 of the cubic Hermite basis functions.
        e00, e10, e11 = 12.0 * s - 6.0, 6.0 * s - 4.0, 6.0 * s - 2.0
        accelerations = [(e00 * (p0[joint] - p1[joint]) / duration
                          + e10 * v0[joint] + e11 * v1[joint]) / duration
                         for joint in self._joints]
        return positions, velocities, accelerations

    def _hold(self, knot: int, positions: MutableSequence[float],
              velocities: MutableSequence[float]) -> None:
        held = self.positions[knot]
        for joint in self._joints:
            positions[joint] = held[joint]
            velocities[joint] = 0.0
