"""``effort_controllers/JointEffortController``: the command is the joint effort.

The effort (N*m or N) is clamped to the URDF effort limit.  Before the
first command the effort is zero.
"""

from __future__ import annotations

from collections.abc import Sequence

from pan_tilt_sim.controllers.framework.base import (
    Actuator,
    ActuatorKind,
    CommandResult,
    JointHandle,
)
from pan_tilt_sim.controllers.framework.single_joint import SingleJointController
from pan_tilt_sim.controllers.toolbox.limits import check_effort
from pan_tilt_sim.controllers.toolbox.step_law import effort_row


class JointEffortController(SingleJointController):
    """Effort command, applied to the joint within its effort limit."""

    type_names = ('effort_controllers/JointEffortController',)
    default_interface = 'effort'

    def actuators(self) -> dict[str, Actuator]:
        """Return what drives the joint while active: the physics applies the effort."""
        return {self._joint_name: Actuator(ActuatorKind.EFFORT, self.name)}

    def reset(self) -> None:
        """Apply no effort until commanded."""
        self._command = 0.0

    def set_command(self, value: float) -> CommandResult:
        """Store an effort command (clamped to the limit; NaN/Inf rejected)."""
        value, result = check_effort(self._handle.spec, value)
        if result is not CommandResult.REJECTED:
            self._command = value
        return result

    def step_law(self) -> tuple[JointHandle, list[float]]:
        """Return the effort law's row (:mod:`pan_tilt_sim.controllers.toolbox.step_law`)."""
        return self._handle, effort_row(self._command)

    def absorb_step_law(self, row: Sequence[float]) -> None:
        """Nothing to take back: the effort law has no state."""

    def update(self, time: float, period: float) -> None:
        """Apply the commanded effort."""
        self._handle.effort = self._command
