"""``position_controllers/JointGroupPositionController``: a forward command group on position.

See :mod:`pan_tilt_sim.controllers.commands.forward_command_controller`.
"""

from __future__ import annotations

from pan_tilt_sim.controllers.commands.forward_command_controller import (
    INTERFACE_FIELD,
    ForwardCommandController,
)


class JointGroupPositionController(ForwardCommandController):
    """The forward command controller with ``interface_name`` fixed to position."""

    type_names = ('position_controllers/JointGroupPositionController',)
    parameters = ForwardCommandController.parameters.without(INTERFACE_FIELD)
    fixed_interface = 'position'
