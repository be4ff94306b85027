"""Joint limits as gazebo_ros_control's joint_limits_interface enforces them.

* Position commands are clamped to the URDF [lower, upper] (not for
  continuous joints); the setpoint then moves toward the command no faster
  than ``max_velocity`` (the URDF velocity limit) -- a "saturating" soft
  ramp, which JointPositionController.update applies step by step.
* Velocity commands are clamped to +-velocity limit.
* Efforts are clamped to +-effort limit.
"""

from __future__ import annotations

import math

from pan_tilt_sim.controllers.framework.base import CommandResult, bounded_command, clamp
from pan_tilt_sim.model.robot import JointSpec


class PositionLimits:
    """Position range and ramp rate of one joint's position setpoint."""

    __slots__ = ('lower', 'upper', 'max_velocity')

    def __init__(self, joint: JointSpec) -> None:
        limited = joint.has_position_limits
        self.lower = joint.lower if limited else -math.inf
        self.upper = joint.upper if limited else math.inf
        self.max_velocity = joint.velocity_limit

    def check(self, command: float) -> tuple[float, CommandResult]:
        """Clamp a position command into range; reject non-finite values."""
        return bounded_command(command, self.lower, self.upper)



def check_velocity(joint: JointSpec, command: float) -> tuple[float, CommandResult]:
    """Clamp a velocity command to the joint's velocity limit; reject non-finite values."""
    return bounded_command(command, -joint.velocity_limit, joint.velocity_limit)


def check_effort(joint: JointSpec, command: float) -> tuple[float, CommandResult]:
    """Clamp an effort command to the joint's effort limit; reject non-finite values."""
    return bounded_command(command, -joint.effort_limit, joint.effort_limit)


def clamp_effort(effort: float, limit: float) -> float:
    """Limit ``effort`` to +-``limit``."""
    return clamp(effort, -limit, limit)
