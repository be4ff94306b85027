"""PyBullet's per-step calls from compiled code, where the package was built with it.

Every physics step makes three PyBullet calls: the joint torques, one
``stepSimulation``, the joint states (and a fourth before them where velocity
motors drive joints: their targets and forces).  Through PyBullet's Python module each
call parses its arguments, and ``stepSimulation`` builds a dict of solver
statistics per step that nobody reads.  ``_compiled_step`` (C, built by
``pip install`` / colcon when a compiler is there) sends the same commands
through PyBullet's C API, without that parsing and that dict.  The results
are the same to the last bit.

Design notes: docs/design/sim.md#compiled_steppy.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable, Sequence
from types import ModuleType
from typing import Protocol

from pan_tilt_sim.controllers.toolbox import step_law
from pan_tilt_sim.sim.bullet import pybullet, quiet_native_output

ENVIRONMENT_SWITCH = 'PAN_TILT_SIM_COMPILED_STEP'

try:
    from pan_tilt_sim.sim import _compiled_step
except ImportError:  # built without a compiler: the Python calls serve
    _compiled_step = None

API_VERSION: int | None = _compiled_step.API_VERSION if _compiled_step else None
_bound = False


def layout_mismatch(compiled: ModuleType) -> str:
    """Say how ``compiled``'s law layout differs from step_law's ('' where it is the same).

    ``compiled`` is ``_compiled_step`` or anything with its attributes
    ``LAW_FIELDS`` ({field name: row index}), ``LAW_ROW_SIZE`` and
    ``LAW_KINDS`` ({kind name: code}); every field, the row size and every
    kind that differs is named, in row order, then kind order.
    """
    try:
        fields, row_size, kinds = compiled.LAW_FIELDS, compiled.LAW_ROW_SIZE, compiled.LAW_KINDS
    except AttributeError:
        return 'it exports no law layout (LAW_FIELDS, LAW_ROW_SIZE, LAW_KINDS)'
    ours = {name: getattr(step_law, name) for name in step_law.FIELDS}
    differences = [
        f'field {name} at {_where(ours.get(name))} in step_law, {_where(fields.get(name))} in C'
        for name in [*step_law.FIELDS, *sorted(set(fields) - set(ours), key=fields.get)]
        if ours.get(name) != fields.get(name)]
    if row_size != step_law.ROW_SIZE:
        differences.append(f'ROW_SIZE {step_law.ROW_SIZE} in step_law, {row_size} in C')
    differences += [
        f'law kind {name} {_code(step_law.KINDS.get(name))} in step_law, '
        f'{_code(kinds.get(name))} in C'
        for name in [*step_law.KINDS, *sorted(set(kinds) - set(step_law.KINDS), key=kinds.get)]
        if step_law.KINDS.get(name) != kinds.get(name)]
    return '; '.join(differences)


def _where(index: int | None) -> str:
    return 'no index' if index is None else f'index {index}'


def _code(code: float | None) -> str:
    return 'missing' if code is None else f'is {code:g}'


# A compiled step whose row layout is not step_law's would read gains as
# states and write states over gains: the physics would be wrong without an
# error.  Such a build (the installed extension compiled from another
# _compiled_step.c than this package's step_law.py) is not used at all, not
# even for the plain per-step calls: its parts come from two sources, and the
# Python loop, the reference, gives the right results.  A warning rather
# than an error: the simulation stays correct and runs, only slower, while
# the warning names every field that differs, so the stale build is seen and
# rebuilt; the test install additionally asserts that nothing refuses it.
_LAYOUT_MISMATCH = layout_mismatch(_compiled_step) if _compiled_step else ''
if _LAYOUT_MISMATCH:
    warnings.warn(f'{_compiled_step.__file__} was built with another law row layout than '
                  f'pan_tilt_sim.controllers.toolbox.step_law ({_LAYOUT_MISMATCH}); '
                  'the physics steps through Python: reinstall pan_tilt_sim to rebuild it',
                  RuntimeWarning, stacklevel=1)  # the importer's frame would be importlib's


class Connection(Protocol):
    """The C API client of one simulation (``_compiled_step.Connection``)."""

    closed: bool

    def stepper(self, body: int, joints: Sequence[int], effort_dofs: Sequence[int],
                motor_dofs: Sequence[int] = ()) -> Callable[[Sequence[float]], tuple]:
        """Return ``step(efforts)``: torques on ``effort_dofs``, one step, ``joints``' states.

        Its ``drive(efforts, targets, forces, gains)`` first sets the velocity
        motors of ``motor_dofs`` (target velocity, maximum force, velocity
        gain), as ``setJointMotorControlArray`` in ``VELOCITY_CONTROL`` does.
        """

    def close(self) -> None:
        """Forget the client; steppers raise RuntimeError from then on."""


def unavailable_reason() -> str:
    """Say why the physics would step through Python ('' if the compiled step is usable)."""
    if os.environ.get(ENVIRONMENT_SWITCH, '1') == '0':
        return f'{ENVIRONMENT_SWITCH}=0'
    if _compiled_step is None:
        return 'pan_tilt_sim was installed without its compiled step (no C compiler?)'
    if _LAYOUT_MISMATCH:
        return f'the compiled step was built with another law row layout: {_LAYOUT_MISMATCH}'
    if pybullet.getAPIVersion() != API_VERSION:
        return (f'PyBullet C API version {pybullet.getAPIVersion()}, the compiled step '
                f'knows {API_VERSION}')
    return ''


def connect(client: int) -> Connection | None:
    """Return a compiled-step connection to PyBullet client ``client``, or None.

    Call it once the robot is loaded (the connection learns the bodies that
    exist then) and close the connection before ``client`` disconnects.
    """
    global _bound
    if unavailable_reason():
        return None
    if not _bound:
        _compiled_step.bind(pybullet.__file__)
        _bound = True
    with quiet_native_output():
        plugin = pybullet.loadPlugin(_compiled_step.__file__, _compiled_step.PLUGIN_POSTFIX,
                                     physicsClientId=client)
    if plugin < 0:
        raise RuntimeError(f'PyBullet refused the compiled step plugin {_compiled_step.__file__}')
    return _compiled_step.take_connection()
