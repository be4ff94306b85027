"""One joint on an ``acceleration`` command interface: a ForwardCommandController's member.

ros2_controllers has no one-joint acceleration type; a
``forward_command_controller/ForwardCommandController`` with
``interface_name: acceleration`` (ros2_control_demos' example 3) drives each
of its joints with one of these.  The command (rad/s^2 or m/s^2) is
integrated as ros2_control's mock hardware (``mock_components/GenericSystem``
with ``calculate_dynamics``) integrates it: every step the velocity grows by
the acceleration times the step, and the joint moves at that velocity.
Here the integrated velocity is the target of the ideal velocity actuator
(:mod:`pan_tilt_sim.controllers.toolbox.actuator`): a velocity motor capped at the
URDF effort limit, so the physics moves the joint.  The target stays within
the joint's velocity limit, as a velocity command does, and does not wind
up beyond it.

The URDF gives no acceleration limit, so any finite command is taken (NaN,
infinite or absurdly large ones are rejected).  The integration starts from
the joint's velocity when the controller starts (at rest after a reset),
with a zero command.
"""

from __future__ import annotations

import math

from pan_tilt_sim.controllers.framework.base import (
    Actuator,
    ActuatorKind,
    CommandResult,
    JointHandle,
    bounded_command,
    clamp,
)
from pan_tilt_sim.controllers.framework.single_joint import SingleJointController

ACCELERATION_INTERFACE = 'acceleration'


class JointAccelerationController(SingleJointController):
    """Acceleration command -> integrated velocity target of the ideal velocity actuator."""

    default_interface = ACCELERATION_INTERFACE

    def actuators(self) -> dict[str, Actuator]:
        """Return what drives the joint while active: the ideal velocity actuator."""
        return {self._joint_name: Actuator(ActuatorKind.IDEAL_ACCELERATION, self.name)}

    def bind(self, handle: JointHandle) -> None:
        """Take the joint's velocity limit, which bounds the integrated velocity."""
        self._max_velocity = handle.spec.velocity_limit
        self._velocity = 0.0

    def reset(self) -> None:
        """Zero command; integrate from the joint's present velocity (within the limit)."""
        self._command = 0.0
        limit = self._max_velocity
        self._velocity = clamp(self._handle.velocity, -limit, limit)

    def set_command(self, value: float) -> CommandResult:
        """Store an acceleration command (NaN, Inf and huge values rejected)."""
        value, result = bounded_command(value, -math.inf, math.inf)
        if result is not CommandResult.REJECTED:
            self._command = value
        return result

    def update(self, time: float, period: float) -> None:
        """Integrate the command over ``period`` into the velocity target."""
        limit = self._max_velocity
        velocity = self._velocity + self._command * period
        velocity = limit if velocity > limit else -limit if velocity < -limit else velocity
        self._velocity = velocity
        self._handle.velocity_target = velocity
