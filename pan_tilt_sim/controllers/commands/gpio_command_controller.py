"""``gpio_controllers/GpioCommandController``: a robot's ``<gpio>`` ports, commanded and published.

``gpios`` names the ``<gpio>`` entries of the URDF's ``<ros2_control>``
blocks; ``command_interfaces.<gpio>.interfaces`` the command interfaces it
claims of each, ``state_interfaces.<gpio>.interfaces`` the state interfaces
it publishes -- all of every listed gpio's when no gpio lists any, as
upstream reads them from the URDF.  With neither it refuses to configure.

Design notes: docs/design/controllers.md#gpio_command_controllerpy.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from pan_tilt_sim.controllers.framework.base import (
    CommandController,
    CommandResult,
    JointHandle,
)
from pan_tilt_sim.controllers.framework.hardware_interfaces import CommandInterface, StateInterface
from pan_tilt_sim.controllers.framework.parameter_spec import (
    REQUIRED,
    STRING_ARRAY,
    Param,
    ParameterSpec,
    names,
    not_empty,
    unique,
)
from pan_tilt_sim.controllers.framework.shared_parameters import UPDATE_RATE, update_period
from pan_tilt_sim.controllers.framework.surface import CommandTopic, Endpoint, StateTopic
from pan_tilt_sim.schedule import DUE_EPSILON, PeriodicSchedule

GPIOS = 'gpios'
COMMANDS_TOPIC = '~/commands'
STATES_TOPIC = '~/gpio_states'
GROUP_VALUES = 'control_msgs/msg/DynamicInterfaceGroupValues'

# A command as the adapter hands it over: the interface_groups, and per entry of
# interface_values its (interface_names, values).
GroupValues = tuple[Sequence[str], Sequence[tuple[Sequence[str], Sequence[float]]]]
StatesSink = Callable[[float, Sequence[Sequence[float]]], None]


class GpioCommandController(CommandController):
    """Commands gpio interfaces from ``~/commands``; publishes gpio states on ``~/gpio_states``."""

    type_names = ('gpio_controllers/GpioCommandController',)
    parameters = ParameterSpec([
        UPDATE_RATE,
        Param(GPIOS, STRING_ARRAY, REQUIRED, 'The gpios, in the order of the published '
              'groups.', (not_empty(), names(), unique()), read_only=True, example=['gpio1']),
        Param('command_interfaces.__map_gpios.interfaces', STRING_ARRAY, [],
              'The command interfaces claimed of each gpio.', (unique(),), read_only=True,
              example=['output1']),
        Param('state_interfaces.__map_gpios.interfaces', STRING_ARRAY, [],
              "The state interfaces published of each gpio; if no gpio lists any: all of "
              "every gpio's.", (unique(),), read_only=True),
    ])
    command_topic = 'commands'

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        self._schedule = PeriodicSchedule(update_period(self.params))
        self._gpios: tuple[str, ...] = tuple(self.params[GPIOS])
        self._command_names = {gpio: tuple(self._listed('command_interfaces', gpio))
                               for gpio in self._gpios}
        self._commands: dict[str, CommandInterface] = {}
        self._states: list[list[StateInterface]] = []
        self.state_names: tuple[tuple[str, ...], ...] = ()
        self._values: list[list[float]] = []
        self._pending: list[tuple[CommandInterface, float]] = []
        self._sink: StatesSink | None = None
        self._problem = ''

    def _listed(self, section: str, gpio: str) -> list[str]:
        return list(self.params.get(section, {}).get(gpio, {}).get('interfaces', []))

    @property
    def gpios(self) -> tuple[str, ...]:
        """The gpios, in the order of the published groups."""
        return self._gpios

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the claimed command interfaces, by gpio."""
        return {gpio: names for gpio, names in self._command_names.items() if names}

    def state_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the published state interfaces, by gpio (once configured)."""
        return {gpio: names for gpio, names in zip(self._gpios, self.state_names, strict=False)
                if names}

    def setpoints(self) -> dict[str, float]:
        """Return the claimed command interfaces' present values, by full name."""
        return {name: command.value for name, command in self._commands.items()}

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Find every claimed command and published state interface of the robot's gpios."""
        hardware = self._hardware
        for gpio in self._gpios:
            if gpio not in hardware.gpios:
                raise self.error(GPIOS, f"'{gpio}' is not a <gpio> of the robot's "
                                        f"<ros2_control> blocks (gpios: "
                                        f"{', '.join(hardware.gpios) or 'none'})")
        self._commands = {
            f'{gpio}/{interface}': self.command_interface(
                f'{gpio}/{interface}', f'command_interfaces.{gpio}.interfaces')
            for gpio in self._gpios for interface in self._command_names[gpio]}
        listed = {gpio: self._listed('state_interfaces', gpio) for gpio in self._gpios}
        if not any(listed.values()):
            listed = {gpio: list(hardware.gpios[gpio].states) for gpio in self._gpios}
        self._states = [[self.state_interface(f'{gpio}/{interface}',
                                              f'state_interfaces.{gpio}.interfaces')
                         for interface in listed[gpio]] for gpio in self._gpios]
        if not self._commands and not any(self._states):
            raise self.error(GPIOS, 'no command or state interfaces are configured (the '
                                    'gpios have no state interfaces in the URDF and none are '
                                    'listed)')
        self.state_names = tuple(tuple(listed[gpio]) for gpio in self._gpios)
        self._values = [[math.nan] * len(states) for states in self._states]
        self.reset()

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return ``~/commands`` (if it claims command interfaces) and ``~/gpio_states``."""
        states = StateTopic(STATES_TOPIC, GROUP_VALUES, self.set_sink,
                            {'groups': self._gpios, 'interface_names': self.state_names})
        if not any(self._command_names.values()):
            return (states,)
        return (CommandTopic(COMMANDS_TOPIC, GROUP_VALUES, self.set_command,
                             self.command_problem), states)

    def set_sink(self, sink: StatesSink | None) -> None:
        """Where state samples go: ``sink(time, values per gpio)``."""
        self._sink = sink

    def schedule(self) -> PeriodicSchedule:
        """Return the update schedule (the controller_manager's rate)."""
        return self._schedule

    def reset(self) -> None:
        """Forget the command (on every activation); update at once, then every period."""
        self._pending = []
        self._schedule.reset()

    def set_command(self, value: GroupValues) -> CommandResult:
        """Check a whole command; keep it for the next updates or reject it with the reason."""
        try:
            groups, entries = value
            groups, entries = list(groups), list(entries)
        except (TypeError, ValueError):
            self._problem = f'ignored command {value!r}: not interface groups with values'
            return CommandResult.REJECTED
        if len(groups) != len(entries):
            self._problem = (f'ignored command: {len(groups)} interface_groups but '
                             f'{len(entries)} interface_values')
            return CommandResult.REJECTED
        pending = []
        for group, (interface_names, values) in zip(groups, entries, strict=True):
            if len(interface_names) != len(values):
                self._problem = (f'ignored command: for gpio {group} interface_names do not '
                                 f'match values ({len(interface_names)} names, '
                                 f'{len(values)} values)')
                return CommandResult.REJECTED
            for interface, number in zip(interface_names, values, strict=True):
                full = f'{group}/{interface}'
                command = self._commands.get(full)
                if command is None:
                    self._problem = (f"ignored command: '{full}' is not a command interface "
                                     f"of this controller ({', '.join(self._commands)})")
                    return CommandResult.REJECTED
                if not (isinstance(number, int | float) and math.isfinite(number)):
                    self._problem = f"ignored command: the value for '{full}' ({number!r}) " \
                        'is not a finite number'
                    return CommandResult.REJECTED
                pending.append((command, float(number)))
        self._pending = pending
        return CommandResult.ACCEPTED

    def command_problem(self, value: Any, result: CommandResult) -> str:
        """Describe the last rejected command."""
        return self._problem

    def update(self, time: float, period: float) -> None:
        """When due: publish the states (if someone listens), then write the command."""
        schedule = self._schedule
        if time + DUE_EPSILON < schedule.next_due:
            return
        schedule.advance(time)
        if self._sink is not None:
            values = self._values
            for row, states in zip(values, self._states, strict=True):
                for index, state in enumerate(states):
                    row[index] = state.value
            self._sink(time, values)
        for command, number in self._pending:
            command.write(number)
