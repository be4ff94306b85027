"""The shared part of the broadcasters of ``<ros2_control>`` sensors (force-torque, IMU...).

A sensor broadcaster reads state interfaces of the robot's sensors
(:mod:`~pan_tilt_sim.controllers.framework.hardware_interfaces`) at its update rate -- the
controller_manager's, as upstream's broadcasters publish at every update --
and hands each sample to its sink.  While nobody listens (no sink) it takes
no sample, and the sensors it reads are not watched, so the simulation does
not measure them.  A sample is taken only when every sensor it reads has a
valid reading
(:meth:`~pan_tilt_sim.controllers.framework.hardware_interfaces.SensorHandle.refresh`): the first
one after someone starts listening may be skipped.

At configure the broadcaster tells its sensors the ``frame_id`` it stamps
(:meth:`~pan_tilt_sim.controllers.framework.hardware_interfaces.SensorHandle.use_frame`): the
simulation places a sensor that nothing in the URDF places there, or gives
its readings in that frame; what it cannot do becomes a notice (the node
logs it).
"""

from __future__ import annotations

import abc
import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from pan_tilt_sim.controllers.framework.base import Controller, JointHandle
from pan_tilt_sim.controllers.framework.hardware_interfaces import SensorHandle, StateInterface
from pan_tilt_sim.controllers.framework.shared_parameters import update_period
from pan_tilt_sim.schedule import DUE_EPSILON, PeriodicSchedule

FRAME_ID = 'frame_id'
SENSOR_NAME = 'sensor_name'


class SensorBroadcaster(Controller):
    """Samples sensor state interfaces at its update rate while someone listens."""

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        self._schedule = PeriodicSchedule(update_period(self.params))
        self._sinks: dict[str, Callable[..., None] | None] = {}
        self._interfaces: list[StateInterface | None] = []
        self._sensors: list[SensorHandle] = []

    @property
    def frame_id(self) -> str:
        """The frame the samples are stamped with."""
        return self.params.get(FRAME_ID, '')

    @abc.abstractmethod
    def interface_names(self) -> list[tuple[str, str]]:
        """Return ``(full interface name, field naming it)`` in sample order; '' for none."""

    @abc.abstractmethod
    def take_sample(self, time: float, values: Sequence[float]) -> None:
        """Hand the values (in :meth:`interface_names` order, NaN for none) to the sinks."""

    def state_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the sensor state interfaces read, by sensor."""
        claimed: dict[str, list[str]] = {}
        for name, _field in self.interface_names():
            if name:
                component, _, interface = name.rpartition('/')
                claimed.setdefault(component, []).append(interface)
        return {component: tuple(names) for component, names in claimed.items()}

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Find the state interfaces and their sensors; tell the sensors the frame_id."""
        self._watch(False)
        self._interfaces = [self.state_interface(name, field) if name else None
                            for name, field in self.interface_names()]
        sensors: dict[str, SensorHandle] = {}
        for interface in self._interfaces:
            sensor = None if interface is None else self._hardware.sensor_of(interface.name)
            if sensor is not None:
                sensors.setdefault(sensor.name, sensor)
        self._sensors = list(sensors.values())
        for sensor in self._sensors:
            problem = sensor.use_frame(self.frame_id) if self.frame_id else None
            if problem:
                self.notices.append(f"{FRAME_ID} '{self.frame_id}': {problem}")
        self._watch(True)
        self.reset()

    def connect(self, topic: str) -> Callable[[Any], None]:
        """Return the ``connect`` of state topic ``topic``: it takes that topic's sink."""
        self._sinks.setdefault(topic, None)

        def connect(sink: Any) -> None:
            self._sinks[topic] = sink
            self._watch(True)
        return connect

    def sink(self, topic: str) -> Callable[..., None] | None:
        """Return the sink of state topic ``topic`` (None: nobody listens)."""
        return self._sinks.get(topic)

    def _watch(self, on: bool) -> None:
        listened = on and any(sink is not None for sink in self._sinks.values())
        for sensor in self._sensors:
            sensor.watch(self, listened)

    def reset(self) -> None:
        """Sample at the next update, then every period."""
        self._schedule.reset()

    def schedule(self) -> PeriodicSchedule:
        """Return the sample schedule: the loop calls :meth:`update` only when one is due."""
        return self._schedule

    def update(self, time: float, period: float) -> None:
        """When a sample is due and someone listens: fresh readings to the sinks."""
        schedule = self._schedule
        if time + DUE_EPSILON < schedule.next_due:
            return
        schedule.advance(time)
        if not any(sink is not None for sink in self._sinks.values()):
            return
        for sensor in self._sensors:
            if not sensor.refresh(time):
                return
        self.take_sample(time, [math.nan if interface is None else interface.value
                                for interface in self._interfaces])
