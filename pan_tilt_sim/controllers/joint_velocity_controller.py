"""``velocity_controllers/`` and ``effort_controllers/JointVelocityController``.

The command (rad/s or m/s) is clamped to the joint's velocity limit; a PID
on the velocity error gives the joint effort, clamped to the effort limit.
The derivative acts on the measured velocity (its finite difference), so a
step in the command gives no kick.  Before the first command the target
velocity is zero.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from pan_tilt_sim.controllers.base import CommandController, CommandResult, JointHandle
from pan_tilt_sim.controllers.gains import gains_from_params
from pan_tilt_sim.controllers.limits import check_velocity
from pan_tilt_sim.controllers.pid import Pid, PidGains

# Proportional-only by default: effort = 10 N*m per rad/s of error, a
# first-order loop that is stable for any inertia and damping.
DEFAULT_VELOCITY_GAINS = PidGains(p=10.0)


class JointVelocityController(CommandController):
    """Velocity command -> effort, through a PID."""

    type_names = ('velocity_controllers/JointVelocityController',
                  'effort_controllers/JointVelocityController')

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        self._joint_name = self.required_joint()
        self._gains = gains_from_params(self, DEFAULT_VELOCITY_GAINS)
        self._handle: JointHandle | None = None

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The one joint this controller drives."""
        return (self._joint_name,)

    @property
    def pid(self) -> Pid:
        """The PID (its gains may be changed live)."""
        return self._pid

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Bind the joint and a PID whose integral is bounded by the effort limit."""
        handle = self.handle(joints, self._joint_name, 'joint')
        self._handle = handle
        self._effort_limit = handle.spec.effort_limit
        self._pid = Pid(self._gains.with_default_clamp(self._effort_limit))
        self.reset()

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
