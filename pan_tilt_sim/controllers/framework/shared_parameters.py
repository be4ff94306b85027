"""Parameter entries several controller types share (see :mod:`.parameter_spec`).

Names, types and defaults are ros2_controllers' (jazzy) where the parameter
exists upstream; ``joint`` and ``pid`` are ROS 1's (gazebo_ros_control), as
the pan/tilt example's controllers file writes them.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any, NamedTuple

from pan_tilt_sim.controllers.framework.base import Controller
from pan_tilt_sim.controllers.framework.parameter_spec import (
    BOOL,
    DOUBLE,
    DOUBLE_ARRAY,
    REQUIRED,
    STRING,
    STRING_ARRAY,
    Param,
    Validator,
    fixed_size,
    frame_id,
    frame_id_prefix,
    gt_eq,
    names,
    not_empty,
    rate,
    unique,
)
from pan_tilt_sim.controllers.toolbox.rate_limiter import RateLimiter, RateLimits
from pan_tilt_sim.model.controller_config import DEFAULT_UPDATE_RATE

UPDATE_RATE = Param('update_rate', DOUBLE, None, "Updates per second of sim time; the "
                    "controller_manager's rate (100 Hz unless the file says otherwise) by "
                    'default.', (rate(),))
JOINT = Param('joint', STRING, REQUIRED, 'The joint this controller drives.',
              (not_empty(),), read_only=True, example='joint1')
JOINTS = Param('joints', STRING_ARRAY, REQUIRED, 'The joints this controller drives, in '
               'the order of every command.', (not_empty(), names(), unique()), read_only=True,
               example=['joint1'])

# A length or radius whose default 0 means 'not set' (upstream's convention); a negative
# one has no meaning.
UNSET_OR_LENGTH = (gt_eq(0.0),)


# An odometry covariance diagonal: x, y, z, roll, pitch, yaw.
COVARIANCE_SIZE = 6


class OdometryFrames(NamedTuple):
    """A drive's odometry frame and covariance entries; a spec lists them in its own order."""

    odom: Param
    base: Param
    pose_covariance: Param
    twist_covariance: Param


def odometry_frames(*, covariance: Sequence[float] = (0.0,) * COVARIANCE_SIZE,
                    pose_name: str = 'pose_covariance_diagonal',
                    twist_name: str = 'twist_covariance_diagonal',
                    read_only: bool = False) -> OdometryFrames:
    """Return ``odom_frame_id``, ``base_frame_id`` and the two covariance diagonals.

    ``covariance``: both diagonals' default; ``pose_name``/``twist_name``:
    the diagonals' names (omni_wheel_drive_controller's are
    ``diagonal_covariance.pose``/``.twist``); ``read_only``: all four fixed
    once configured.
    """
    size = (fixed_size(COVARIANCE_SIZE),)
    return OdometryFrames(
        Param('odom_frame_id', STRING, 'odom', 'The odometry frame.', (frame_id(),),
              read_only=read_only),
        Param('base_frame_id', STRING, 'base_link', "The robot's base frame, child of "
              'odom_frame_id.', (frame_id(),), read_only=read_only),
        Param(pose_name, DOUBLE_ARRAY, list(covariance), "Diagonal of the odometry pose's "
              'covariance (x, y, z, roll, pitch, yaw).', size, read_only=read_only),
        Param(twist_name, DOUBLE_ARRAY, list(covariance), "Diagonal of the odometry twist's "
              'covariance.', size, read_only=read_only))


def tf_frame_prefix(*, enable_read_only: bool = False,
                    prefix_read_only: bool = False) -> tuple[Param, Param]:
    """Return ``tf_frame_prefix_enable`` and ``tf_frame_prefix`` (empty: the namespace).

    ``enable_read_only``/``prefix_read_only``: each fixed once configured, as
    the controller's upstream declares it.
    """
    return (Param('tf_frame_prefix_enable', BOOL, True, 'Prefix the frame ids with '
                  'tf_frame_prefix.', read_only=enable_read_only),
            Param('tf_frame_prefix', STRING, '', "The frame ids' prefix; empty: the "
                  "controller's namespace.", (frame_id_prefix(),), read_only=prefix_read_only))


def same_frames_problem(params: Mapping[str, Any]) -> str | None:
    """Say why ``odom_frame_id`` and ``base_frame_id`` cannot make a transform, or None.

    The odom -> base transform needs two frames; tf2 strips one leading '/'
    of each, so ``/odom`` and ``odom`` are one frame.  Any prefix is shared.
    """
    odom, base = params['odom_frame_id'], params['base_frame_id']
    if odom.removeprefix('/') == base.removeprefix('/'):
        return (f"'{base}' is odom_frame_id too: the odom -> base transform needs two "
                'different frames')
    return None


def check_odometry_frames(controller: Controller) -> None:
    """Raise the controller's error on ``base_frame_id`` if it is ``odom_frame_id`` too."""
    problem = same_frames_problem(controller.params)
    if problem:
        raise controller.error('base_frame_id', problem)


def prefixed_frames(params: Mapping[str, Any], namespace: str) -> tuple[str, str]:
    """Return ``odom_frame_id`` and ``base_frame_id`` with the prefix upstream gives them.

    With ``tf_frame_prefix_enable``: ``tf_frame_prefix``, or the controller's
    node ``namespace`` if that is empty, ending in one '/' and without a
    leading one.
    """
    prefix = ''
    if params['tf_frame_prefix_enable']:
        prefix = params['tf_frame_prefix'] or namespace
        if not prefix.endswith('/'):
            prefix += '/'
        prefix = prefix.removeprefix('/')
    return prefix + params['odom_frame_id'], prefix + params['base_frame_id']


def pid_gains(prefix: str) -> tuple[Param, ...]:
    """Return the PID gain entries under ``prefix`` (``pid`` or ``gains.__map_joints``).

    Absent gains leave the joint to the ideal actuator (or an effort type's
    defaults); the live-tunable ones become node parameters while the
    controller is configured.
    """
    return (
        Param(f'{prefix}.p', DOUBLE, None, 'Proportional gain.', (gt_eq(0.0),), tunable=True),
        Param(f'{prefix}.i', DOUBLE, None, 'Integral gain.', (gt_eq(0.0),), tunable=True),
        Param(f'{prefix}.d', DOUBLE, None, 'Derivative gain (on the measured rate).',
              (gt_eq(0.0),), tunable=True),
        Param(f'{prefix}.i_clamp', DOUBLE, None,
              'Symmetric bound of the integral term (ROS 1 and ros2_controllers).',
              (gt_eq(0.0),)),
        Param(f'{prefix}.i_clamp_max', DOUBLE, None,
              'Upper bound of the integral term (same unit as the effort).',
              tunable=True, finite=False),
        Param(f'{prefix}.i_clamp_min', DOUBLE, None, 'Lower bound of the integral term.',
              tunable=True, finite=False),
        Param(f'{prefix}.antiwindup', BOOL, None,
              'Hold the integrator itself within the clamp (else only its contribution).',
              tunable=True),
    )


def joint_gains() -> tuple[Param, ...]:
    """Return ros2_controllers' per-joint ``gains.<joint>`` entries (PID plus extras)."""
    prefix = 'gains.__map_joints'
    return (*pid_gains(prefix),
            Param(f'{prefix}.ff_velocity_scale', DOUBLE, None,
                  'Feed-forward gain on the desired velocity.'),
            Param(f'{prefix}.normalize_error', BOOL, None,
                  'Wrap the position error of continuous joints.', simulated=False),
            Param(f'{prefix}.angle_wraparound', BOOL, None,
                  'Deprecated name of normalize_error.', simulated=False))


def update_period(params: Mapping[str, Any]) -> float:
    """Return the seconds of sim time between updates: 1 / ``update_rate``, else 1 / 100 Hz.

    A ros2_control style file gives every controller its controller_manager's
    rate; a ROS 1 file gives none, and 100 Hz is the controller_manager's default.
    """
    rate = params.get(UPDATE_RATE.name)
    return 1.0 / float(rate if rate is not None else DEFAULT_UPDATE_RATE)


def _or_nan(text: str, accept: Callable[[float], bool]) -> Validator:
    return Validator(f'{text} or NaN (off)', lambda value: None if math.isnan(value) or accept(
        value) else f'{value!r} must be {text} or NaN (off)')


def velocity_limit_params(group: str, *, deprecated_switches: bool = False) -> tuple[Param, ...]:
    """Return one group of velocity limits (``linear.x`` ...), as jazzy's drive controllers.

    Every limit is NaN (off) by default; :func:`velocity_limiter` builds the
    group's limiter.  ``deprecated_switches`` adds diff_drive_controller's
    ``has_*_limits`` switches and its ignored ``min_acceleration``.
    """
    unit = 'm' if group.startswith('linear') else 'rad'
    positive = _or_nan('>= 0', lambda value: value >= 0.0)
    negative = _or_nan('<= 0', lambda value: value <= 0.0)

    def limit(name: str, text: str, rule: Validator) -> Param:
        return Param(f'{group}.{name}', DOUBLE, math.nan, text, (rule,), finite=False)

    switches = tuple(
        Param(f'{group}.has_{kind}_limits', BOOL, True,
              f'Deprecated: false turns the {kind} limits off (set them to NaN instead).')
        for kind in ('velocity', 'acceleration', 'jerk')) if deprecated_switches else ()
    ignored = (Param(f'{group}.min_acceleration', DOUBLE, None,
                     'Deprecated upstream, which ignores it: use max_deceleration.',
                     finite=False, simulated=False),) if deprecated_switches else ()
    return (
        *switches,
        limit('max_velocity', f'Largest velocity ({unit}/s).', positive),
        limit('min_velocity', f'Smallest velocity ({unit}/s); NaN: -max_velocity.', negative),
        limit('max_acceleration', f'Largest acceleration in the positive direction '
              f'({unit}/s^2).', positive),
        limit('max_deceleration', f'Largest deceleration while moving in the positive direction '
              f'({unit}/s^2, <= 0); NaN: max_acceleration_reverse.', negative),
        *ignored,
        limit('max_acceleration_reverse', f'Largest acceleration in the negative direction '
              f'({unit}/s^2, <= 0); NaN: -max_acceleration.', negative),
        limit('max_deceleration_reverse', f'Largest deceleration while moving in the negative '
              f'direction ({unit}/s^2); NaN: max_acceleration.', positive),
        limit('max_jerk', f'Largest jerk ({unit}/s^3).', positive),
        limit('min_jerk', f'Smallest jerk ({unit}/s^3); NaN: -max_jerk.', negative),
    )


# Which has_*_limits switch turns each limit off (see velocity_limit_params).
_SWITCHES = {'min_velocity': 'velocity', 'max_velocity': 'velocity',
             'max_acceleration_reverse': 'acceleration', 'max_acceleration': 'acceleration',
             'max_deceleration': 'acceleration', 'max_deceleration_reverse': 'acceleration',
             'min_jerk': 'jerk', 'max_jerk': 'jerk'}


def velocity_limiter(params: Mapping[str, Any], group: str) -> RateLimiter:
    """Build the limiter of ``group`` from the nested ``params``; InvalidLimitsError if crossed.

    A limit whose ``has_*_limits`` switch is present and false is off (NaN).
    """
    axis, direction = group.split('.')
    values = params[axis][direction]
    return RateLimiter(RateLimits(**{
        name: values[name] if values.get(f'has_{switch}_limits', True) else math.nan
        for name, switch in _SWITCHES.items()}))
