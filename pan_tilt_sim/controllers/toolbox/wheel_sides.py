"""The left and right wheels of a differential drive, bound to their joint handles.

The Gazebo diff-drive plugins (classic's and gz-sim's) drive their wheels
by side: :class:`WheelSides` binds the named joints' handles and reports
their velocity targets (the plugins' setpoints).  :func:`feedback_interfaces`
says what the drive controllers' wheel odometry reads.  Pure Python.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

from pan_tilt_sim.controllers.framework.base import JointHandle

# handle(joints, joint, field): the controller's checked handle of ``joint``,
# ``field`` naming the setting that lists it (Controller.handle).
HandleLookup = Callable[[Mapping[str, JointHandle], str, str], JointHandle]


def feedback_interfaces(wheels: Sequence[str],
                        params: Mapping[str, Any]) -> dict[str, tuple[str, ...]]:
    """Return the state interface each wheel is read by: none with ``open_loop``.

    Else ``position`` with ``position_feedback``, ``velocity`` without.
    """
    if params['open_loop']:
        return {}
    feedback = 'position' if params['position_feedback'] else 'velocity'
    return {wheel: (feedback,) for wheel in wheels}


def velocity_targets(handles: Sequence[JointHandle]) -> dict[str, float]:
    """Return each handle's velocity target (rad/s), by joint."""
    return {handle.name: handle.velocity_target for handle in handles}


class WheelSides:
    """The wheels on each side, left ones first; no handles until :meth:`bind`.

    ``left_field``/``right_field``: the settings that name them (for errors).
    """

    def __init__(self, left: Sequence[str], right: Sequence[str], *,
                 left_field: str = 'left_joint', right_field: str = 'right_joint') -> None:
        self._names = (tuple(left), tuple(right))
        self._fields = (left_field, right_field)
        self.left: list[JointHandle] = []
        self.right: list[JointHandle] = []

    def bind(self, joints: Mapping[str, JointHandle], handle: HandleLookup) -> None:
        """Take each wheel's handle from ``joints`` through ``handle``."""
        (left, right), (left_field, right_field) = self._names, self._fields
        self.left = [handle(joints, wheel, left_field) for wheel in left]
        self.right = [handle(joints, wheel, right_field) for wheel in right]

    @property
    def all(self) -> list[JointHandle]:
        """Every bound wheel, left ones first."""
        return self.left + self.right

    def setpoints(self) -> dict[str, float]:
        """Return each bound wheel's velocity target (rad/s)."""
        return velocity_targets(self.left + self.right)
