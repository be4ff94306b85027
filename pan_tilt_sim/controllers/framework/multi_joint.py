"""The shared part of the controllers that command several joints at once.

:class:`MultiJointController` names its joints with the ``joints`` list (the
order of every command's elements) and remembers why it last refused or
clamped a command, so the node's throttled warning can say exactly what was
wrong with an array or a trajectory.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from pan_tilt_sim.controllers.framework.base import CommandController, CommandResult
from pan_tilt_sim.controllers.framework.parameter_spec import ParameterSpec
from pan_tilt_sim.controllers.framework.shared_parameters import JOINTS

JOINTS_FIELD = 'joints'


class MultiJointController(CommandController):
    """A command controller over the joints its ``joints`` parameter lists."""

    parameters = ParameterSpec([JOINTS])

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        self._joint_names: tuple[str, ...] = tuple(self.params[JOINTS_FIELD])
        self._problem = ''

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The joints, in the order of every command's elements."""
        return self._joint_names

    def command_problem(self, value: Any, result: CommandResult) -> str:
        """Describe the last rejected or clamped command."""
        return self._problem
