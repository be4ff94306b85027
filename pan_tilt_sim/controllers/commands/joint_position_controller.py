"""``position_controllers/`` and ``effort_controllers/JointPositionController``.

The command (rad or m) becomes a setpoint that is clamped to the joint's
position limits and moves toward the command within the velocity limit.
Until the first command arrives the setpoint is the joint's position at
start, so the joint holds still.  What follows the setpoint:

* with PID gains (``pid:``, or ``gazebo_ros_control/pid_gains/<joint>``; the
  ``effort_controllers/`` type always, with defaults): the setpoint ramps at
  the velocity limit, and a PID on the position error, with the derivative
  on the measured velocity, gives the joint effort, clamped to the effort
  limit -- gazebo_ros_control's behaviour with gains;
* without: the ideal actuator (:mod:`pan_tilt_sim.controllers.toolbox.actuator`):
  the setpoint also respects an acceleration limit, and a velocity motor
  capped at the effort limit tracks it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from pan_tilt_sim.controllers.framework.base import ActuatorKind, CommandResult, JointHandle
from pan_tilt_sim.controllers.framework.single_joint import PidJointController
from pan_tilt_sim.controllers.toolbox.actuator import ARRIVED, SETPOINT_ACCELERATION, ramp
from pan_tilt_sim.controllers.toolbox.gains import DEFAULT_POSITION_GAINS
from pan_tilt_sim.controllers.toolbox.limits import PositionLimits
from pan_tilt_sim.controllers.toolbox.step_law import (
    INTEGRAL,
    LAST_MEASUREMENT,
    OUTPUT,
    POSITION_PID,
    SETPOINT,
    pid_row,
)


class JointPositionController(PidJointController):
    """Position command: a limited setpoint, tracked by the ideal actuator or, with gains, a PID."""

    type_names = ('position_controllers/JointPositionController',
                  'effort_controllers/JointPositionController')
    default_gains = DEFAULT_POSITION_GAINS
    pid_kind = ActuatorKind.POSITION_PID
    ideal_kind = ActuatorKind.IDEAL_POSITION
    # The command the ideal actuator ramps to, as the last update took it; None while the
    # controller updates every physics step and ramps in its update itself.
    _held: float | None = None

    @property
    def setpoint(self) -> float:
        """Return the limited position setpoint the joint tracks now."""
        return self._setpoint

    def bind(self, handle: JointHandle) -> None:
        """Take the joint's position limits and velocity limit, and choose the actuator."""
        super().bind(handle)
        self._limits = PositionLimits(handle.spec)
        self._max_velocity = self._limits.max_velocity

    def setpoints(self) -> dict[str, float]:
        """Return the limited position setpoint the joint tracks now."""
        return {self._joint_name: self._setpoint}

    def reset(self) -> None:
        """Hold the joint where it is; forget commands and the integral."""
        self._setpoint = self._handle.position
        self._rate = 0.0
        self._command = self._setpoint
        if self._held is not None:
            self._held = self._command
        if self._pid is not None:
            self._pid.reset()

    def set_command(self, value: float) -> CommandResult:
        """Store a position command (clamped to the limits; NaN/Inf rejected)."""
        value, result = self._limits.check(value)
        if result is not CommandResult.REJECTED:
            self._command = value
        return result

    def step_law(self) -> tuple[JointHandle, list[float]] | None:
        """With a PID: the position PID's row (:mod:`pan_tilt_sim.controllers.toolbox.step_law`)."""
        pid = self._pid
        if pid is None:
            return None
        return self._handle, pid_row(POSITION_PID, pid.law_values(), self._max_velocity,
                                     self._effort_limit, self._setpoint, self._command)

    def absorb_step_law(self, row: Sequence[float]) -> None:
        """Take the setpoint and the PID's state from a compiled loop's row."""
        self._setpoint = row[SETPOINT]
        self._pid.restore(row[INTEGRAL], row[OUTPUT], row[LAST_MEASUREMENT])

    def actuation(self) -> Callable[[float], None] | None:
        """Without gains: the ideal actuator, which ramps and tracks the held command every step.

        From then on an update only takes the command (the command
        interface's value), as ros2_control's forward command controller does.
        """
        if self._pid is not None:
            return None
        self._held = self._command
        return self._actuate

    def _actuate(self, time_step: float) -> None:
        self._ideal_step(self._held, time_step)

    def update(self, time: float, period: float) -> None:
        """Move the setpoint, then compute the effort or the velocity target."""
        if self._pid is None:
            if self._held is None:
                self._ideal_step(self._command, period)
            else:  # the hardware ramps and tracks it every physics step (actuation)
                self._held = self._command
            return
        handle = self._handle
        setpoint = self._setpoint
        command = self._command
        max_velocity = self._max_velocity
        # The ramp (at most max_velocity * period per step) and clamp_effort,
        # written out: this runs every physics step, and the two calls cost a
        # third of it.
        max_step = max_velocity * period
        delta = command - setpoint
        if delta > max_step:
            setpoint += max_step
        elif delta < -max_step:
            setpoint -= max_step
        else:
            setpoint = command
        self._setpoint = setpoint
        effort = self._pid.compute(setpoint, handle.position, period, handle.velocity)
        limit = self._effort_limit
        handle.effort = limit if effort > limit else -limit if effort < -limit else effort

    def _ideal_step(self, command: float, period: float) -> None:
        """Run the ideal actuator for one step of ``period`` s: the ramp, the velocity target."""
        handle = self._handle
        setpoint = self._setpoint
        max_velocity = self._max_velocity
        # Written out: the common case of a setpoint at rest on its command costs two
        # comparisons.
        rate = self._rate
        delta = command - setpoint
        if rate != 0.0 or not -ARRIVED < delta < ARRIVED:
            setpoint, rate = ramp(setpoint, rate, command, period, max_velocity,
                                  SETPOINT_ACCELERATION)
            # Braking for a command that reversed can carry the setpoint a little
            # past the one it was heading for: it stops at a limit it would cross.
            limits = self._limits
            if setpoint > limits.upper >= self._setpoint:
                setpoint, rate = limits.upper, 0.0
            elif setpoint < limits.lower <= self._setpoint:
                setpoint, rate = limits.lower, 0.0
            self._setpoint, self._rate = setpoint, rate
        target = rate + self._tracking_gain / period * (setpoint - handle.position)
        handle.velocity_target = (max_velocity if target > max_velocity else
                                  -max_velocity if target < -max_velocity else target)
