"""``velocity_controllers/JointGroupVelocityController``: a forward command group on velocity.

See :mod:`pan_tilt_sim.controllers.forward_command_controller`.
"""

from __future__ import annotations

from pan_tilt_sim.controllers.forward_command_controller import ForwardCommandController


class JointGroupVelocityController(ForwardCommandController):
    """Velocity commands for a group of joints, on ``<controller>/commands``."""

    type_names = ('velocity_controllers/JointGroupVelocityController',)
    fixed_interface = 'velocity'
