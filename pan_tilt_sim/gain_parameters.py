"""Live PID tuning: every PID gain is a node parameter, as dynamic_reconfigure made it.

For each PID, ``<prefix>.p``, ``.i``, ``.d`` and ``.i_clamp`` are declared
from the gains in effect (the YAML's, or the controller's defaults).  The
prefix follows the YAML the gains come from:

* ``<controller>.pid`` for a one-joint controller (ROS 1 style, as the seed's
  ``joint1_position_controller.pid.p``);
* ``<controller>.gains.<joint>`` for each joint of a multi-joint controller
  (ros2_controllers style, as ``arm_controller.gains.shoulder_joint.p``).
  ``ros2 param set /sim_node
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

from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter

from pan_tilt_sim.controllers.base import Controller
from pan_tilt_sim.controllers.pid import GainsError, Pid, PidGains
from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.parameters import DOUBLE, coerce, declare

PID_PREFIX = 'pid'
GAINS_PREFIX = 'gains'
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


def controller_pids(controller: Controller) -> dict[str, Pid]:
    """Return the PIDs of ``controller`` by parameter prefix (none for PID-less types)."""
    pid = getattr(controller, 'pid', None)
    if isinstance(pid, Pid):
        return {f'{controller.name}.{PID_PREFIX}': pid}
    pids = {}
    members = getattr(controller, 'members', None)
    if members is not None:  # a group: one one-joint controller per joint
        for member in members:
            member_pid = getattr(member, 'pid', None)
            if isinstance(member_pid, Pid):
                pids[f'{controller.name}.{GAINS_PREFIX}.{member.joint_names[0]}'] = member_pid
    joint_pids = getattr(controller, 'pids', None)
    if joint_pids is not None:  # one PID per joint, in joint order
        for joint, joint_pid in zip(controller.joint_names, joint_pids, strict=True):
            pids[f'{controller.name}.{GAINS_PREFIX}.{joint}'] = joint_pid
    return pids


class GainParameters:
    """Declares the PID gain parameters of ``controllers`` on ``node`` and applies changes."""

    def __init__(self, node: Node, controllers: Iterable[Controller]) -> None:
        self._pids: dict[str, Pid] = {}
        for controller in controllers:
            self._pids.update(controller_pids(controller))
        self._fields = {prefix: gain_fields(pid.gains) for prefix, pid in self._pids.items()}
        # Declare before listening; values given at start-up (-p ...) pass the same check.
        for prefix, pid in self._pids.items():
            declared = {field: self._declare(node, prefix, field, value)
                        for field, value in field_values(pid.gains, self._fields[prefix]).items()}
            pid.gains = self._checked(prefix, declared)
        node.add_on_set_parameters_callback(self.on_set_parameters)

    def parameter_names(self) -> list[str]:
        """Return the names of every gain parameter."""
        return [f'{prefix}.{field}' for prefix, fields in self._fields.items() for field in fields]

    def on_set_parameters(self, changed: list[Parameter]) -> SetParametersResult:
        """Validate and apply the gain parameters among ``changed``; ignore the rest."""
        updates: dict[str, dict[str, float]] = {}
        try:
            for parameter in changed:
                prefix, _, field = parameter.name.rpartition('.')
                if field not in self._fields.get(prefix, ()):
                    continue
                updates.setdefault(prefix, {})[field] = coerce(
                    parameter.name, DOUBLE, parameter.value)
            new_gains = {prefix: self._checked(prefix, fields)
                         for prefix, fields in updates.items()}
        except ParameterError as err:
            return SetParametersResult(successful=False, reason=str(err))
        for prefix, gains in new_gains.items():
            self._pids[prefix].gains = gains
        return SetParametersResult(successful=True)

    def _checked(self, prefix: str, fields: dict[str, float]) -> PidGains:
        try:
            return apply_fields(self._pids[prefix].gains, fields)
        except GainsError as err:
            field, _, problem = str(err).partition(': ')
            if field in self._fields[prefix]:
                raise ParameterError(f"parameter '{prefix}.{field}': {problem}") from None
            raise ParameterError(f"parameters '{prefix}.*': {err}") from None

    @staticmethod
    def _declare(node: Node, prefix: str, field: str, value: float) -> float:
        return declare(node, f'{prefix}.{field}', DOUBLE, value,
                       f'{prefix}: {DESCRIPTIONS[field]}', read_only=False)
