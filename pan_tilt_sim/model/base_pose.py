"""Where the robot's base starts, and whether it is welded to the world. No ROS, no PyBullet.

sim_node's ``fixed_base`` parameter says whether the robot's root link is
welded to the world (``true``), free (``false``), or -- ``auto``, the
default -- free exactly when the robot is mobile: when a controller that
drives the base (a ``diff_drive_controller/DiffDriveController``, say)
will be active.  A robot whose root link is ``world``, hung on it by a
fixed joint, is welded whatever the parameter says, as in Gazebo.

``initial_pose`` (x, y, z, yaw: m and rad) places the base: a free base
rests on the ground, its lowest collision point ``z`` above z = 0 (0:
standing on it), turned by ``yaw`` about the vertical; a welded base has
its root link frame at (x, y, z), turned by ``yaw``.  A spawn request's
pose (``create -R -P -Y``) also tilts it: ``roll`` and ``pitch``, fixed
axes, as gz's pose (yaw last).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

from pan_tilt_sim.errors import ParameterError

AUTO, TRUE, FALSE = 'auto', 'true', 'false'
FIXED_BASE_CHOICES = (AUTO, TRUE, FALSE)
FIXED_BASE = 'fixed_base'
INITIAL_POSE = 'initial_pose'
POSE_FIELDS = ('x', 'y', 'z', 'yaw')


@dataclasses.dataclass(frozen=True)
class BasePose:
    """The base's start: position (m), height of its lowest point or frame (m), angles (rad).

    The angles are fixed-axis: roll about x, then pitch about y, then yaw about z.
    """

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    yaw: float = 0.0
    roll: float = 0.0
    pitch: float = 0.0

    @property
    def is_origin(self) -> bool:
        """Whether this is the default pose (nothing to move)."""
        return self == ORIGIN


ORIGIN = BasePose()  # the default: at the origin, heading along x


def parse_fixed_base(value: object) -> bool | None:
    """Return ``fixed_base`` as True, False or None (auto); ParameterError otherwise.

    Takes a bool (``-p fixed_base:=true`` arrives as one) or one of
    ``auto``, ``true``, ``false``.
    """
    if isinstance(value, bool):
        return value
    if isinstance(value, str) and value.strip().lower() in FIXED_BASE_CHOICES:
        return {AUTO: None, TRUE: True, FALSE: False}[value.strip().lower()]
    raise ParameterError(
        f"parameter '{FIXED_BASE}' must be one of {', '.join(FIXED_BASE_CHOICES)}, "
        f'got {value!r}')


def parse_initial_pose(values: Sequence[float] | None) -> BasePose:
    """Return ``initial_pose`` ([x, y, z, yaw], or unset) as a :class:`BasePose`.

    Unset or empty: the origin.  Anything but four finite numbers is a
    ParameterError naming the parameter.
    """
    if not values:
        return ORIGIN
    numbers = [float(value) for value in values if isinstance(value, int | float)
               and not isinstance(value, bool)]
    if len(values) != len(POSE_FIELDS) or len(numbers) != len(values) or not all(
            math.isfinite(value) for value in numbers):
        raise ParameterError(
            f"parameter '{INITIAL_POSE}' must be four finite numbers "
            f"[{', '.join(POSE_FIELDS)}] (m, m, m, rad), got {list(values)!r}")
    return BasePose(*numbers)
