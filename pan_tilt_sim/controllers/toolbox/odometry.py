"""Differential-drive odometry, as diff_drive_controller's (jazzy): pose and twist in odom.

From the wheels' positions (rad, each side's mean), their velocities, or
the commanded twist (open loop), the robot's displacement per update is
integrated exactly along an arc (second-order Runge-Kutta when the turn is
below 1e-6 rad).  The reported twist is a rolling mean over the last
``window`` updates.  Updates closer than 0.1 ms to the previous one are
skipped, as upstream: the wheels' motion then counts at the next one.
Units: m, rad, s.  Pure Python.
"""

from __future__ import annotations

import collections
import math

MIN_INTERVAL = 1e-4  # s: updates closer together than this are skipped, as upstream
STRAIGHT = 1e-6  # rad: a smaller turn per update is integrated as a straight step


class RollingMean:
    """The mean of the last ``size`` values."""

    def __init__(self, size: int) -> None:
        self._values: collections.deque[float] = collections.deque(maxlen=max(1, size))
        self._sum = 0.0

    def add(self, value: float) -> float:
        """Take ``value``; return the mean of the window."""
        values = self._values
        if len(values) == values.maxlen:
            self._sum -= values[0]
        values.append(value)
        self._sum += value
        return self._sum / len(values)


class Odometry:
    """The robot's pose (x, y, heading) and twist (linear, angular) from its wheels."""

    def __init__(self, wheel_separation: float, left_radius: float, right_radius: float,
                 window: int = 10) -> None:
        self.wheel_separation = wheel_separation
        self.left_radius = left_radius
        self.right_radius = right_radius
        self._window = window
        self.reset()

    def reset(self, time: float = 0.0, left_position: float = 0.0,
              right_position: float = 0.0) -> None:
        """Back to the origin at sim ``time``; the wheels' positions now are the reference."""
        self.x = 0.0
        self.y = 0.0
        self.heading = 0.0
        self.linear = 0.0
        self.angular = 0.0
        self._time = time
        self._left = left_position * self.left_radius
        self._right = right_position * self.right_radius
        self._linear_mean = RollingMean(self._window)
        self._angular_mean = RollingMean(self._window)

    def update(self, left_position: float, right_position: float, time: float) -> bool:
        """Integrate the wheels' travel since the last update (positions in rad).

        Returns False (nothing changed) when less than :data:`MIN_INTERVAL` passed.
        """
        if time - self._time < MIN_INTERVAL:
            return False
        left = left_position * self.left_radius
        right = right_position * self.right_radius
        left_travel, right_travel = left - self._left, right - self._right
        self._left, self._right = left, right
        return self.update_from_travel(left_travel, right_travel, time)

    def update_from_travel(self, left_travel: float, right_travel: float, time: float) -> bool:
        """Integrate each side's travel (m) since the last update; False if too soon."""
        dt = time - self._time
        if dt < MIN_INTERVAL:
            return False
        linear = (left_travel + right_travel) * 0.5
        angular = (right_travel - left_travel) / self.wheel_separation
        self._integrate(linear, angular)
        self._time = time
        self.linear = self._linear_mean.add(linear / dt)
        self.angular = self._angular_mean.add(angular / dt)
        return True

    def update_open_loop(self, linear: float, angular: float, time: float) -> None:
        """Integrate the commanded twist (m/s, rad/s) over the time since the last update."""
        dt = time - self._time
        self._time = time
        self.linear = linear
        self.angular = angular
        self._integrate(linear * dt, angular * dt)

    def _integrate(self, linear: float, angular: float) -> None:
        """Move by ``linear`` metres while turning ``angular`` radians."""
        if abs(angular) < STRAIGHT:
            direction = self.heading + angular * 0.5
            self.x += linear * math.cos(direction)
            self.y += linear * math.sin(direction)
            self.heading += angular
            return
        before = self.heading
        radius = linear / angular
        self.heading += angular
        self.x += radius * (math.sin(self.heading) - math.sin(before))
        self.y -= radius * (math.cos(self.heading) - math.cos(before))
