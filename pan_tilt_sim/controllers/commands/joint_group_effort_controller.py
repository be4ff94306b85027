"""``effort_controllers/JointGroupEffortController``: a forward command group on effort.

See :mod:`pan_tilt_sim.controllers.commands.forward_command_controller`.
"""

from __future__ import annotations

from pan_tilt_sim.controllers.commands.forward_command_controller import (
    INTERFACE_FIELD,
    ForwardCommandController,
)


class JointGroupEffortController(ForwardCommandController):
    """The forward command controller with ``interface_name`` fixed to effort."""

    type_names = ('effort_controllers/JointGroupEffortController',)
    parameters = ForwardCommandController.parameters.without(INTERFACE_FIELD)
    fixed_interface = 'effort'
