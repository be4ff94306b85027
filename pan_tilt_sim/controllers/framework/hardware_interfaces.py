"""The robot's interfaces beside its joints: ros2_control ``<sensor>`` and ``<gpio>`` entries.

ros2_control names every interface ``<component>/<interface>``
(``tcp_fts_sensor/force.x``, ``flange_vacuum/vacuum``); a controller claims
state interfaces to read and command interfaces to write.  Here each is a
small object holding one value (a double; NaN until something sets it),
shared by the simulation and the controllers as joints share
:class:`~pan_tilt_sim.controllers.framework.base.JointHandle` (see the design notes).

Design notes: docs/design/controllers.md#hardware_interfacespy.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Protocol

# The command interfaces the simulation drives a joint through, as the refusal to
# activate a controller claiming another one words them.
DRIVABLE = 'position, velocity, effort and acceleration'


class StateInterface:
    """One state interface: ``<component>/<interface>`` and its present value (NaN: none yet)."""

    __slots__ = ('name', 'value', 'initial_value')

    def __init__(self, name: str, initial_value: float = math.nan) -> None:
        self.name = name
        self.initial_value = initial_value
        self.value = initial_value

    def reset(self) -> None:
        """Back to the initial value."""
        self.value = self.initial_value


class CommandInterface:
    """One command interface: the value a controller last wrote (NaN: none since the start).

    ``echo``: the state interface the hardware mirrors a finite command
    into (None: none), as mock hardware does for a gpio.
    """

    __slots__ = ('name', 'value', 'echo')

    def __init__(self, name: str, echo: StateInterface | None = None) -> None:
        self.name = name
        self.value = math.nan
        self.echo = echo

    def write(self, value: float) -> None:
        """Command ``value``; a finite one shows at once in the echoed state interface."""
        self.value = value
        if self.echo is not None and math.isfinite(value):
            self.echo.value = value

    def reset(self) -> None:
        """Forget the command (NaN), as at start-up."""
        self.value = math.nan


class SensorSource(Protocol):
    """What the simulation attaches to a :class:`SensorHandle` to fill it."""

    def write(self, handle: SensorHandle, time: float) -> bool:
        """Write the readings at sim ``time`` into the handle; False if none is valid yet."""

    def set_watched(self, watched: bool) -> None:
        """Someone reads the sensor (True) or nobody does any more (False)."""

    def use_frame(self, frame: str) -> str | None:
        """Place or express the readings in ``frame``, a reader's; return any problem."""

    def reset(self) -> None:
        """Forget what earlier readings left behind (the simulation was reset)."""


class SensorHandle:
    """A ``<sensor>``'s state interfaces, by short name (``force.x``), written by the simulation.

    Readers register with :meth:`watch` while they take samples, ask for
    fresh readings with :meth:`refresh` and then read the interfaces'
    values.  Without a source attached (no simulation, or an interface set
    it cannot produce) the values keep their initial ones.
    """

    def __init__(self, name: str, interfaces: Iterable[StateInterface]) -> None:
        self.name = name
        self.interfaces: dict[str, StateInterface] = {
            _short(interface.name, name): interface for interface in interfaces}
        self.source: SensorSource | None = None
        self._watchers: set[object] = set()

    def attach(self, source: SensorSource) -> None:
        """Let ``source`` (the simulation) fill this sensor's interfaces."""
        self.source = source
        source.set_watched(bool(self._watchers))

    def watch(self, reader: object, watching: bool) -> None:
        """Register ``reader`` as taking samples (or no longer); the source hears of changes."""
        before = bool(self._watchers)
        if watching:
            self._watchers.add(reader)
        else:
            self._watchers.discard(reader)
        if self.source is not None and bool(self._watchers) != before:
            self.source.set_watched(bool(self._watchers))

    def refresh(self, time: float) -> bool:
        """Have the simulation write the readings at sim ``time``; False if none is valid yet.

        Without a source the interfaces keep their values and this is True.
        """
        return True if self.source is None else self.source.write(self, time)

    def use_frame(self, frame: str) -> str | None:
        """Tell the simulation a reader publishes in ``frame``; return a problem, if any."""
        return None if self.source is None else self.source.use_frame(frame)

    def reset(self) -> None:
        """Back to the initial values; the source forgets its past readings."""
        for interface in self.interfaces.values():
            interface.reset()
        if self.source is not None:
            self.source.reset()


class GpioHandle:
    """A ``<gpio>``'s command and state interfaces, by short name."""

    def __init__(self, name: str, commands: Iterable[CommandInterface],
                 states: Iterable[StateInterface]) -> None:
        self.name = name
        self.commands: dict[str, CommandInterface] = {
            _short(command.name, name): command for command in commands}
        self.states: dict[str, StateInterface] = {
            _short(state.name, name): state for state in states}

    def reset(self) -> None:
        """Commands forgotten, states back to their initial values."""
        for command in self.commands.values():
            command.reset()
        for state in self.states.values():
            state.reset()


class HardwareInterfaces:
    """The robot's sensors and gpios, and their interfaces by full name."""

    def __init__(self, sensors: Iterable[SensorHandle] = (),
                 gpios: Iterable[GpioHandle] = ()) -> None:
        self.sensors: dict[str, SensorHandle] = {sensor.name: sensor for sensor in sensors}
        self.gpios: dict[str, GpioHandle] = {gpio.name: gpio for gpio in gpios}
        self.state_interfaces: dict[str, StateInterface] = {
            interface.name: interface for sensor in self.sensors.values()
            for interface in sensor.interfaces.values()}
        self.state_interfaces.update({state.name: state for gpio in self.gpios.values()
                                      for state in gpio.states.values()})
        self.command_interfaces: dict[str, CommandInterface] = {
            command.name: command for gpio in self.gpios.values()
            for command in gpio.commands.values()}
        self._sensor_of = {interface.name: sensor for sensor in self.sensors.values()
                           for interface in sensor.interfaces.values()}

    def sensor_of(self, interface: str) -> SensorHandle | None:
        """Return the sensor whose state interface ``interface`` (full name) is, if any."""
        return self._sensor_of.get(interface)

    def reset(self) -> None:
        """Every sensor and gpio back to its initial state (the simulation was reset)."""
        for sensor in self.sensors.values():
            sensor.reset()
        for gpio in self.gpios.values():
            gpio.reset()


def _short(full: str, component: str) -> str:
    """``<component>/<interface>`` -> ``<interface>``."""
    prefix = f'{component}/'
    if not full.startswith(prefix):
        raise ValueError(f"interface '{full}' is not one of component '{component}'")
    return full[len(prefix):]


NO_HARDWARE = HardwareInterfaces()
EXAMPLE_SENSOR = 'sensor1'
EXAMPLE_GPIO = 'gpio1'
EXAMPLE_SENSOR_INTERFACES = (
    'force.x', 'force.y', 'force.z', 'torque.x', 'torque.y', 'torque.z',
    'orientation.x', 'orientation.y', 'orientation.z', 'orientation.w',
    'angular_velocity.x', 'angular_velocity.y', 'angular_velocity.z',
    'linear_acceleration.x', 'linear_acceleration.y', 'linear_acceleration.z',
    'position.x', 'position.y', 'position.z', 'range')


def example_hardware() -> HardwareInterfaces:
    """Return the sensor and gpio the parameter specs' examples name (docs, every-type test).

    ``sensor1`` has every sensor interface the broadcasters read (all 0.0);
    ``gpio1`` a command ``output1`` echoed into its state ``output1``.
    """
    sensor = SensorHandle(EXAMPLE_SENSOR, [StateInterface(f'{EXAMPLE_SENSOR}/{name}', 0.0)
                                           for name in EXAMPLE_SENSOR_INTERFACES])
    state = StateInterface(f'{EXAMPLE_GPIO}/output1', 0.0)
    gpio = GpioHandle(EXAMPLE_GPIO, [CommandInterface(f'{EXAMPLE_GPIO}/output1', state)],
                      [state])
    return HardwareInterfaces([sensor], [gpio])
