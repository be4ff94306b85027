"""Live PID tuning: every PID gain is a node parameter, as control_toolbox's PidROS makes it.

For each PID, the tunable entries of its controller's parameter spec
(:meth:`~pan_tilt_sim.controllers.framework.parameter_spec.ParameterSpec.tunable`) are
declared, from the gains in effect (the YAML's, or the controller's
defaults): ``<prefix>.p``, ``.i``, ``.d``, ``.i_clamp_max``, ``.i_clamp_min``
(doubles) and ``.antiwindup`` (bool), whatever the YAML wrote (its ``i_clamp: x`` is
``i_clamp_min = -x``, ``i_clamp_max = x``).  The prefix follows the YAML the
gains come from (:attr:`Controller.gains_field`):

* ``<controller>.pid`` for a one-joint controller (ROS 1 style, as the pan/tilt example's
  ``joint1_position_controller.pid.p``);
* ``<controller>.gains.<joint>`` for each joint of a multi-joint controller
  (ros2_controllers style, as ``arm_controller.gains.shoulder_joint.p``).

Design notes: docs/design/ros.md#gain_parameterspy.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Sequence
from typing import Any

from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter

from pan_tilt_sim.controllers.framework import parameter_spec
from pan_tilt_sim.controllers.framework.base import Controller
from pan_tilt_sim.controllers.framework.parameter_spec import Param
from pan_tilt_sim.controllers.framework.shared_parameters import pid_gains
from pan_tilt_sim.controllers.toolbox.gains import PID_FIELD
from pan_tilt_sim.controllers.toolbox.pid import GainsError, Pid, PidGains
from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.ros.parameters import BOOL, DOUBLE, coerce, declare

# The node parameter type of each spec type a gain may have.
NODE_TYPES = {parameter_spec.DOUBLE: DOUBLE, parameter_spec.BOOL: BOOL}


def tunable_fields(controller: Controller) -> dict[str, Param]:
    """Return the live-tunable gain entries of ``controller``'s spec, by their last name."""
    return {param.name.rpartition('.')[2]: param
            for param in type(controller).parameters.tunable()}


# Every PID's tunable gains, as the shared spec declares them (p, i, d, the clamp, antiwindup).
FIELDS = tuple(param.name.rpartition('.')[2] for param in pid_gains(PID_FIELD) if param.tunable)


def field_values(gains: PidGains, fields: Iterable[str] = FIELDS) -> dict[str, Any]:
    """Return the value of each gain parameter field for ``gains``."""
    values = dataclasses.asdict(gains)
    return {field: values[field] for field in fields}


def apply_fields(gains: PidGains, updates: dict[str, Any]) -> PidGains:
    """Return ``gains`` with the fields in ``updates`` replaced; GainsError if invalid."""
    return dataclasses.replace(gains, **updates)


def parameter_prefixes(controller: Controller) -> dict[str, Pid]:
    """Return the PIDs of ``controller`` by the prefix of their gain parameters."""
    pids = controller.pids()
    if controller.gains_field == PID_FIELD:
        return {f'{controller.name}.{PID_FIELD}': pid for pid in pids.values()}
    return {f'{controller.name}.{controller.gains_field}.{joint}': pid
            for joint, pid in pids.items()}


class GainParameters:
    """Declares the PID gain parameters of ``controllers`` on ``node`` and applies changes.

    Controllers configured later are added with :meth:`add` and leave with
    :meth:`remove` (their parameters are undeclared).
    """

    def __init__(self, node: Node, controllers: Iterable[Controller] = ()) -> None:
        self._node = node
        self._pids: dict[str, Pid] = {}
        self._fields: dict[str, dict[str, Param]] = {}
        self._by_controller: dict[str, list[str]] = {}
        # Declare before listening; values given at start-up (-p ...) pass the same check.
        for controller in controllers:
            self.add(controller)
        node.add_on_set_parameters_callback(self.on_set_parameters)
        node.add_post_set_parameters_callback(self.on_parameters_set)

    def add(self, controller: Controller) -> None:
        """Declare the gain parameters of ``controller`` (values given with -p must pass)."""
        self.remove(controller.name)
        prefixes = parameter_prefixes(controller)
        fields = tunable_fields(controller)
        self._by_controller[controller.name] = list(prefixes)
        for prefix, pid in prefixes.items():
            # Known to the on-set check only once declared: a bad start-up value (-p) then
            # ends here with the one-line ParameterError, not rclpy's exception.
            declared = {field: self._declare(self._node, prefix, fields[field], value)
                        for field, value in field_values(pid.gains, fields).items()}
            self._fields[prefix] = fields
            self._pids[prefix] = pid
            pid.gains = self._checked(prefix, declared)

    def remove(self, name: str) -> None:
        """Undeclare the gain parameters of controller ``name`` (if any)."""
        for prefix in self._by_controller.pop(name, ()):
            self._pids.pop(prefix, None)
            for field in self._fields.pop(prefix, {}):
                full = f'{prefix}.{field}'
                if self._node.has_parameter(full):
                    self._node.undeclare_parameter(full)

    def parameter_names(self) -> list[str]:
        """Return the names of every gain parameter."""
        return [f'{prefix}.{field}' for prefix in self._pids for field in self._fields[prefix]]

    def on_set_parameters(self, changed: Sequence[Parameter]) -> SetParametersResult:
        """Check the gain parameters among ``changed`` (the rest are not ours); apply nothing."""
        try:
            self._new_gains(changed)
        except ParameterError as err:
            return SetParametersResult(successful=False, reason=str(err))
        return SetParametersResult(successful=True)

    def on_parameters_set(self, changed: Sequence[Parameter]) -> None:
        """Apply the gain parameters among ``changed``, which the on-set check accepted."""
        for prefix, gains in self._new_gains(changed).items():
            self._pids[prefix].gains = gains

    def _new_gains(self, changed: Sequence[Parameter]) -> dict[str, PidGains]:
        updates: dict[str, dict[str, Any]] = {}
        for parameter in changed:
            prefix, _, field = parameter.name.rpartition('.')
            if prefix not in self._pids or field not in self._fields[prefix]:
                continue
            updates.setdefault(prefix, {})[field] = coerce(
                parameter.name, NODE_TYPES[self._fields[prefix][field].type], parameter.value)
        return {prefix: self._checked(prefix, fields) for prefix, fields in updates.items()}

    def _checked(self, prefix: str, fields: dict[str, Any]) -> PidGains:
        try:
            return apply_fields(self._pids[prefix].gains, fields)
        except GainsError as err:
            field, _, problem = str(err).partition(': ')
            if field in self._fields[prefix]:
                raise ParameterError(f"parameter '{prefix}.{field}': {problem}") from None
            raise ParameterError(f"parameters '{prefix}.*': {err}") from None

    @staticmethod
    def _declare(node: Node, prefix: str, param: Param, value: Any) -> Any:
        field = param.name.rpartition('.')[2]
        return declare(node, f'{prefix}.{field}', NODE_TYPES[param.type], value,
                       f'{prefix}: {param.description}', read_only=False)
