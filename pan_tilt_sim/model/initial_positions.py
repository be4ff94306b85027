"""Where each joint starts: ros2_control's ``initial_value``, overridden by a parameter.

The first that applies, per movable joint:

1. the node parameter ``initial_positions`` (``['joint:=value', ...]``);
2. ``<state_interface name="position"><param name="initial_value">`` in the
   URDF's ``<ros2_control>`` block, as gz_ros2_control and mock_components read it;
3. zero.

The value is clamped into the joint's position limits (with a warning when
the user asked for it; a default of 0 outside the limits is only reported).
A ``<mimic>`` joint starts where its leader puts it.  Reset services return here.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model.robot import RobotModel
from pan_tilt_sim.model.xml_input import float_or_nan

PARAMETER = 'initial_positions'
SEPARATOR = ':='
FROM_PARAMETER = f"parameter '{PARAMETER}'"
FROM_URDF = '<ros2_control> initial_value'
FROM_DEFAULT = 'default'


@dataclasses.dataclass(frozen=True)
class StartPosition:
    """One joint's start: the position used, what was asked for, and who asked."""

    joint: str
    position: float
    requested: float
    source: str

    @property
    def clamped(self) -> bool:
        """Whether the request lay outside the joint's limits."""
        return self.position != self.requested

    def describe(self, lower: float, upper: float) -> str:
        """One log line about this start, if it is worth one ('' otherwise)."""
        if self.clamped and self.source == FROM_DEFAULT:
            return (f"joint '{self.joint}' starts at {self.position:g}: 0 is outside its "
                    f'limits [{lower:g}, {upper:g}]')
        if self.clamped:
            return (f"joint '{self.joint}': initial position {self.requested:g} ({self.source}) "
                    f'is outside its limits [{lower:g}, {upper:g}]; starts at {self.position:g}')
        if self.source != FROM_DEFAULT:
            return f"joint '{self.joint}' starts at {self.position:g} ({self.source})"
        return ''


def parse_initial_positions(entries: Sequence[str]) -> dict[str, float]:
    """Read ``['joint:=value', ...]``; ParameterError naming the parameter and the entry."""
    positions: dict[str, float] = {}
    for entry in entries:
        joint, separator, text = entry.partition(SEPARATOR)
        joint = joint.strip()
        if not separator or not joint:
            raise ParameterError(
                f"{FROM_PARAMETER}: '{entry}' is not of the form joint:=value")
        value = float_or_nan(text)
        if not math.isfinite(value):
            raise ParameterError(
                f"{FROM_PARAMETER}: '{entry}': '{text.strip()}' is not a finite number")
        if joint in positions:
            raise ParameterError(f"{FROM_PARAMETER}: joint '{joint}' is given more than once")
        positions[joint] = value
    return positions


def start_positions(model: RobotModel,
                    overrides: Mapping[str, float] | None = None) -> dict[str, StartPosition]:
    """Return every movable joint's start, by name, in the model's joint order.

    ``overrides`` (from :func:`parse_initial_positions`) must name movable,
    non-mimic joints of ``model``; otherwise ParameterError.
    """
    overrides = dict(overrides or {})
    movable = [joint.name for joint in model.actuated_joints]
    for joint in overrides:
        if joint not in movable:
            raise ParameterError(
                f"{FROM_PARAMETER}: '{joint}' is not a movable joint of the robot "
                f"(movable joints: {', '.join(movable) or 'none'})")
        mimic = model.joint(joint).mimic
        if mimic is not None:
            raise ParameterError(
                f"{FROM_PARAMETER}: joint '{joint}' mimics '{mimic.joint}' and starts where "
                f"it puts it; give '{mimic.joint}' instead")
    starts: dict[str, StartPosition] = {}
    for joint in model.actuated_joints:
        control = model.control_joint(joint.name)
        if joint.name in overrides:
            requested, source = overrides[joint.name], FROM_PARAMETER
        elif control is not None and control.initial_position is not None:
            requested, source = control.initial_position, FROM_URDF
        else:
            requested, source = 0.0, FROM_DEFAULT
        starts[joint.name] = StartPosition(
            joint.name, joint.clamp_position(requested), requested, source)
    return starts
