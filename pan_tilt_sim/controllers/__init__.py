"""Pure-Python controllers, one type per module, built from controller YAML."""

from pan_tilt_sim.controllers.framework.base import (
    CommandController,
    CommandKind,
    CommandResult,
    Controller,
    JointHandle,
)
from pan_tilt_sim.controllers.framework.registry import create_controller, supported_types

__all__ = [
    'CommandController',
    'CommandKind',
    'CommandResult',
    'Controller',
    'JointHandle',
    'create_controller',
    'supported_types',
]
