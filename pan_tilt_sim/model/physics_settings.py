"""PyBullet's solver settings as sim_node's parameters: names, defaults, checks. No ROS.

Named as PyBullet names them in ``setPhysicsEngineParameter`` (snake case):
``numSolverIterations``, ``erp``, ``contactERP``, ``globalCFM``,
``contactSlop``, ``useSplitImpulse``.  The defaults are the values PyBullet
3.2.7 starts a simulation with, so leaving them alone changes nothing.  An
SDF world's ``<physics>`` gives them other defaults
(:mod:`pan_tilt_sim.model.sdf_world`); the parameters win where given.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

# Most constraint solver iterations per step taken: far beyond any use, small enough that a
# typo (1e9) does not freeze the simulation in one step.
MAX_SOLVER_ITERATIONS = 10_000


@dataclasses.dataclass(frozen=True)
class PhysicsSettings:
    """PyBullet's constraint solver settings (the defaults: PyBullet's own)."""

    solver_iterations: int = 50  # per step (numSolverIterations)
    erp: float = 0.2  # joint error reduction per step, 0..1
    contact_erp: float = 0.08  # contact error reduction per step, 0..1 (contactERP)
    cfm: float = 0.0  # constraint force mixing, >= 0 (globalCFM)
    contact_slop: float = 1e-5  # m of penetration left uncorrected (contactSlop)
    split_impulse: bool = True  # correct penetration apart from velocity (useSplitImpulse)


DEFAULT_PHYSICS = PhysicsSettings()
NAMES = tuple(field.name for field in dataclasses.fields(PhysicsSettings))
DESCRIPTIONS = {
    'solver_iterations': "Constraint solver iterations per physics step (PyBullet's "
                         f'numSolverIterations, 1 .. {MAX_SOLVER_ITERATIONS}).',
    'erp': "Share of a joint's constraint error corrected per step (PyBullet's erp, 0 .. 1).",
    'contact_erp': "Share of a contact's penetration corrected per step (PyBullet's "
                   'contactERP, 0 .. 1).',
    'cfm': "Constraint force mixing: softens every constraint (PyBullet's globalCFM, >= 0).",
    'contact_slop': "Penetration (m) left uncorrected, so resting contacts do not jitter "
                    "(PyBullet's contactSlop, >= 0).",
    'split_impulse': 'Correct penetration apart from the velocities, so it adds no energy '
                     "(PyBullet's useSplitImpulse).",
}


def setting_problem(name: str, value: Any) -> str | None:
    """Say why ``value`` is no value for physics setting ``name``, or None."""
    where = f"parameter '{name}'"
    if name == 'split_impulse':
        return None if isinstance(value, bool) else f'{where} must be a bool, got {value!r}'
    if name == 'solver_iterations':
        if isinstance(value, bool) or not isinstance(value, int) or not (
                1 <= value <= MAX_SOLVER_ITERATIONS):
            return (f'{where} must be a whole number from 1 to {MAX_SOLVER_ITERATIONS}, '
                    f'got {value!r}')
        return None
    if name not in NAMES:
        raise KeyError(name)
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        return f'{where} must be a finite number, got {value!r}'
    if name in ('erp', 'contact_erp') and not 0.0 <= value <= 1.0:
        return f'{where} must be from 0 to 1 (a share of the error per step), got {value!r}'
    if value < 0.0:
        return f'{where} must be >= 0, got {value!r}'
    return None
