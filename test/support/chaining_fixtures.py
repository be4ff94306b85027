"""A chainable controller for the chaining tests, registered only while a test runs.

:class:`ChainableTestController` is a small ``pid_controller``-like type: for
every joint of ``joints`` it exports the reference interface
``<controller>/<joint>/position`` and drives the joint toward it through the
joint's velocity interface -- a velocity target ``GAIN * (reference -
position)`` for the ideal velocity actuator, zero while the reference is
NaN.  Outside chained mode its own command topic
(``<controller>/reference``, one position per joint) writes the references.
It records its lifecycle calls in :attr:`ChainableTestController.calls`.

:func:`register_chainable` puts the type into the registry for one test.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import pytest

from pan_tilt_sim.controllers.framework import registry
from pan_tilt_sim.controllers.framework.base import (
    Actuator,
    ActuatorKind,
    CommandController,
    CommandKind,
    CommandResult,
    JointHandle,
    Reference,
    is_sane_number,
)
from pan_tilt_sim.controllers.framework.parameter_spec import ParameterSpec
from pan_tilt_sim.controllers.framework.shared_parameters import JOINTS

CHAINABLE_TYPE = 'test_controllers/ChainableTestController'
GAIN = 10.0  # 1/s: velocity target per metre or radian of reference error
INTERFACE = 'velocity'


class ChainableTestController(CommandController):
    """Tracks one position reference per joint (exported) with a velocity target."""

    type_names = (CHAINABLE_TYPE,)
    chainable = True
    command_topic = 'reference'
    command_kind = CommandKind.FLOAT64_ARRAY

    parameters = ParameterSpec([JOINTS])

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        self._joint_names = tuple(self.params['joints'])
        self._exported = {f'{name}/{joint}/position': Reference(f'{name}/{joint}/position')
                          for joint in self._joint_names}
        self._handles: list[JointHandle] = []
        # ('reset' | 'deactivate' | 'chained' | 'unchained', controller name), in call order.
        self.calls: list[tuple[str, str]] = []

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The joints it drives."""
        return self._joint_names

    def reference_interfaces(self) -> Mapping[str, Reference]:
        """Return ``<name>/<joint>/position`` for every joint."""
        return self._exported

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the velocity interface of every joint."""
        return {joint: (INTERFACE,) for joint in self._joint_names}

    def actuators(self) -> dict[str, Actuator]:
        """Return the ideal velocity actuator for every joint."""
        return {joint: Actuator(ActuatorKind.IDEAL_VELOCITY, self.name)
                for joint in self._joint_names}

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Bind the joints' handles, then reset."""
        self._handles = [self.handle(joints, joint, 'joints') for joint in self._joint_names]
        self.reset()

    def reset(self) -> None:
        """Forget the references (NaN: hold still)."""
        self.calls.append(('reset', self.name))
        for reference in self._exported.values():
            reference.value = math.nan

    def deactivate(self) -> None:
        """Record the call."""
        self.calls.append(('deactivate', self.name))

    def set_chained_mode(self, chained: bool) -> None:
        """Record the call, then change mode."""
        self.calls.append(('chained' if chained else 'unchained', self.name))
        super().set_chained_mode(chained)

    def set_command(self, value: Sequence[float]) -> CommandResult:
        """Write one position per joint to the references."""
        if len(value) != len(self._exported) or not all(map(is_sane_number, value)):
            return CommandResult.REJECTED
        for reference, element in zip(self._exported.values(), value, strict=True):
            reference.value = float(element)
        return CommandResult.ACCEPTED

    def setpoints(self) -> dict[str, float]:
        """Return each joint's reference."""
        return {joint: reference.value
                for joint, reference in zip(self._joint_names, self._exported.values(),
                                            strict=True)}

    def update(self, time: float, period: float) -> None:
        """Set each joint's velocity target toward its reference."""
        for handle, reference in zip(self._handles, self._exported.values(), strict=True):
            value = reference.value
            handle.velocity_target = 0.0 if math.isnan(value) else GAIN * (
                value - handle.position)


def register_chainable(monkeypatch: pytest.MonkeyPatch) -> str:
    """Register :class:`ChainableTestController` until the test ends; return its type name."""
    monkeypatch.setitem(registry.CONTROLLER_TYPES, CHAINABLE_TYPE, ChainableTestController)
    return CHAINABLE_TYPE
