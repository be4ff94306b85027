"""``position_controllers/`` and ``effort_controllers/JointPositionController``.

The command (rad or m) becomes a setpoint that is clamped to the joint's
position limits and ramps toward the command no faster than the velocity
limit; a PID on the position error, with the derivative on the measured
velocity, gives the joint effort, clamped to the effort limit.  Until the
first command arrives the setpoint is the joint's position at start, so the
joint holds still.
"""

from __future__ import annotations

from pan_tilt_sim.controllers.base import CommandResult, JointHandle
from pan_tilt_sim.controllers.limits import PositionLimits
from pan_tilt_sim.controllers.pid import PidGains
from pan_tilt_sim.controllers.single_joint import PidJointController

# The seed's gains, used when the YAML gives none: with the seed's damping
# they track critically damped or slower for link inertias up to ~10 kg m^2.
DEFAULT_POSITION_GAINS = PidGains(p=100.0, i=0.01, d=10.0)


class JointPositionController(PidJointController):
    """Position setpoint -> effort, through a PID."""

    type_names = ('position_controllers/JointPositionController',
                  'effort_controllers/JointPositionController')
    default_gains = DEFAULT_POSITION_GAINS

    @property
    def setpoint(self) -> float:
        """Return the rate-limited position setpoint the PID tracks now."""
        return self._setpoint

    def bind(self, handle: JointHandle) -> None:
        """Take the joint's position limits and velocity limit, and build the PID."""
        super().bind(handle)
        self._limits = PositionLimits(handle.spec)
        self._max_velocity = self._limits.max_velocity

    def setpoints(self) -> dict[str, float]:
        """Return the rate-limited position setpoint the PID tracks now."""
        return {self._joint_name: self._setpoint}

    def reset(self) -> None:
        """Hold the joint where it is; forget commands and the integral."""
        self._setpoint = self._handle.position
        self._command = self._setpoint
        self._pid.reset()

    def set_command(self, value: float) -> CommandResult:
        """Store a position command (clamped to the limits; NaN/Inf rejected)."""
        value, result = self._limits.check(value)
        if result is not CommandResult.REJECTED:
            self._command = value
        return result

    def update(self, time: float, period: float) -> None:
        """Ramp the setpoint, then compute and clamp the effort."""
        # The ramp (at most max_velocity * period per step) and clamp_effort,
        # written out: this runs every
        # physics step, and the two calls cost a third of it.
        handle = self._handle
        setpoint = self._setpoint
        command = self._command
        max_step = self._max_velocity * period
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
