"""Driving a holonomic drive controller (mecanum, omni wheel) in a unit test, on ideal wheels.

The mecanum and omni wheel controllers' tests build their controller on free
continuous joints, command it with :func:`twist` and :func:`run` it at 100 Hz;
each wheel turns exactly as commanded (velocity and position).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

from pan_tilt_sim.controllers import JointHandle
from pan_tilt_sim.controllers.framework.base import CommandResult
from pan_tilt_sim.controllers.framework.surface import StampedTwist
from pan_tilt_sim.model.robot import JointKind, JointSpec

DT = 0.01  # the controller's update period at 100 Hz
NAME = 'base_controller'


def twist(vx: float, vy: float, wz: float, stamp: float = 0.0) -> StampedTwist:
    """Return a TwistStamped value: linear.x, linear.y and angular.z."""
    return StampedTwist(stamp, (vx, vy, 0.0), (0.0, 0.0, wz))


def configured(kind: Callable[..., Any], parameters: Mapping[str, Any], joints: Sequence[str],
               source: str) -> tuple[Any, dict[str, JointHandle]]:
    """Return a ``kind`` controller configured on ``joints``, and the joints' handles."""
    handles = {name: JointHandle(JointSpec(name, JointKind.CONTINUOUS)) for name in joints}
    drive = kind(NAME, parameters, source)
    drive.configure(handles)
    return drive, handles


def run(drive: Any, handles: dict[str, JointHandle], seconds: float, start: float = 0.0,
        command: StampedTwist | None = None) -> float:
    """Update ``drive`` for ``seconds``; ideal wheels turn as commanded; return the end time.

    ``command``, if given, is sent (stamped now) before every update and must be taken.
    """
    steps = round(seconds / DT)
    for step in range(steps):
        time = start + step * DT
        if command is not None:
            assert drive.set_command(command._replace(stamp=time)) is CommandResult.ACCEPTED
        drive.update(time, DT)
        for handle in handles.values():
            handle.velocity = handle.velocity_target
            handle.position += handle.velocity_target * DT
    return start + steps * DT
