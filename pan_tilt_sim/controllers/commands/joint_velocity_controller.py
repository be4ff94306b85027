"""``velocity_controllers/`` and ``effort_controllers/JointVelocityController``.

The command (rad/s or m/s) is clamped to the joint's velocity limit.
Before the first command the target velocity is zero.  What follows it:

* with PID gains (``pid:``, or ``gazebo_ros_control/pid_gains/<joint>``; the
  ``effort_controllers/`` type always, with defaults): a PID on the velocity
  error gives the joint effort, clamped to the effort limit.  The derivative
  acts on the measured velocity (its finite difference), so a step in the
  command gives no kick;
* without: the ideal actuator (:mod:`pan_tilt_sim.controllers.toolbox.actuator`), a
  velocity motor at the command, capped at the effort limit.
"""

from __future__ import annotations

from collections.abc import Sequence

from pan_tilt_sim.controllers.framework.base import ActuatorKind, CommandResult, JointHandle
from pan_tilt_sim.controllers.framework.single_joint import PidJointController
from pan_tilt_sim.controllers.toolbox.limits import check_velocity
from pan_tilt_sim.controllers.toolbox.pid import PidGains
from pan_tilt_sim.controllers.toolbox.step_law import (
    INTEGRAL,
    LAST_MEASUREMENT,
    OUTPUT,
    VELOCITY_PID,
    pid_row,
)

# The effort_controllers type's defaults: effort = 10 N*m per rad/s of error,
# a first-order loop, stable while 10 * time_step < 2 * the joint's inertia.
DEFAULT_VELOCITY_GAINS = PidGains(p=10.0)


class JointVelocityController(PidJointController):
    """Velocity command within the limit: the ideal actuator turns the joint, or a PID."""

    type_names = ('velocity_controllers/JointVelocityController',
                  'effort_controllers/JointVelocityController')
    default_gains = DEFAULT_VELOCITY_GAINS
    pid_kind = ActuatorKind.VELOCITY_PID
    ideal_kind = ActuatorKind.IDEAL_VELOCITY
    default_interface = 'velocity'

    def reset(self) -> None:
        """Target zero velocity; forget the integral."""
        self._command = 0.0
        if self._pid is not None:
            self._pid.reset()

    def set_command(self, value: float) -> CommandResult:
        """Store a velocity command (clamped to the limit; NaN/Inf rejected)."""
        value, result = check_velocity(self._handle.spec, value)
        if result is not CommandResult.REJECTED:
            self._command = value
        return result

    def step_law(self) -> tuple[JointHandle, list[float]] | None:
        """With a PID: the velocity PID's row (:mod:`pan_tilt_sim.controllers.toolbox.step_law`)."""
        pid = self._pid
        if pid is None:
            return None
        return self._handle, pid_row(VELOCITY_PID, pid.law_values(), 0.0, self._effort_limit,
                                     0.0, self._command)

    def absorb_step_law(self, row: Sequence[float]) -> None:
        """Take the PID's state from a compiled loop's row."""
        self._pid.restore(row[INTEGRAL], row[OUTPUT], row[LAST_MEASUREMENT])

    def update(self, time: float, period: float) -> None:
        """Compute and clamp the effort for the velocity error, or set the velocity target."""
        handle = self._handle
        if self._pid is None:
            handle.velocity_target = self._command
            return
        # clamp_effort written out: this runs every physics step.
        effort = self._pid.compute(self._command, handle.velocity, period)
        limit = self._effort_limit
        handle.effort = limit if effort > limit else -limit if effort < -limit else effort
