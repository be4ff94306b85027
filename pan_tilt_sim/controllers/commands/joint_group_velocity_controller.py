"""``velocity_controllers/JointGroupVelocityController``: a forward command group on velocity.

See :mod:`pan_tilt_sim.controllers.commands.forward_command_controller`.
"""

from __future__ import annotations

from pan_tilt_sim.controllers.commands.forward_command_controller import (
    INTERFACE_FIELD,
    ForwardCommandController,
)


class JointGroupVelocityController(ForwardCommandController):
    """The forward command controller with ``interface_name`` fixed to velocity."""

    type_names = ('velocity_controllers/JointGroupVelocityController',)
    parameters = ForwardCommandController.parameters.without(INTERFACE_FIELD)
    fixed_interface = 'velocity'
