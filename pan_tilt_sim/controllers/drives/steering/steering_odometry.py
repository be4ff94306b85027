"""Steering kinematics, as steering_controllers_library's (jazzy): odometry and wheel commands.

Three configurations, by their number of steering and traction joints:

* **bicycle**: one steering joint (angle ``phi``), one traction wheel;
* **tricycle**: one steering joint, two traction wheels on an axle of
  ``traction_track`` (right, then left);
* **Ackermann**: two steering joints on an axle of ``steering_track`` and
  two traction wheels (each pair right, then left).

Design notes: docs/design/controllers.md#steering_odometrypy.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence

from pan_tilt_sim.controllers.toolbox.odometry import RollingMean

MIN_INTERVAL = 1e-4  # s: a shorter update moves the pose but is not averaged, as upstream
NEAR_ZERO = 1e-6  # rad (or rad per update): treated as zero, as upstream's is_close_to_zero
# Reduce the wheel speed until the steering is there: full speed within 30 degrees of the
# commanded angle, then cos(error) / cos(30 degrees), the error capped just below 90 degrees.
FULL_SPEED_ERROR = math.pi / 6.0
MAX_SLOWDOWN_ERROR = 1.5608


class Configuration(enum.Enum):
    """The kinematic configuration: (steering joints, traction joints)."""

    BICYCLE = (1, 1)
    TRICYCLE = (1, 2)
    ACKERMANN = (2, 2)

    @property
    def steering_joints(self) -> int:
        """How many steering joints it has."""
        return self.value[0]

    @property
    def traction_joints(self) -> int:
        """How many traction joints it has."""
        return self.value[1]


class SteeringKinematics:
    """Pose (x, y, heading), twist (linear, angular) and wheel commands of a steered base."""

    def __init__(self, configuration: Configuration, wheelbase: float, radius: float,
                 traction_track: float = 0.0, steering_track: float = 0.0,
                 window: int = 10) -> None:
        self.configuration = configuration
        self.wheelbase = wheelbase
        self.radius = radius
        self.traction_track = traction_track
        self.steering_track = steering_track
        self._window = window
        self.reset()

    def reset(self, traction_positions: Sequence[float] = ()) -> None:
        """Back to the origin at rest; the traction wheels' positions now (rad) count from here."""
        self.x = 0.0
        self.y = 0.0
        self.heading = 0.0
        self.linear = 0.0
        self.angular = 0.0
        self.steering_angle = 0.0  # the last measured (virtual, centre) steering angle, rad
        self._positions = list(traction_positions) or [0.0] * self.configuration.traction_joints
        self._linear_mean = RollingMean(self._window)
        self._angular_mean = RollingMean(self._window)

    # --- forward kinematics: the odometry ---------------------------------------------------

    def update_from_positions(self, traction_positions: Sequence[float],
                              steering_positions: Sequence[float], dt: float) -> None:
        """Integrate from the traction wheels' positions (rad) and the steering angles (rad)."""
        velocities = [(position - old) / dt
                      for position, old in zip(traction_positions, self._positions, strict=True)]
        self._positions = list(traction_positions)
        self.update_from_velocities(velocities, steering_positions, dt)

    def update_from_velocities(self, traction_velocities: Sequence[float],
                               steering_positions: Sequence[float], dt: float) -> None:
        """Integrate from the traction wheels' velocities (rad/s) and the steering angles (rad)."""
        if self.configuration is Configuration.ACKERMANN:
            right, left = steering_positions
            half, base = self.steering_track / 2.0, self.wheelbase
            right = math.atan(base * math.tan(right) / (base - half * math.tan(right)))
            left = math.atan(base * math.tan(left) / (base + half * math.tan(left)))
            self.steering_angle = (right + left) / 2.0
        else:
            self.steering_angle = steering_positions[0]
        if self.configuration is Configuration.BICYCLE:
            linear = traction_velocities[0] * self.radius
        else:
            linear = self._axle_speed(*traction_velocities, self.steering_angle)
        angular = math.tan(self.steering_angle) * linear / self.wheelbase
        self._integrate(linear, angular, dt)
        if dt < MIN_INTERVAL:
            return
        self.linear = self._linear_mean.add(linear)
        self.angular = self._angular_mean.add(angular)

    def update_from_twist(self, linear: float, angular: float, dt: float) -> None:
        """Integrate a measured twist (m/s, rad/s) over ``dt``; add it to the rolling means."""
        self._integrate(linear, angular, dt)
        self.linear = self._linear_mean.add(linear)
        self.angular = self._angular_mean.add(angular)

    def update_open_loop(self, linear: float, angular: float, dt: float) -> None:
        """Integrate the commanded twist (m/s, rad/s) over ``dt``."""
        self.linear, self.angular = linear, angular
        self._integrate(linear, angular, dt)

    def _axle_speed(self, right: float, left: float, steering: float) -> float:
        """Return the speed (m/s) of a two-wheel axle's centre from its wheels (rad/s)."""
        right, left = right * self.radius, left * self.radius
        tangent = math.tan(steering)
        if tangent == 0.0:
            return (right + left) / 2.0
        turning = self.wheelbase / tangent
        half = self.traction_track / 2.0
        return (right * turning / (turning + half) + left * turning / (turning - half)) / 2.0

    def _integrate(self, linear: float, angular: float, dt: float) -> None:
        """Move by ``linear * dt`` metres while turning ``angular * dt`` radians."""
        turn = angular * dt
        if abs(turn) < NEAR_ZERO:
            direction = self.heading + turn / 2.0
            self.x += linear * dt * math.cos(direction)
            self.y += linear * dt * math.sin(direction)
            self.heading += turn
            return
        before = self.heading
        radius = linear * dt / turn
        self.heading += turn
        self.x += radius * (math.sin(self.heading) - math.sin(before))
        self.y -= radius * (math.cos(self.heading) - math.cos(before))

    # --- inverse kinematics: the wheel commands -----------------------------------------------

    def steering_for(self, linear: float, angular: float) -> float:
        """Return the (virtual, centre) steering angle (rad) of a twist; 0 where undefined."""
        try:
            phi = math.atan(angular * self.wheelbase / linear)
        except ZeroDivisionError:
            phi = math.copysign(math.pi / 2.0, angular) if angular else 0.0
        return phi if math.isfinite(phi) else 0.0

    def commands(self, linear: float, angular: float, *, open_loop: bool = False,
                 slow_until_steered: bool = False) -> tuple[list[float], list[float]]:
        """Return the traction wheels' velocities (rad/s) and the steering angles (rad).

        Each list is right then left where there are two.  The traction axle's
        wheel speeds follow the measured steering angle (the commanded one
        with ``open_loop``); ``slow_until_steered`` scales the speed down
        while the steering is far from its command
        (``reduce_wheel_speed_until_steering_reached``).
        """
        phi = self.steering_for(linear, angular)
        steered = phi if open_loop else self.steering_angle
        speed = linear / self.radius
        if slow_until_steered and not open_loop:
            error = abs(self.steering_angle - phi)
            if error >= FULL_SPEED_ERROR:
                speed *= math.cos(min(error, MAX_SLOWDOWN_ERROR)) / math.cos(FULL_SPEED_ERROR)
        configuration = self.configuration
        if configuration is Configuration.BICYCLE:
            return [speed], [phi]
        if abs(steered) < NEAR_ZERO:
            traction = [speed, speed]
        else:
            turning = self.wheelbase / math.tan(steered)
            half = self.traction_track / 2.0
            traction = [speed * (turning + half) / turning, speed * (turning - half) / turning]
        if configuration is Configuration.TRICYCLE:
            return traction, [phi]
        if abs(steered) < NEAR_ZERO:
            return traction, [phi, phi]
        along = 2.0 * self.wheelbase * math.cos(phi)
        across = self.steering_track * math.sin(phi)
        rise = 2.0 * self.wheelbase * math.sin(phi)
        return traction, [math.atan2(rise, along + across), math.atan2(rise, along - across)]
