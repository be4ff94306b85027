"""Shared steps of the per-controller spec tests: the manager's lifecycle and config errors.

A controller under test is loaded into a :class:`ControllerManager` without a
robot model (every joint takes any command interface), then configured,
activated, commanded and cleaned up through it, as controller_manager's
services would.  Configuration errors are matched on the ``controller.field``
they name, not on the wording of the problem.
"""

from __future__ import annotations

import pathlib
import re
from collections.abc import Mapping
from typing import Any

import pytest

from pan_tilt_sim.controllers import JointHandle
from pan_tilt_sim.controllers.manager import ControllerManager
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.controller_config import ControllersConfig, ControllerSpec

SOURCE = 'test.yaml'
DT = 0.001  # s: the physics step every update is given


def loaded(name: str, type_name: str, params: Mapping[str, Any],
           handles: Mapping[str, JointHandle]) -> ControllerManager:
    """Return a manager (no robot model) that has loaded ``name``: it is unconfigured."""
    config = ControllersConfig((ControllerSpec(name, type_name, params),), pathlib.Path(SOURCE))
    manager = ControllerManager(config, handles, autostart=False)
    manager.load(name, type_name, params)
    return manager


def step(manager: ControllerManager, steps: int, start: int = 0) -> None:
    """Run the active controllers' per-step updates ``steps`` times, DT apart, from ``start``."""
    for number in range(start, start + steps):
        for update in manager.updates:
            update(number * DT, DT)


def raises_naming(field: str) -> Any:
    """Expect a ControllerConfigError that names ``field`` (``controller.field``, or inside it).

    The error reads ``<file>: <controller>.<field>: <problem>``; only the
    field is matched, so the wording of the problem may change.
    """
    return pytest.raises(ControllerConfigError,
                         match=rf'(^|: ){re.escape(field)}(\.[^\s:]+)?: ')
