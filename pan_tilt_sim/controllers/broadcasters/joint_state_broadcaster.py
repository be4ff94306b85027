"""The joint_state_broadcaster (ROS 1: ``joint_state_controller/JointStateController``).

Every ``1 / publish_rate`` seconds of sim time it samples the joints' state
interfaces and hands the samples to its sinks, which the node turns into
messages stamped with sim time:

* ``joint_states`` (``sensor_msgs/msg/JointState``): name, position,
  velocity, effort of each joint that has at least one of the three;
* ``dynamic_joint_states`` (``control_msgs/msg/DynamicJointState``): every
  selected state interface of each joint, by name (unless
  ``publish_dynamic_joint_states`` is false; the node publishes it where
  control_msgs is installed).

Design notes: docs/design/controllers.md#joint_state_broadcasterpy.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from pan_tilt_sim.controllers.framework.base import MEASURED_STATES, Controller, JointHandle
from pan_tilt_sim.controllers.framework.parameter_spec import (
    BOOL,
    DOUBLE,
    STRING,
    STRING_ARRAY,
    Param,
    ParameterSpec,
    names,
    rate,
    unique,
)
from pan_tilt_sim.controllers.framework.surface import PRIVATE, Endpoint, StateTopic
from pan_tilt_sim.schedule import DUE_EPSILON, PeriodicSchedule

DEFAULT_PUBLISH_RATE = 50.0  # Hz, as in the pan/tilt example's YAML
RATE_FIELDS = ('publish_rate', 'update_rate')  # the first one given sets the rate
JOINT_STATE_FIELDS = MEASURED_STATES  # JointState's position, velocity, effort
MAP_FIELD = 'map_interface_to_joint_state'
JOINT_STATE_MESSAGE = 'sensor_msgs/msg/JointState'
DYNAMIC_JOINT_STATE_MESSAGE = 'control_msgs/msg/DynamicJointState'
EXTRA_JOINT_VALUE = 0.0  # position, velocity and effort of an extra joint
UNAVAILABLE = math.nan  # a JointState field the joint has no selected interface for

# sink(time, names, positions, velocities, efforts)
JointStateSink = Callable[[float, Sequence[str], Sequence[float], Sequence[float],
                           Sequence[float]], None]
# sink(time, values): values[i][k] is interface k of joint i, as the topic's fields name them.
DynamicJointStateSink = Callable[[float, Sequence[Sequence[float]]], None]
# A measured value to copy on each sample: into values[index], the handle's attribute.
Read = tuple[list[float], int, JointHandle, str]


class JointStateBroadcaster(Controller):
    """Publishes the joints' state interfaces at its rate of sim time."""

    type_names = ('joint_state_controller/JointStateController',
                  'joint_state_broadcaster/JointStateBroadcaster')
    parameters = ParameterSpec([
        Param('publish_rate', DOUBLE, None, 'Samples per second of sim time (ROS 1).',
              (rate(),)),
        Param('update_rate', DOUBLE, None, "The controller's update rate (Hz); the "
              "controller_manager's by default.", (rate(),)),
        Param('joints', STRING_ARRAY, [], 'With interfaces: the joints to publish, in this '
              'order; if either is empty, every movable joint.', (names(), unique()),
              read_only=True),
        Param('extra_joints', STRING_ARRAY, [], 'Names published with zero position, velocity '
              "and effort after the robot's joints.", (names(), unique()),
              read_only=True),
        Param('interfaces', STRING_ARRAY, [], 'With joints: the state interfaces to publish; '
              'if either is empty, all.', (unique(),), read_only=True),
        Param('use_local_topics', BOOL, False, 'Publish on ~/joint_states and '
              "~/dynamic_joint_states (the controller's namespace) instead of joint_states "
              'and dynamic_joint_states.', read_only=True),
        Param('publish_dynamic_joint_states', BOOL, True, 'Publish every selected state '
              'interface on dynamic_joint_states (control_msgs/msg/DynamicJointState).',
              read_only=True),
        Param(f'{MAP_FIELD}.position', STRING, 'position',
              'The interface published as JointState.position.', read_only=True),
        Param(f'{MAP_FIELD}.velocity', STRING, 'velocity',
              'The interface published as JointState.velocity.', read_only=True),
        Param(f'{MAP_FIELD}.effort', STRING, 'effort',
              'The interface published as JointState.effort.', read_only=True),
    ])

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        field = next((name for name in RATE_FIELDS if name in self.params), None)
        rate = self.params[field] if field else DEFAULT_PUBLISH_RATE
        self._schedule = PeriodicSchedule(1.0 / float(rate))
        joints, interfaces = tuple(self.params['joints']), tuple(self.params['interfaces'])
        # Upstream publishes the joints x interfaces "matrix" only when both are given.
        self._selection = (joints, interfaces) if joints and interfaces else None
        if bool(joints) != bool(interfaces):
            given, empty = ('joints', 'interfaces') if joints else ('interfaces', 'joints')
            self._warn(given, f"ignored while '{empty}' is empty: every state interface of "
                              'every movable joint is published')
        # Each JointState field: the interfaces it is taken from, the first a joint has.
        self._field_sources: dict[str, tuple[str, ...]] = {}
        for joint_field in JOINT_STATE_FIELDS:
            mapped = self.params[MAP_FIELD][joint_field]
            if joint_field in interfaces and self._selection is not None:
                self._field_sources[joint_field] = (joint_field,)
                if mapped != joint_field:
                    self._warn(f'{MAP_FIELD}.{joint_field}',
                               f"'{mapped}' is not published as JointState.{joint_field}: "
                               f"'interfaces' names '{joint_field}' itself")
            else:
                self._field_sources[joint_field] = tuple(dict.fromkeys((mapped, joint_field)))
        self._prefix = PRIVATE if self.params['use_local_topics'] else ''
        self._sink: JointStateSink | None = None
        self._dynamic_sink: DynamicJointStateSink | None = None
        self._selected: dict[str, tuple[str, ...]] = {}
        self.names: list[str] = []
        self.dynamic_names: list[str] = []
        self.dynamic_interfaces: list[tuple[str, ...]] = []
        self.positions: list[float] = []
        self.velocities: list[float] = []
        self.efforts: list[float] = []
        self.dynamic_values: list[list[float]] = []
        self._joint_state_reads: list[Read] = []
        self._dynamic_reads: list[Read] = []

    @property
    def publish_period(self) -> float:
        """Seconds of sim time between samples."""
        return self._schedule.period

    @property
    def publish_rate(self) -> float:
        """Samples per second of sim time."""
        return 1.0 / self._schedule.period

    @property
    def joint_states_topic(self) -> str:
        """Where the JointStates go: ``joint_states``, or ``~/joint_states`` (local topics)."""
        return f'{self._prefix}joint_states'

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the JointState publisher and, unless turned off, the DynamicJointState one.

        The JointState topic's fields: ``names``; the dynamic topic's:
        ``joint_names`` and, per joint, its ``interface_names``.
        """
        surface: list[Endpoint] = [StateTopic(
            self.joint_states_topic, JOINT_STATE_MESSAGE, self.set_sink,
            {'names': tuple(self.names)})]
        if self.params['publish_dynamic_joint_states']:
            surface.append(StateTopic(
                f'{self._prefix}dynamic_joint_states', DYNAMIC_JOINT_STATE_MESSAGE,
                self.set_dynamic_sink, {'joint_names': tuple(self.dynamic_names),
                                        'interface_names': tuple(self.dynamic_interfaces)}))
        return tuple(surface)

    def set_sink(self, sink: JointStateSink | None) -> None:
        """Where JointState samples go: ``sink(time, names, positions, velocities, efforts)``."""
        self._sink = sink

    def set_dynamic_sink(self, sink: DynamicJointStateSink | None) -> None:
        """Where DynamicJointState samples go: ``sink(time, values)``, one list per joint."""
        self._dynamic_sink = sink

    def state_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the state interfaces read, by joint of the robot (extra joints have none)."""
        return dict(self._selected)

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Choose the joints and interfaces published (see the module's design notes)."""
        handles, self._selected = self._select(joints)
        sources = self._field_sources
        self.names, self.dynamic_names, self.dynamic_interfaces = [], [], []
        self.positions, self.velocities, self.efforts = [], [], []
        self.dynamic_values = []
        self._joint_state_reads, self._dynamic_reads = [], []
        fields = (self.positions, self.velocities, self.efforts)
        offered = {interface for names in self._selected.values() for interface in names}
        for joint_field, field_sources in sources.items():
            mapped = field_sources[0]
            if mapped != joint_field and mapped not in offered:
                self._warn(f'{MAP_FIELD}.{joint_field}',
                           f"'{mapped}' is not a state interface of any published joint: "
                           f"JointState.{joint_field} is each joint's own '{joint_field}'")
        for handle in handles:
            selected = self._selected[handle.name]
            chosen = [next((name for name in sources[joint_field] if name in selected), None)
                      for joint_field in JOINT_STATE_FIELDS]
            if any(chosen):
                index = len(self.names)
                self.names.append(handle.name)
                for values, interface in zip(fields, chosen, strict=True):
                    values.append(self._value(handle, interface, values, index,
                                              self._joint_state_reads))
            values = []
            for index, interface in enumerate(selected):
                values.append(self._value(handle, interface, values, index, self._dynamic_reads))
            self.dynamic_names.append(handle.name)
            self.dynamic_interfaces.append(selected)
            self.dynamic_values.append(values)
        for extra in self.params['extra_joints']:
            if extra in self.dynamic_names:
                self._warn('extra_joints', f"'{extra}' is published with its own state already")
                continue
            self.names.append(extra)
            for values in fields:
                values.append(EXTRA_JOINT_VALUE)
            self.dynamic_names.append(extra)
            self.dynamic_interfaces.append(JOINT_STATE_FIELDS)
            self.dynamic_values.append([EXTRA_JOINT_VALUE] * len(JOINT_STATE_FIELDS))
        self.reset()

    def _select(self, joints: Mapping[str, JointHandle]) -> tuple[
            list[JointHandle], dict[str, tuple[str, ...]]]:
        """Return the joints published and the interfaces selected of each."""
        if self._selection is None:
            handles = list(joints.values())
            return handles, {handle.name: handle.state_interface_names for handle in handles}
        names, interfaces = self._selection
        handles, selected, missing = [], {}, []
        for name in names:
            handle = self.handle(joints, name, 'joints', commanded=False)
            offered = handle.state_interface_names
            missing += [f'{name}/{interface}' for interface in interfaces
                        if interface not in offered]
            chosen = tuple(interface for interface in interfaces if interface in offered)
            if chosen:
                handles.append(handle)
                selected[name] = chosen
        if not handles:
            raise self.error('interfaces', f"no joint named in 'joints' has any of "
                                           f"{', '.join(interfaces)} (their state interfaces: "
                                           f'{self._offered(joints, names)})')
        if missing:
            self._warn('interfaces', f"not published, the robot lacks them: {', '.join(missing)}")
        return handles, selected

    @staticmethod
    def _offered(joints: Mapping[str, JointHandle], names: Sequence[str]) -> str:
        return '; '.join(f"{name}: {', '.join(joints[name].state_interface_names)}"
                         for name in names)

    @staticmethod
    def _value(handle: JointHandle, interface: str | None, values: list[float], index: int,
               reads: list[Read]) -> float:
        """Return the value ``interface`` holds now; a measured one is also read on each sample."""
        if interface is None:
            return UNAVAILABLE
        if interface in MEASURED_STATES:
            reads.append((values, index, handle, interface))
            return getattr(handle, interface)
        return handle.other_states[interface]

    def _warn(self, field: str, problem: str) -> None:
        where = f'{self._source}: ' if self._source else ''
        warning = f'{where}{self.name}.{field}: {problem}'
        if warning not in self.config_warnings:
            self.config_warnings.append(warning)

    def reset(self) -> None:
        """Publish at the next update, then every period."""
        self._schedule.reset()

    def schedule(self) -> PeriodicSchedule:
        """Return the sample schedule: the loop calls :meth:`update` only when one is due."""
        return self._schedule

    def time_of_next_sample(self) -> float:
        """Sim time (s) at which the next sample is due."""
        return self._schedule.next_due

    def update(self, time: float, period: float) -> None:
        """Hand a sample to each connected sink when one is due."""
        schedule = self._schedule
        if time + DUE_EPSILON < schedule.next_due:  # the test of schedule.take, inlined
            return
        schedule.advance(time)
        sink = self._sink
        if sink is not None:
            for values, index, handle, interface in self._joint_state_reads:
                values[index] = getattr(handle, interface)
            sink(time, self.names, self.positions, self.velocities, self.efforts)
        dynamic_sink = self._dynamic_sink
        if dynamic_sink is not None:
            for values, index, handle, interface in self._dynamic_reads:
                values[index] = getattr(handle, interface)
            dynamic_sink(time, self.dynamic_values)
