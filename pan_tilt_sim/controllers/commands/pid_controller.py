"""``pid_controller/PidController``: one PID per degree of freedom, chainable.

ros2_controllers' (jazzy) PID controller.  Its parameters are those of
upstream's ``pid_controller.yaml``; ``dof_names`` are the degrees of freedom
it commands through ``command_interface``, and ``reference_and_state_dof_names``
(default: ``dof_names``) those whose references it takes and whose state it
reads, through the one or two ``reference_and_state_interfaces`` (the second
is the first derivative of the first: ``[position, velocity]``).

Design notes: docs/design/controllers.md#pid_controllerpy.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from pan_tilt_sim.controllers.framework.base import (
    MAX_COMMAND_MAGNITUDE,
    Actuator,
    ActuatorKind,
    CommandController,
    CommandKind,
    CommandResult,
    JointHandle,
    Reference,
    clamp,
    is_sane_number,
)
from pan_tilt_sim.controllers.framework.parameter_spec import (
    BOOL,
    DOUBLE,
    REQUIRED,
    STRING,
    STRING_ARRAY,
    Param,
    ParameterSpec,
    Validator,
    gt_eq,
    not_empty,
    one_of,
    unique,
)
from pan_tilt_sim.controllers.framework.surface import CommandTopic, Endpoint, Service, StateTopic
from pan_tilt_sim.controllers.toolbox.actuator import ARRIVED, SETPOINT_ACCELERATION, ramp
from pan_tilt_sim.controllers.toolbox.gains import GAINS_FIELD
from pan_tilt_sim.controllers.toolbox.limits import PositionLimits
from pan_tilt_sim.controllers.toolbox.pid import GainsError, Pid, PidGains

DOF_NAMES = 'dof_names'
REFERENCE_DOFS = 'reference_and_state_dof_names'
COMMAND_INTERFACE = 'command_interface'
INTERFACES = 'reference_and_state_interfaces'
FIRST_SETPOINT = 'set_current_state_as_first_setpoint'
EXTERNAL_STATES = 'use_external_measured_states'
ENABLE_FEEDFORWARD = 'enable_feedforward'
GAINS = f'{GAINS_FIELD}.__map_{DOF_NAMES}'
# The interfaces a joint of the simulator has (its handle's attributes of the same names).
JOINT_INTERFACES = ('position', 'velocity', 'effort')
CONTROLLER_STATE = 'control_msgs/msg/MultiDOFStateStamped'
SET_BOOL = 'std_srvs/srv/SetBool'
# Upstream's warning when the service is called.
FEEDFORWARD_SERVICE_NOTICE = ('This service will be deprecated in favour of setting the '
                              '``feedforward_gain`` parameter to a non-zero value.')
ANTIWINDUP_STRATEGIES = ('back_calculation', 'conditional_integration', 'legacy', 'none')
TWO_PI = 2.0 * math.pi


def _one_or_two() -> Validator:
    """Require one or two elements (upstream's ``size_gt<> 0`` and ``size_lt<> 3``)."""
    return Validator('1 or 2 elements', lambda value: None if 0 < len(value) < 3 else
                     f'must have 1 or 2 elements, has {len(value)}')


def _gain(name: str, default: float, description: str, **flags: Any) -> Param:
    return Param(f'{GAINS}.{name}', DOUBLE, default, description, **flags)


PARAMETERS = ParameterSpec([
    Param(DOF_NAMES, STRING_ARRAY, REQUIRED,
          'The degrees of freedom commanded: joints, or `<controller>/<dof>` reference '
          'interfaces of chainable controllers.', (not_empty(), unique()), read_only=True,
          example=['joint1']),
    Param(REFERENCE_DOFS, STRING_ARRAY, [], 'The degrees of freedom whose references are '
          'exported and whose state is read, one per entry of dof_names (empty: dof_names).',
          (unique(),), read_only=True),
    Param(COMMAND_INTERFACE, STRING, REQUIRED, 'The interface every DoF is commanded through '
          '(position, velocity or effort on a joint).', (not_empty(),), read_only=True,
          example='effort'),
    Param(INTERFACES, STRING_ARRAY, REQUIRED, 'The reference and state interfaces; the '
          'second is the first derivative of the first.', (not_empty(), _one_or_two()),
          read_only=True, example=['position']),
    Param(FIRST_SETPOINT, BOOL, True, 'On activation, take the present state as the first '
          'reference.', read_only=True),
    Param(EXTERNAL_STATES, BOOL, False, 'Read the state from `~/measured_state` instead of '
          'the state interfaces.'),
    Param(ENABLE_FEEDFORWARD, BOOL, False, 'Start in feed-forward mode '
          '(`~/set_feedforward_control` switches it).'),
    _gain('p', 0.0, 'Proportional gain.', validators=(gt_eq(0.0),), tunable=True),
    _gain('i', 0.0, 'Integral gain.', validators=(gt_eq(0.0),), tunable=True),
    _gain('d', 0.0, 'Derivative gain.', validators=(gt_eq(0.0),), tunable=True),
    _gain('u_clamp_max', math.inf, 'Upper bound of the PID output (the feed-forward term '
          'is added after it).', finite=False),
    _gain('u_clamp_min', -math.inf, 'Lower bound of the PID output.', finite=False),
    Param(f'{GAINS}.antiwindup', BOOL, False, 'Hold the integrator itself within the '
          'integral clamp (else only its contribution).', tunable=True),
    _gain('i_clamp_max', math.inf, 'Upper bound of the integral term.', finite=False,
          tunable=True),
    _gain('i_clamp_min', -math.inf, 'Lower bound of the integral term.', finite=False,
          tunable=True),
    Param(f'{GAINS}.antiwindup_strategy', STRING, 'legacy', "control_toolbox's anti-windup "
          'strategy; only legacy (the integral clamp and antiwindup) is simulated.',
          (one_of(*ANTIWINDUP_STRATEGIES),), simulated=False),
    _gain('tracking_time_constant', 0.0, "The back_calculation strategy's time constant.",
          simulated=False),
    _gain('error_deadband', 1e-16, 'The error within which integration stops.',
          simulated=False),
    _gain('feedforward_gain', 0.0, 'Gain of the feed-forward term (in feed-forward mode).'),
    Param(f'{GAINS}.angle_wraparound', BOOL, False, 'Wrap the error into [-pi, pi] '
          '(continuous joints).'),
    Param(f'{GAINS}.save_i_term', BOOL, True, 'Keep the integral term when the controller '
          'is activated again.'),
    Param(f'{GAINS}.activate_state_publisher', BOOL, False, "Publish the DoF's "
          '`~/<dof>/pid_state`.', simulated=False),
])


@dataclasses.dataclass(frozen=True)
class _DofSettings:
    """The per-DoF entries of ``gains.<dof>`` that are read at configure time."""

    gains: PidGains
    u_min: float
    u_max: float
    feedforward_gain: float
    wraparound: bool
    save_i_term: bool


class _Output:
    """Where one DoF's command goes."""

    def write(self, command: float) -> None:
        """Take a new command."""
        raise NotImplementedError

    def step(self, period: float) -> None:
        """Drive the joint for one step (also without a new command)."""

    def reset(self) -> None:
        """Command nothing until the next command."""


class _ReferenceOutput(_Output):
    """The command is written, as it is, to a following controller's reference interface."""

    def __init__(self, reference: Reference) -> None:
        self.reference = reference

    def write(self, command: float) -> None:
        """Write the reference."""
        self.reference.value = command


class _EffortOutput(_Output):
    """The command is the joint's effort, within its effort limit."""

    def __init__(self, handle: JointHandle) -> None:
        self.handle = handle
        self.limit = handle.spec.effort_limit

    def write(self, command: float) -> None:
        """Apply the effort, clamped."""
        self.handle.effort = clamp(command, -self.limit, self.limit)

    def reset(self) -> None:
        """No effort."""
        self.handle.effort = 0.0


class _VelocityOutput(_Output):
    """The command is the ideal actuator's velocity target, within the velocity limit."""

    def __init__(self, handle: JointHandle) -> None:
        self.handle = handle
        self.limit = handle.spec.velocity_limit

    def write(self, command: float) -> None:
        """Set the velocity target, clamped."""
        self.handle.velocity_target = clamp(command, -self.limit, self.limit)

    def reset(self) -> None:
        """Stand still."""
        self.handle.velocity_target = 0.0


class _PositionOutput(_Output):
    """The command is a position the ideal actuator reaches, as JointPositionController's."""

    def __init__(self, handle: JointHandle) -> None:
        self.handle = handle
        self.limits = PositionLimits(handle.spec)
        self.setpoint = self.command = handle.position
        self.rate = 0.0

    def write(self, command: float) -> None:
        """Aim at the command, clamped into the position limits."""
        self.command = clamp(command, self.limits.lower, self.limits.upper)

    def step(self, period: float) -> None:
        """Move the setpoint toward the command; track it with the velocity target."""
        if period <= 0.0:
            return
        max_velocity = self.limits.max_velocity
        if self.rate != 0.0 or not -ARRIVED < self.command - self.setpoint < ARRIVED:
            self.setpoint, self.rate = ramp(self.setpoint, self.rate, self.command, period,
                                            max_velocity, SETPOINT_ACCELERATION)
        handle = self.handle
        target = self.rate + handle.tracking_gain / period * (self.setpoint - handle.position)
        handle.velocity_target = clamp(target, -max_velocity, max_velocity)

    def reset(self) -> None:
        """Hold the joint where it is."""
        self.setpoint = self.command = self.handle.position
        self.rate = 0.0


OUTPUTS: dict[str, Callable[[JointHandle], _Output]] = {
    'position': _PositionOutput, 'velocity': _VelocityOutput, 'effort': _EffortOutput}
# What drives a joint commanded through the effort interface, by the first reference interface.
EFFORT_KINDS = {'position': ActuatorKind.POSITION_PID, 'velocity': ActuatorKind.VELOCITY_PID}
IDEAL_KINDS = {'position': ActuatorKind.IDEAL_POSITION, 'velocity': ActuatorKind.IDEAL_VELOCITY}


class PidController(CommandController):
    """A PID per DoF from references (a topic, or a preceding controller) to its command."""

    type_names = ('pid_controller/PidController',)
    parameters = PARAMETERS
    chainable = True
    command_topic = 'reference'
    command_kind = CommandKind.MULTI_DOF_COMMAND
    # Whether the position outputs step every physics step in the hardware's place (see
    # actuation) rather than in the update: the controller updates less often.
    _stepped_by_hardware = False

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        values = self.params
        self._dofs: tuple[str, ...] = tuple(values[DOF_NAMES])
        self._state_dofs: tuple[str, ...] = tuple(values[REFERENCE_DOFS]) or self._dofs
        if len(self._state_dofs) != len(self._dofs):
            raise self.error(REFERENCE_DOFS, f'has {len(self._state_dofs)} entries and '
                             f'{DOF_NAMES} {len(self._dofs)}: they must be the same size')
        self._interface: str = values[COMMAND_INTERFACE]
        self._interfaces: tuple[str, ...] = tuple(values[INTERFACES])
        self._external: bool = values[EXTERNAL_STATES]
        self._first_setpoint: bool = values[FIRST_SETPOINT]
        self._settings = tuple(self._dof_settings(dof) for dof in self._dofs)
        # [interface][dof], interface-major as upstream exports them.
        self._references = tuple(
            tuple(Reference(f'{name}/{dof}/{interface}') for dof in self._state_dofs)
            for interface in self._interfaces)
        self._exported = {reference.name: reference for row in self._references
                          for reference in row}
        self._feedforward: bool = values[ENABLE_FEEDFORWARD]
        self._pids: dict[str, Pid] = {}  # by DoF, in the order of dof_names
        self._outputs: list[_Output] = []
        self._state_handles: list[JointHandle] = []
        n = len(self._dofs)
        self._measured = [[math.nan] * n for _ in self._interfaces]
        self._pending: list[tuple[float, float]] | None = None
        self._last_errors = [0.0] * n
        self._commands = [math.nan] * n
        self._problem = ''
        self._measured_problem = ''
        self._sink: Callable[[float, Sequence[Sequence[float]]], None] | None = None

    def _dof_settings(self, dof: str) -> _DofSettings:
        entry = self.params[GAINS_FIELD][dof]
        field = f'{GAINS_FIELD}.{dof}'
        try:
            gains = PidGains(p=entry['p'], i=entry['i'], d=entry['d'],
                             i_clamp_min=entry['i_clamp_min'], i_clamp_max=entry['i_clamp_max'],
                             antiwindup=entry['antiwindup'])
        except GainsError as err:
            raise self.error(field, str(err)) from None
        u_min, u_max = entry['u_clamp_min'], entry['u_clamp_max']
        for bound in ('u_clamp_min', 'u_clamp_max'):
            if math.isnan(entry[bound]):
                raise self.error(f'{field}.{bound}', 'nan must be a number')
        if u_min > u_max:
            raise self.error(f'{field}.u_clamp_min', f'{u_min:g} is greater than '
                             f'u_clamp_max ({u_max:g})')
        return _DofSettings(gains, u_min, u_max, entry['feedforward_gain'],
                            entry['angle_wraparound'], entry['save_i_term'])

    # --- what it claims and exports -----------------------------------------------------------

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The entries of ``dof_names`` (joints, or references it claims)."""
        return self._dofs

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return ``<dof>/<command_interface>`` for every commanded DoF."""
        return {dof: (self._interface,) for dof in self._dofs}

    def state_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return every reference DoF's state interfaces (none with external states)."""
        if self._external:
            return {}
        return {dof: self._interfaces for dof in self._state_dofs}

    def reference_interfaces(self) -> Mapping[str, Reference]:
        """Return ``<name>/<dof>/<interface>`` for every interface and reference DoF."""
        return self._exported

    def pids(self) -> dict[str, Pid]:
        """Return the PID of every commanded DoF, once configured (gains tunable live)."""
        return self._pids

    def actuators(self) -> dict[str, Actuator]:
        """Return what drives each commanded joint while active (references: nothing)."""
        actuators = {}
        first = self._interfaces[0]
        for dof, output in zip(self._dofs, self._outputs, strict=True):
            if isinstance(output, _ReferenceOutput):
                continue
            if isinstance(output, _EffortOutput):
                kind = EFFORT_KINDS.get(first, ActuatorKind.EFFORT)
            else:
                kind = IDEAL_KINDS[self._interface]
            actuators[dof] = Actuator(kind, self.name, self._pids[dof],
                                      f'{self.name}.{GAINS_FIELD}.{dof}')
        return actuators

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the topics and the service, as upstream's.

        ``~/reference``, ``~/measured_state`` (external states only),
        ``~/controller_state`` and ``~/set_feedforward_control``.
        """
        endpoints: list[Endpoint] = [*super().ros_surface()]
        if self._external:
            endpoints.append(CommandTopic('~/measured_state', self.command_kind.value,
                                          self.set_measured_state, self.measured_state_problem,
                                          while_chained=True))
        endpoints.append(StateTopic('~/controller_state', CONTROLLER_STATE, self.connect_state,
                                    {'names': list(self._state_dofs)}))
        endpoints.append(Service('~/set_feedforward_control', SET_BOOL,
                                 self.set_feedforward_control))
        return tuple(endpoints)

    # --- lifecycle ------------------------------------------------------------------------------

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Bind each DoF's command target and state; create the PIDs; then reset."""
        outputs: list[_Output] = []
        for dof in self._dofs:
            target = self.command_target(joints, dof, self._interface, DOF_NAMES)
            if isinstance(target, Reference):
                outputs.append(_ReferenceOutput(target))
            elif self._interface in OUTPUTS:
                outputs.append(OUTPUTS[self._interface](target))
            else:
                raise self.error(COMMAND_INTERFACE, f"'{self._interface}' is not an interface "
                                 f"a joint is commanded through ({', '.join(JOINT_INTERFACES)})")
        handles: list[JointHandle] = []
        if not self._external:
            field = REFERENCE_DOFS if self.params[REFERENCE_DOFS] else DOF_NAMES
            for interface in self._interfaces:
                if interface not in JOINT_INTERFACES:
                    raise self.error(INTERFACES, f"'{interface}' is not a state interface of a "
                                     f"joint ({', '.join(JOINT_INTERFACES)}); an other one "
                                     f'needs {EXTERNAL_STATES}')
            handles = [self.handle(joints, dof, field, commanded=False)
                       for dof in self._state_dofs]
        self._outputs = outputs
        self._state_handles = handles
        self._pids = {dof: Pid(settings.gains)
                      for dof, settings in zip(self._dofs, self._settings, strict=True)}
        self.reset()

    def reset(self) -> None:
        """Start afresh: references from the present state (or NaN), no command yet.

        The PIDs restart; their integral terms stay where ``save_i_term`` says so.
        """
        self._pending = None
        for row in self._measured:
            row[:] = [math.nan] * len(row)
        for row in self._references:
            for reference in row:
                reference.value = math.nan
        if self._first_setpoint and not self._external:
            for row, interface in zip(self._references, self._interfaces, strict=True):
                for reference, handle in zip(row, self._state_handles, strict=True):
                    reference.value = getattr(handle, interface)
        for position, pid in enumerate(self._pids.values()):
            *_gains, integral, _output, _last = pid.law_values()
            pid.reset()
            if self._settings[position].save_i_term:
                pid.restore(integral, 0.0, math.nan)
        self._last_errors = [0.0] * len(self._dofs)
        self._commands = [math.nan] * len(self._dofs)
        for output in self._outputs:
            output.reset()

    # --- inputs ---------------------------------------------------------------------------------

    def set_command(self, value: Any) -> CommandResult:
        """Take a ``~/reference`` message, ``(dof_names, values, values_dot)``.

        Used at the next update unless the controller is in chained mode.
        """
        names, values, values_dot = value
        dofs = self._state_dofs
        expected = len(dofs)
        if not names and len(values) == expected:
            names = dofs
        elif len(names) != expected or len(values) != expected:
            self._problem = (f'Size of input data names ({len(names)}) and/or values '
                             f'({len(values)}) is not matching the expected size ({expected}).')
            return CommandResult.REJECTED
        if values_dot and len(values_dot) != expected:
            self._problem = (f'Size of input data values_dot ({len(values_dot)}) is not '
                             f'matching the expected size ({expected}).')
            return CommandResult.REJECTED
        pending = [(math.nan, math.nan)] * expected
        index = {dof: position for position, dof in enumerate(dofs)}
        for position, name in enumerate(names):
            if name not in index:
                self._problem = f"DoF name '{name}' not found in the defined list of state DoFs."
                return CommandResult.REJECTED
            pair = (values[position], values_dot[position] if values_dot else math.nan)
            for element in pair:
                if not (_is_nan(element) or is_sane_number(element)):
                    self._problem = (f"ignored reference: the value for '{name}' is not a "
                                     f'finite number (within +-{MAX_COMMAND_MAGNITUDE:g})')
                    return CommandResult.REJECTED
            pending[index[name]] = (float(pair[0]), float(pair[1]))
        self._pending = pending
        return CommandResult.ACCEPTED

    def command_problem(self, value: Any, result: CommandResult) -> str:
        """Describe why the last ``~/reference`` message was ignored."""
        return self._problem

    def set_measured_state(self, value: Any) -> CommandResult:
        """Take a ``~/measured_state`` message, ``(dof_names, values, values_dot)``, in order."""
        names, values, values_dot = value
        expected = len(self._state_dofs)
        for what, given in (('names', names), ('values', values)):
            if len(given) != expected:
                self._measured_problem = (f'Size of input data {what} ({len(given)}) is not '
                                          f'matching the expected size ({expected}).')
                return CommandResult.REJECTED
        if values_dot:
            if len(self._interfaces) != 2:
                self._measured_problem = (
                    f'The {INTERFACES} parameter has to have two interfaces [the interface '
                    'and the derivative of the interface], in order to use the values_dot '
                    'field.')
                return CommandResult.REJECTED
            if len(values_dot) != expected:
                self._measured_problem = (
                    f'Size of input data values_dot ({len(values_dot)}) is not matching the '
                    f'expected size ({expected}).')
                return CommandResult.REJECTED
        self._measured[0][:] = [float(item) for item in values]
        if len(self._measured) == 2:
            self._measured[1][:] = ([float(item) for item in values_dot] if values_dot
                                    else [math.nan] * expected)
        return CommandResult.ACCEPTED

    def measured_state_problem(self, value: Any, result: CommandResult) -> str:
        """Describe why the last ``~/measured_state`` message was ignored."""
        return self._measured_problem

    def set_feedforward_control(self, enabled: Any) -> tuple[bool, str]:
        """Enter (true) or leave feed-forward mode; upstream warns the service is deprecated."""
        self._feedforward = bool(enabled)
        self.notices.append(FEEDFORWARD_SERVICE_NOTICE)
        return True, ''

    @property
    def feedforward(self) -> bool:
        """Whether the feed-forward term is added (feed-forward mode)."""
        return self._feedforward

    def connect_state(self, sink: Callable[[float, Sequence[Sequence[float]]], None] | None
                      ) -> None:
        """Take the ``~/controller_state`` sink (None: nobody listens, take no samples).

        Every update then hands it the time and, per reference DoF,
        ``(reference, feedback, feedback_dot, error, error_dot, time_step, output)``.
        """
        self._sink = sink

    # --- the loop -------------------------------------------------------------------------------

    def setpoints(self) -> dict[str, float]:
        """Return each commanded DoF's (first) reference; NaN while it has none."""
        return {dof: reference.value
                for dof, reference in zip(self._dofs, self._references[0], strict=True)}

    def actuation(self) -> Callable[[float], None] | None:
        """For position outputs: the ideal actuator, ramping to and tracking the held command.

        From then on an update writes the commands, and the outputs step
        every physics step here.
        """
        tracked = [output for output in self._outputs if isinstance(output, _PositionOutput)]
        if not tracked:
            return None
        self._stepped_by_hardware = True

        def step(time_step: float) -> None:
            for output in tracked:
                output.step(time_step)

        return step

    def update(self, time: float, period: float) -> None:
        """Take the topic's references (not in chained mode), compute and write the commands."""
        references = self._references
        two = len(references) == 2
        if self._pending is not None and not self._chained:
            for position, (value, value_dot) in enumerate(self._pending):
                if not math.isnan(value):
                    references[0][position].value = value
                    if two and not math.isnan(value_dot):
                        references[1][position].value = value_dot
            self._pending = None
        measured = self._measured
        if not self._external:
            for row, interface in zip(measured, self._interfaces, strict=True):
                row[:] = [getattr(handle, interface) for handle in self._state_handles]
        rows = [] if self._sink is not None else None
        for position, (output, settings, pid) in enumerate(zip(
                self._outputs, self._settings, self._pids.values(), strict=True)):
            reference = references[0][position].value
            state = measured[0][position]
            error = reference - state
            if settings.wraparound:
                error = math.remainder(error, TWO_PI)
            error_dot = math.nan
            if two:
                error_dot = references[1][position].value - measured[1][position]
            if math.isfinite(reference) and math.isfinite(state):
                command = 0.0
                if self._feedforward:
                    fed = references[1][position].value if two else reference
                    if math.isfinite(fed):
                        command = fed * settings.feedforward_gain
                if not math.isfinite(error_dot):
                    # control_toolbox's compute_command(error, dt): the error's difference.
                    last = self._last_errors[position]
                    rate = (error - last) / period if period > 0.0 else 0.0
                    if period > 0.0:
                        self._last_errors[position] = error
                else:
                    rate = error_dot
                command += clamp(pid.compute(error, 0.0, period, -rate), settings.u_min,
                                 settings.u_max)
                self._commands[position] = command
                output.write(command)
            if not self._stepped_by_hardware:
                output.step(period)
            if rows is not None:
                rows.append((reference, state, measured[1][position] if two else 0.0, error,
                             error_dot if two else 0.0, period, self._commands[position]))
        if rows is not None:
            self._sink(time, rows)


def _is_nan(value: Any) -> bool:
    return isinstance(value, float) and math.isnan(value)
