"""Ideal joints for the steering controller tests: every joint does exactly what it is told.

The steering joints jump to their commanded angle and the traction wheels
turn at their commanded velocity, so every figure follows from the
kinematics alone.
"""

from __future__ import annotations

import math
from typing import Any

from pan_tilt_sim.controllers import JointHandle
from pan_tilt_sim.controllers.drives.steering.steering_controllers import SteeringController
from pan_tilt_sim.controllers.framework.base import CommandResult
from pan_tilt_sim.controllers.framework.registry import create_controller
from pan_tilt_sim.controllers.framework.surface import StampedTwist
from pan_tilt_sim.model.robot import JointKind, JointSpec

DT = 0.001
NAME = 'steering_controller'
STEER_LIMIT = 0.6


def twist(linear: float, angular: float, stamp: float = 0.0) -> StampedTwist:
    """Return a TwistStamped value: linear.x and angular.z."""
    return StampedTwist(stamp, (linear, 0.0, 0.0), (0.0, 0.0, angular))


def handles(params: dict[str, Any]) -> dict[str, JointHandle]:
    """Return handles for the joints ``params`` names: wheels continuous, steering limited."""
    made = {name: JointHandle(JointSpec(name, JointKind.CONTINUOUS, velocity_limit=40.0))
            for name in params.get('traction_joints_names', ())}
    made.update({name: JointHandle(JointSpec(name, JointKind.REVOLUTE, -STEER_LIMIT, STEER_LIMIT,
                                             velocity_limit=3.0))
                 for name in params.get('steering_joints_names', ())})
    return made


def configured(type_name: str, params: dict[str, Any]) -> tuple[SteeringController,
                                                                  dict[str, JointHandle]]:
    """Return a configured ``type_name`` controller and its joints' handles."""
    joints = handles(params)
    controller = create_controller(NAME, type_name, params, 'car.yaml')
    assert isinstance(controller, SteeringController)
    controller.configure(joints)
    return controller, joints


def steering_joints(controller: SteeringController) -> list[str]:
    """Return the controller's steering joints, in its order (right, then left)."""
    return [joint for joint, interfaces in controller.command_interfaces().items()
            if interfaces == ('position',)]


def run(controller: SteeringController, joints: dict[str, JointHandle], seconds: float,
        start: float = 0.0, command: StampedTwist | None = None) -> float:
    """Step for ``seconds`` with ideal joints; resend ``command`` each step; return the end time.

    The steering joints stand at their last commanded angle; the wheels turn as commanded.
    """
    steps = round(seconds / DT)
    steering = steering_joints(controller)
    for step in range(steps):
        time = start + step * DT
        if command is not None:
            assert controller.set_command(command) is CommandResult.ACCEPTED
        controller.update(time, DT)
        for name, angle in zip(steering, controller.steering_commands, strict=True):
            if not math.isnan(angle):  # commanded
                joints[name].position = angle
        for handle in joints.values():
            if handle.spec.kind is JointKind.CONTINUOUS:
                handle.velocity = handle.velocity_target
                handle.position += handle.velocity_target * DT
    return start + steps * DT
