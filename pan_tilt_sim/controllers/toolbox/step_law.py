"""Per-step controller updates written as data, for a compiled stepping loop.

A controller's :meth:`~pan_tilt_sim.controllers.framework.base.Controller.update` is
the reference: Python, run every physics step.  Where the per-step update of
every active controller is one of the laws below, the stepping loop may run
many steps in compiled code instead (:mod:`pan_tilt_sim.sim.compiled_step`)
and must get the same results to the last bit, operation for operation.  A
controller offers its law with ``step_law()`` -- its joint's handle and a
row of floats laid out as below -- and takes the row back, with the state
the compiled steps left in it, with ``absorb_step_law(row)``.

The laws (``KIND``) (see the design notes).

Design notes: docs/design/controllers.md#step_lawpy.
"""

from __future__ import annotations

# The fields' names in row order: FIELDS[index] names the constant equal to index.
FIELDS = ('KIND', 'P_GAIN', 'I_GAIN', 'D_GAIN', 'I_CLAMP_MIN', 'I_CLAMP_MAX', 'ANTIWINDUP',
          'MAX_VELOCITY', 'EFFORT_LIMIT', 'SETPOINT', 'COMMAND', 'INTEGRAL', 'OUTPUT',
          'LAST_MEASUREMENT', 'UPDATE_STEPS', 'NEXT_UPDATE', 'PERIOD')
ROW_SIZE = len(FIELDS)
(KIND, P_GAIN, I_GAIN, D_GAIN, I_CLAMP_MIN, I_CLAMP_MAX, ANTIWINDUP, MAX_VELOCITY, EFFORT_LIMIT,
 SETPOINT, COMMAND, INTEGRAL, OUTPUT, LAST_MEASUREMENT, UPDATE_STEPS, NEXT_UPDATE,
 PERIOD) = range(ROW_SIZE)

POSITION_PID, VELOCITY_PID, EFFORT = 0.0, 1.0, 2.0
# Each law kind's name and its code in a row's KIND field.
KINDS = {'POSITION_PID': POSITION_PID, 'VELOCITY_PID': VELOCITY_PID, 'EFFORT': EFFORT}
_UNUSED = 0.0
# A row's clock as the laws build it: every step, due at the first, dt the physics step.
EVERY_STEP, DUE_NOW, PHYSICS_STEP = 1.0, 0.0, 0.0


def pid_row(kind: float, pid_values: list[float], max_velocity: float, effort_limit: float,
            setpoint: float, command: float) -> list[float]:
    """Return a PID law's row from :meth:`~.pid.Pid.law_values` and the controller's state."""
    p, i, d, i_min, i_max, antiwindup, integral, output, last = pid_values
    return [kind, p, i, d, i_min, i_max, antiwindup, max_velocity, effort_limit, setpoint,
            command, integral, output, last, EVERY_STEP, DUE_NOW, PHYSICS_STEP]


def effort_row(command: float) -> list[float]:
    """Return the effort law's row."""
    row = [_UNUSED] * ROW_SIZE
    row[KIND] = EFFORT
    row[COMMAND] = command
    row[UPDATE_STEPS], row[NEXT_UPDATE], row[PERIOD] = EVERY_STEP, DUE_NOW, PHYSICS_STEP
    return row
