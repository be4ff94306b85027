"""The ideal actuator: what drives a position or velocity interface that has no PID gains.

Gazebo does not put a PID between a position interface and the joint unless
it is given gains: gazebo_ros_control sets the joint's position, and
gz_ros2_control turns the position error into a joint velocity command
(``position_proportional_gain`` 0.1 per step) that the physics enforces with
at most the joint's effort limit.  Here, likewise (see the design notes).

Design notes: docs/design/controllers.md#actuatorpy.
"""

from __future__ import annotations

import math

# Share of the position error the velocity target closes per step, as
# gz_ros2_control's position_proportional_gain: stable for anything in (0, 2),
# critically damped near 1, and 0.1 does not exceed the speed limit catching up.
TRACKING_GAIN = 0.1
# rad/s^2 (m/s^2 on a prismatic joint): how fast a position setpoint speeds up
# and slows down.  URDF has no acceleration limits; 10 keeps step commands on
# UR, Franka and KUKA arms within 0.003 rad of overshoot, and light fingers
# still reach their speed limit within a few steps.
SETPOINT_ACCELERATION = 10.0
# A setpoint this close to its command is there.
ARRIVED = 1e-12


def tracking_target(setpoint: float, rate: float, position: float, period: float,
                    max_velocity: float) -> float:
    """Return the velocity target toward ``setpoint`` moving at ``rate``, within +-max_velocity."""
    target = rate + TRACKING_GAIN / period * (setpoint - position)
    return max_velocity if target > max_velocity else (
        -max_velocity if target < -max_velocity else target)


def ramp(setpoint: float, rate: float, command: float, period: float, max_velocity: float,
         acceleration: float = SETPOINT_ACCELERATION) -> tuple[float, float]:
    """Move ``setpoint`` (moving at ``rate``) one ``period`` toward ``command``.

    Speeds up and slows down at ``acceleration`` and never exceeds
    ``max_velocity``; lands exactly on the command and stops there.  Returns
    the new setpoint and rate.
    """
    delta = command - setpoint
    if -ARRIVED < delta < ARRIVED and rate == 0.0:
        return command, 0.0
    # The fastest rate from which the setpoint, slowing down by acceleration *
    # period every step, still stops exactly at the command: n steps of
    # braking from n * a * dt cover a * dt^2 * n (n + 1) / 2 (-> sqrt(2 a d)).
    step_change = acceleration * period
    braking_steps = math.sqrt(0.25 + 2.0 * abs(delta) / (step_change * period)) - 0.5
    wanted = min(max_velocity, step_change * braking_steps)
    if delta < 0.0:
        wanted = -wanted
    rate = rate + step_change if wanted > rate + step_change else (
        rate - step_change if wanted < rate - step_change else wanted)
    if abs(delta) <= abs(rate) * period * (1.0 + 1e-9) or -ARRIVED < delta < ARRIVED:
        return command, 0.0
    return setpoint + rate * period, rate
