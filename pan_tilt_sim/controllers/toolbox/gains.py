"""Reading a controller's PID gains from its YAML parameters.

Three places, the first that gives gains for a joint wins:

* ROS 1 (gazebo_ros_control), one joint per controller:
  ``pid: {p, i, d, i_clamp...}``;
* ROS 2 (gazebo_ros2_control, ros2_controllers), per joint:
  ``gains: {<joint>: {p, i, d, i_clamp...}}``.  ros2_controllers' entries
  may also hold ``ff_velocity_scale`` (a velocity feed-forward, see
  :func:`feedforward_scales`) and the angle-wrapping flags
  ``angle_wraparound`` / ``normalize_error``, which are accepted and not
  used: this simulator never wraps angles (continuous joints' commands are
  taken as they are);
* gazebo_ros_control's own ``gazebo_ros_control/pid_gains/<joint>`` (read
  into each joint's handle, see :func:`plugin_gains`).

Design notes: docs/design/controllers.md#gainspy.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from pan_tilt_sim.controllers.framework.base import Controller, JointHandle
from pan_tilt_sim.controllers.toolbox.pid import GainsError, PidGains
from pan_tilt_sim.errors import ControllerConfigError

PID_FIELD = 'pid'
GAINS_FIELD = 'gains'
PLUGIN_GAINS_FIELD = 'gazebo_ros_control.pid_gains'
FEEDFORWARD_FIELD = 'ff_velocity_scale'
# Per-joint entries of ros2_controllers' gains that are not PID gains.
NON_PID_FIELDS = (FEEDFORWARD_FIELD, 'angle_wraparound', 'normalize_error')
# The pan/tilt example's gains, the default of a position loop on an effort interface
# (effort_controllers/JointPositionController, the trajectory and effort gripper
# controllers) when the YAML gives none: with the pan/tilt example's damping they track
# critically damped or slower for link inertias up to ~10 kg m^2.
DEFAULT_POSITION_GAINS = PidGains(p=100.0, i=0.01, d=10.0)


def gains_from_params(controller: Controller, default: PidGains | None) -> PidGains | None:
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


def plugin_gains(entries: Mapping[str, Any], joints: Sequence[str],
                 source: str = '') -> dict[str, PidGains]:
    """Return ``gazebo_ros_control/pid_gains`` as gains by joint; errors name the entry."""
    where = f'{source}: ' if source else ''
    gains = {}
    for joint, entry in entries.items():
        field = f'{PLUGIN_GAINS_FIELD}.{joint}'
        if joint not in joints:
            raise ControllerConfigError(
                f"{where}{field}: '{joint}' is not a movable joint of the robot "
                f"(movable joints: {', '.join(joints) or 'none'})")
        try:
            gains[joint] = PidGains.from_mapping(entry)
        except GainsError as err:
            raise ControllerConfigError(f'{where}{field}: {err}') from None
    return gains


def choose_gains(own: PidGains | None, own_field: str, handle: JointHandle,
                 default: PidGains | None = None) -> tuple[PidGains | None, str]:
    """Return the gains that drive ``handle``'s joint and where they come from.

    ``own`` (the controller's, from ``own_field``) first, then the joint's
    ``gazebo_ros_control/pid_gains``, then ``default`` (from '').  None: no
    gains anywhere -- the joint gets the ideal actuator.
    """
    if own is not None:
        return own, own_field
    if handle.plugin_gains is not None:
        return handle.plugin_gains, f'{PLUGIN_GAINS_FIELD}.{handle.name}'
    return default, ''
