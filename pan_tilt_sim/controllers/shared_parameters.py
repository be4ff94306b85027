"""Parameter entries several controller types share (see :mod:`.parameter_spec`).

Names, types and defaults are ros2_controllers' (jazzy) where the parameter
exists upstream; ``joint`` and ``pid`` are ROS 1's (gazebo_ros_control), as
the pan/tilt example's controllers file writes them.
"""

from __future__ import annotations

from pan_tilt_sim.controllers.parameter_spec import (
    BOOL,
    DOUBLE,
    REQUIRED,
    STRING,
    STRING_ARRAY,
    Param,
    gt_eq,
    names,
    not_empty,
    unique,
)

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
