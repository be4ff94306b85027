"""``velocity_controllers/`` and ``effort_controllers/JointVelocityController``.

The command (rad/s or m/s) is clamped to the joint's velocity limit; a PID
on the velocity error gives the joint effort, clamped to the effort limit.
The derivative acts on the measured velocity (its finite difference), so a
step in the command gives no kick.  Before the first command the target
velocity is zero.
"""

from __future__ import annotations

from pan_tilt_sim.controllers.base import CommandResult
from pan_tilt_sim.controllers.limits import check_velocity
from pan_tilt_sim.controllers.pid import PidGains
from pan_tilt_sim.controllers.single_joint import PidJointController

# Proportional-only by default: effort = 10 N*m per rad/s of error, a
# first-order loop that is stable for any inertia and damping.
DEFAULT_VELOCITY_GAINS = PidGains(p=10.0)


class JointVelocityController(PidJointController):
    """Velocity command -> effort, through a PID."""

    type_names = ('velocity_controllers/JointVelocityController',
                  'effort_controllers/JointVelocityController')
    default_gains = DEFAULT_VELOCITY_GAINS
    default_interface = 'velocity'

    def reset(self) -> None:
        """Target zero velocity; forget the integral."""
        self._command = 0.0
        self._pid.reset()

    def set_command(self, value: float) -> CommandResult:
        """Store a velocity command (clamped to the limit; NaN/Inf rejected)."""
        value, result = check_velocity(self._handle.spec, value)
        if result is not CommandResult.REJECTED:
            self._command = value
        return result

    def update(self, time: float, period: float) -> None:
        """Compute and clamp the effort for the present velocity error."""
        # clamp_effort written out: this runs every physics step.
        handle = self._handle
        effort = self._pid.compute(self._command, handle.velocity, period)
        limit = self._effort_limit
        handle.effort = limit if effort > limit else -limit if effort < -limit else effort
