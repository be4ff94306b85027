"""``effort_controllers/JointGroupEffortController``: a forward command group on effort.

See :mod:`pan_tilt_sim.controllers.forward_command_controller`.
"""

from __future__ import annotations

from pan_tilt_sim.controllers.forward_command_controller import ForwardCommandController


class JointGroupEffortController(ForwardCommandController):
    """Effort commands for a group of joints, on ``<controller>/commands``."""

    type_names = ('effort_controllers/JointGroupEffortController',)
    fixed_interface = 'effort'
