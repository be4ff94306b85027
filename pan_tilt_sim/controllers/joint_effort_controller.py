"""``effort_controllers/JointEffortController``: the command is the joint effort.

The effort (N*m or N) is clamped to the URDF effort limit.  Before the
first command the effort is zero.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from pan_tilt_sim.controllers.base import CommandController, CommandResult, JointHandle
from pan_tilt_sim.controllers.limits import check_effort


class JointEffortController(CommandController):
    """Effort command -> effort."""

    type_names = ('effort_controllers/JointEffortController',)

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        self._joint_name = self.required_joint()
        self._handle: JointHandle | None = None

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The one joint this controller drives."""
        return (self._joint_name,)

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Bind the joint."""
        self._handle = self.handle(joints, self._joint_name, 'joint')
        self.reset()

    def reset(self) -> None:
        """Apply no effort until commanded."""
        self._command = 0.0

    def set_command(self, value: float) -> CommandResult:
        """Store an effort command (clamped to the limit; NaN/Inf rejected)."""
        value, result = check_effort(self._handle.spec, value)
        if result is not CommandResult.REJECTED:
            self._command = value
        return result

    def update(self, time: float, period: float) -> None:
        """Apply the commanded effort."""
        self._handle.effort = self._command
