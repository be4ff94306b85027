"""Shared steps of the per-controller spec tests: the manager's lifecycle and config errors.

A controller under test is loaded into a :class:`ControllerManager` without a
robot model (every joint takes any command interface), then configured,
activated, commanded and cleaned up through it, as controller_manager's
services would.  Configuration errors are matched on the ``controller.field``
they name, not on the wording of the problem.  Sensors and gpios are built
here too, a :class:`FakeSource` standing in for the simulation that fills a
sensor's interfaces.
"""

from __future__ import annotations

import pathlib
import re
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import pytest

from pan_tilt_sim.controllers import JointHandle
from pan_tilt_sim.controllers.framework.hardware_interfaces import (
    NO_HARDWARE,
    GpioHandle,
    HardwareInterfaces,
    SensorHandle,
    StateInterface,
)
from pan_tilt_sim.controllers.framework.manager import ControllerManager
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.controller_config import ControllersConfig, ControllerSpec

SOURCE = 'test.yaml'
DT = 0.001  # s: the physics step every update is given


def loaded(name: str, type_name: str, params: Mapping[str, Any],
           handles: Mapping[str, JointHandle],
           hardware: HardwareInterfaces = NO_HARDWARE) -> ControllerManager:
    """Return a manager (no robot model) that has loaded ``name``: it is unconfigured."""
    config = ControllersConfig((ControllerSpec(name, type_name, params),), pathlib.Path(SOURCE))
    manager = ControllerManager(config, handles, autostart=False, hardware=hardware)
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


class FakeSource:
    """A sensor source standing in for the simulation: hands out readings it is given.

    ``readings`` (by short interface name) are written at every refresh;
    ``valid`` False makes a refresh report no valid reading.  ``watched``,
    ``frames`` and ``refreshed`` record what the readers asked.
    """

    def __init__(self, readings: Mapping[str, float] | None = None, problem: str | None = None):
        self.readings = dict(readings or {})
        self.valid = True
        self.watched = False
        self.frames: list[str] = []
        self.refreshed: list[float] = []
        self.resets = 0
        self._problem = problem

    def write(self, handle: SensorHandle, time: float) -> bool:
        self.refreshed.append(time)
        if not self.valid:
            return False
        for name, value in self.readings.items():
            handle.interfaces[name].value = value
        return True

    def set_watched(self, watched: bool) -> None:
        self.watched = watched

    def use_frame(self, frame: str) -> str | None:
        self.frames.append(frame)
        return self._problem

    def reset(self) -> None:
        self.resets += 1


def sensor(name: str, interfaces: Sequence[str], source: FakeSource | None = None
           ) -> SensorHandle:
    """Return a sensor handle with ``interfaces`` (NaN), fed by ``source`` if given."""
    handle = SensorHandle(name, [StateInterface(f'{name}/{interface}')
                                 for interface in interfaces])
    if source is not None:
        handle.attach(source)
    return handle


def hardware(*sensors: SensorHandle, gpios: Sequence[GpioHandle] = ()) -> HardwareInterfaces:
    """Return the robot's sensors and gpios for a controller under test."""
    return HardwareInterfaces(sensors, gpios)


def _copied(value: Any) -> Any:
    """Return ``value`` with every list or tuple in it copied as a list (sinks must copy)."""
    if isinstance(value, list | tuple):
        return [_copied(item) for item in value]
    return value


def sample_sink(samples: list) -> Callable[..., None]:
    """Return a sink that appends every sample (its arguments, lists copied) to ``samples``."""
    def sink(*values: Any) -> None:
        samples.append(tuple(_copied(value) for value in values))
    return sink
