"""Reading a controller's PID gains from its YAML parameters.

Two layouts:

* ROS 1 (gazebo_ros_control), one joint per controller:
  ``pid: {p, i, d, i_clamp...}``;
* ROS 2 (gazebo_ros2_control, ros2_controllers), per joint:
  ``gains: {<joint>: {p, i, d, i_clamp...}}``.  ros2_controllers' entries
  may also hold ``ff_velocity_scale`` (a velocity feed-forward, see
  :func:`feedforward_scales`) and the angle-wrapping flags
  ``angle_wraparound`` / ``normalize_error``, which are accepted and not
  used: this simulator never wraps angles (continuous joints' commands are
  taken as they are).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from pan_tilt_sim.controllers.base import Controller
from pan_tilt_sim.controllers.pid import GainsError, PidGains

PID_FIELD = 'pid'
GAINS_FIELD = 'gains'
FEEDFORWARD_FIELD = 'ff_velocity_scale'
# Per-joint entries of ros2_controllers' gains that are not PID gains.
NON_PID_FIELDS = (FEEDFORWARD_FIELD, 'angle_wraparound', 'normalize_error')


def gains_from_params(controller: Controller, default: PidGains) -> PidGains:
    """Return the ``pid: {p, i, d, i_clamp...}`` section of ``controller``, or ``default``.

    The section may already be a :class:`PidGains` (group controllers build
    their one-joint members that way).
    """
    values = controller.params.get(PID_FIELD)
    if values is None:
        return default
    if isinstance(values, PidGains):
        return values
    try:
        return PidGains.from_mapping(values)
    except GainsError as err:
        raise controller.error(PID_FIELD, str(err)) from None


def joint_gains_from_params(controller: Controller,
                            joints: Sequence[str]) -> dict[str, PidGains]:
    """Return the ``gains: {<joint>: {...}}`` section's PID gains, for the joints it names."""
    return {joint: _pid_gains(controller, joint, entry)
            for joint, entry in _gains_entries(controller, joints).items()}


def feedforward_scales(controller: Controller, joints: Sequence[str]) -> dict[str, float]:
    """Return each joint's ``gains.<joint>.ff_velocity_scale`` (0 when not given)."""
    scales = dict.fromkeys(joints, 0.0)
    for joint, entry in _gains_entries(controller, joints).items():
        scale = entry.get(FEEDFORWARD_FIELD, 0.0)
        if isinstance(scale, bool) or not isinstance(scale, int | float) or not math.isfinite(
                scale):
            raise controller.error(f'{GAINS_FIELD}.{joint}.{FEEDFORWARD_FIELD}',
                                   f'{scale!r} is not a number')
        scales[joint] = float(scale)
    return scales


def _gains_entries(controller: Controller,
                   joints: Sequence[str]) -> dict[str, Mapping[str, Any]]:
    section = controller.params.get(GAINS_FIELD)
    if section is None:
        return {}
    if not isinstance(section, Mapping):
        raise controller.error(
            GAINS_FIELD, 'expected a mapping of joint names to {p, i, d, i_clamp}')
    entries = {}
    for joint, entry in section.items():
        field = f'{GAINS_FIELD}.{joint}'
        if joint not in joints:
            raise controller.error(
                field, f"'{joint}' is not one of this controller's joints ({', '.join(joints)})")
        if not isinstance(entry, Mapping):
            raise controller.error(field, f'expected a mapping of gains, got {entry!r}')
        entries[str(joint)] = entry
    return entries


def _pid_gains(controller: Controller, joint: str, entry: Mapping[str, Any]) -> PidGains:
    values = {name: value for name, value in entry.items() if name not in NON_PID_FIELDS}
    try:
        return PidGains.from_mapping(values)
    except GainsError as err:
        raise controller.error(f'{GAINS_FIELD}.{joint}', str(err)) from None
