"""``position_controllers/JointGroupPositionController``: a forward command group on position.

See :mod:`pan_tilt_sim.controllers.forward_command_controller`.
"""

from __future__ import annotations

from pan_tilt_sim.controllers.forward_command_controller import ForwardCommandController


class JointGroupPositionController(ForwardCommandController):
    """Position commands for a group of joints, on ``<controller>/commands``."""

    type_names = ('position_controllers/JointGroupPositionController',)
    fixed_interface = 'position'
