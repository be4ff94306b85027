"""Parameter entries several controller types share (see :mod:`.parameter_spec`).

Names, types and defaults are ros2_controllers' (jazzy) where the parameter
exists upstream; ``joint`` and ``pid`` are ROS 1's (gazebo_ros_control), as
the pan/tilt example's controllers file writes them.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from pan_tilt_sim.controllers.parameter_spec import (
    BOOL,
    DOUBLE,
    REQUIRED,
    STRING,
    STRING_ARRAY,
    Param,
    gt,
    gt_eq,
    names,
    not_empty,
    unique,
)
from pan_tilt_sim.model.controller_config import DEFAULT_UPDATE_RATE

UPDATE_RATE = Param('update_rate', DOUBLE, None, "Updates per second of sim time; the "
                    "controller_manager's rate (100 Hz unless the file says otherwise) by "
                    'default.', (gt(0.0),))
JOINT = Param('joint', STRING, REQUIRED, 'The joint this controller drives.',
              (not_empty(),), read_only=True, example='joint1')
JOINTS = Param('joints', STRING_ARRAY, REQUIRED, 'The joints this controller drives, in '
               'the order of every command.', (not_empty(), names(), unique()), read_only=True,
               example=['joint1'])


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
