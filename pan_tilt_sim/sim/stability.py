"""Start-up check: is each PID stable for its joint's inertia at this time step.

A PID on effort is explicit: PyBullet applies the torque computed from the
state at the start of the step.  For a position loop ``tau = -p q - d v``
on a joint of effective inertia ``J`` (``1 / (M^-1)_ii``: what a torque on
that joint alone accelerates while the others move freely), PyBullet's
semi-implicit Euler step is stable exactly while

    d * dt / 2 + p * dt^2 / 4 < J

(from the eigenvalues of one step's map; with p = 0 it is the familiar
``d dt < 2 J``).  A velocity loop ``tau = p (v_cmd - v)`` is stable while
``p * dt / 2 < J``.  ``J`` depends on the arm's pose, so the check takes the
smallest over a few poses: the start, the middle of the limits, and a
quarter of the range in from either limit.  A joint that fails gets one
warning naming it, the gain and the largest stable value.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from pan_tilt_sim.controllers.base import ActuatorKind, Drive, JointHandle
from pan_tilt_sim.model.robot import JointKind
from pan_tilt_sim.sim.physics import Physics


def largest_stable_time_step(p: float, d: float, inertia: float) -> float:
    """Return the time step below which ``d dt / 2 + p dt^2 / 4 < inertia``."""
    if p > 0.0:
        return (-d / 2.0 + math.sqrt(d * d / 4.0 + p * inertia)) / (p / 2.0)
    return math.inf if d <= 0.0 else 2.0 * inertia / d


def pid_stability_warnings(physics: Physics, handles: Sequence[JointHandle],
                           time_step: float) -> list[str]:
    """Return one warning per PID-driven joint whose gains are unstable at ``time_step``."""
    # A PID whose output is not an effort (a velocity target, say) is no explicit effort loop.
    checked = [handle for handle in handles
               if handle.actuator.pid is not None and handle.drive is Drive.EFFORT]
    if not checked:
        return []
    inertias = dict(zip((joint.name for joint in physics.joints), physics.smallest_inertias(),
                        strict=True))
    dt = time_step
    warnings = []
    for handle in checked:
        actuator = handle.actuator
        gains = actuator.pid.gains
        inertia = inertias[handle.name]
        unit = 'kg' if handle.spec.kind is JointKind.PRISMATIC else 'kg*m^2'
        where = f"joint '{handle.name}' ({actuator.controller})"
        if actuator.kind is ActuatorKind.VELOCITY_PID:
            if gains.p * dt / 2.0 < inertia:
                continue
            warnings.append(
                f'{where}: velocity PID p {gains.p:g} is unstable at time_step {dt:g} s for '
                f'its effective inertia {inertia:.3g} {unit} (needs p * time_step / 2 < '
                f'inertia): use p < {2.0 * inertia / dt:.3g}, a time_step below '
                f'{2.0 * inertia / gains.p:.3g} s, or no gains (the ideal actuator)')
            continue
        need = gains.d * dt / 2.0 + gains.p * dt * dt / 4.0
        if need < inertia:
            continue
        largest_d = (4.0 * inertia - gains.p * dt * dt) / (2.0 * dt)
        advice = (f'use d < {largest_d:.3g}' if largest_d > 0.0 else
                  f'use p < {4.0 * inertia / (dt * dt):.3g} and a smaller d')
        warnings.append(
            f'{where}: PID p {gains.p:g} d {gains.d:g} is unstable at time_step {dt:g} s for '
            f'its effective inertia {inertia:.3g} {unit} (needs d * time_step / 2 + '
            f'p * time_step^2 / 4 = {need:.3g} < inertia): {advice}, a time_step below '
            f'{largest_stable_time_step(gains.p, gains.d, inertia):.3g} s, or no gains '
            '(the ideal actuator)')
    return warnings
