"""Per-step controller updates written as data, for a compiled stepping loop.

A controller's :meth:`~pan_tilt_sim.controllers.base.Controller.update` is
the reference: Python, run every physics step.  Where the per-step update of
every active controller is one of the laws below, the stepping loop may run
many steps in compiled code instead (:mod:`pan_tilt_sim.sim.compiled_step`)
and must get the same results to the last bit, operation for operation.  A
controller offers its law with ``step_law()`` -- its joint's handle and a
row of floats laid out as below -- and takes the row back, with the state
the compiled steps left in it, with ``absorb_step_law(row)``.

The one law so far is the position PID (``JointPositionController`` with
gains, alone or as a member of a group): the setpoint ramps toward the
command at most ``max_velocity * dt`` per step, a :class:`~.pid.Pid` on the
position error with the measured velocity as the rate gives the effort,
which is clamped to the effort limit.
"""

from __future__ import annotations

# The position PID's row: the gains (antiwindup as 0.0 / 1.0), the limits, then the state.
(P_GAIN, I_GAIN, D_GAIN, I_CLAMP_MIN, I_CLAMP_MAX, ANTIWINDUP, MAX_VELOCITY, EFFORT_LIMIT,
 SETPOINT, COMMAND, INTEGRAL, OUTPUT) = range(12)
POSITION_PID_SIZE = 12
