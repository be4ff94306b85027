"""Live PID tuning: every PID gain is a node parameter, as dynamic_reconfigure made it.

For each controller with a PID, ``<controller>.pid.p``, ``.i``, ``.d`` and
``.i_clamp`` are declared from the gains in effect (the YAML's, or the
controller's defaults).  ``ros2 param set /sim_node
joint1_position_controller.pid.p 50`` changes the gain at the next physics
step; the integral term is kept (:class:`~pan_tilt_sim.controllers.pid.Pid`
stores it already multiplied by ``i``).  Invalid values -- negative, not
finite, not a number -- are refused with a reason and change nothing.
Integers are accepted for these doubles.

``i_clamp`` bounds the integral term symmetrically, as in the YAML.  A
controller whose YAML gives an asymmetric ``i_clamp_min``/``i_clamp_max``
gets those two parameters instead.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Sequence

from rcl_interfaces.msg import ParameterDescriptor, SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter

from pan_tilt_sim.controllers.base import Controller
from pan_tilt_sim.controllers.pid import GainsError, Pid, PidGains
from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.extra_parameters import DOUBLE
from pan_tilt_sim.parameters import coerce

PID_PREFIX = 'pid'
SYMMETRIC_FIELDS = ('p', 'i', 'd', 'i_clamp')
ASYMMETRIC_FIELDS = ('p', 'i', 'd', 'i_clamp_min', 'i_clamp_max')
DESCRIPTIONS = {
    'p': 'Proportional gain.',
    'i': 'Integral gain.',
    'd': 'Derivative gain (on the measured rate).',
    'i_clamp': 'Bound of the integral term, +-i_clamp (same unit as the effort).',
    'i_clamp_min': 'Lower bound of the integral term.',
    'i_clamp_max': 'Upper bound of the integral term.',
}


def gain_fields(gains: PidGains) -> tuple[str, ...]:
    """Return the parameter fields that describe ``gains`` (symmetric clamp or not)."""
    if gains.i_clamp_min == -gains.i_clamp_max:
        return SYMMETRIC_FIELDS
    return ASYMMETRIC_FIELDS


def field_values(gains: PidGains, fields: Sequence[str]) -> dict[str, float]:
    """Return the value of each parameter field for ``gains``."""
    values = dataclasses.asdict(gains)
    values['i_clamp'] = gains.i_clamp_max
    return {field: values[field] for field in fields}


def apply_fields(gains: PidGains, updates: dict[str, float]) -> PidGains:
    """Return ``gains`` with the fields in ``updates`` replaced; GainsError if invalid."""
    changes = dict(updates)
    if 'i_clamp' in changes:
        bound = changes.pop('i_clamp')
        if not bound >= 0.0:  # also refuses NaN
            raise GainsError(f'i_clamp: {bound!r} must be a number >= 0')
        changes['i_clamp_min'], changes['i_clamp_max'] = -bound, bound
    return dataclasses.replace(gains, **changes)


class GainParameters:
    """Declares the PID gain parameters of ``controllers`` on ``node`` and applies changes."""

    def __init__(self, node: Node, controllers: Iterable[Controller]) -> None:
        self._pids: dict[str, Pid] = {}
        self._fields: dict[str, tuple[str, ...]] = {}
        for controller in controllers:
            pid = getattr(controller, 'pid', None)
            if not isinstance(pid, Pid):
                continue
            fields = gain_fields(pid.gains)
            self._pids[controller.name] = pid
            self._fields[controller.name] = fields
        # Declare before listening; values given at start-up (-p ...) pass the same check.
        for name, pid in self._pids.items():
            declared = {field: self._declare(node, name, field, value)
                        for field, value in field_values(pid.gains, self._fields[name]).items()}
            pid.gains = self._checked(name, declared)
        node.add_on_set_parameters_callback(self.on_set_parameters)

    def parameter_names(self) -> list[str]:
        """Return the names of every gain parameter."""
        return [_parameter_name(controller, field)
                for controller, fields in self._fields.items() for field in fields]

    def on_set_parameters(self, changed: list[Parameter]) -> SetParametersResult:
        """Validate and apply the gain parameters among ``changed``; ignore the rest."""
        updates: dict[str, dict[str, float]] = {}
        try:
            for parameter in changed:
                owner = self._owner(parameter.name)
                if owner is None:
                    continue
                controller, field = owner
                updates.setdefault(controller, {})[field] = coerce(
                    parameter.name, DOUBLE, parameter.value)
            new_gains = {controller: self._checked(controller, fields)
                         for controller, fields in updates.items()}
        except ParameterError as err:
            return SetParametersResult(successful=False, reason=str(err))
        for controller, gains in new_gains.items():
            self._pids[controller].gains = gains
        return SetParametersResult(successful=True)

    def _owner(self, name: str) -> tuple[str, str] | None:
        controller, separator, rest = name.rpartition(f'.{PID_PREFIX}.')
        if not separator or rest not in self._fields.get(controller, ()):
            return None
        return controller, rest

    def _checked(self, controller: str, fields: dict[str, float]) -> PidGains:
        try:
            return apply_fields(self._pids[controller].gains, fields)
        except GainsError as err:
            field, _, problem = str(err).partition(': ')
            if field in self._fields[controller]:
                raise ParameterError(
                    f"parameter '{_parameter_name(controller, field)}': {problem}") from None
            raise ParameterError(
                f"parameters '{controller}.{PID_PREFIX}.*': {err}") from None

    @staticmethod
    def _declare(node: Node, controller: str, field: str, value: float) -> float:
        name = _parameter_name(controller, field)
        # Dynamic typing lets integers through; coerce() checks the type instead.
        descriptor = ParameterDescriptor(
            name=name, type=DOUBLE, description=f'{controller}: {DESCRIPTIONS[field]}',
            dynamic_typing=True)
        return coerce(name, DOUBLE, node.declare_parameter(name, value, descriptor).value)


def _parameter_name(controller: str, field: str) -> str:
    return f'{controller}.{PID_PREFIX}.{field}'
