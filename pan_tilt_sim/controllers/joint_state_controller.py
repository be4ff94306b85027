"""``joint_state_controller/JointStateController`` (ROS 2: joint_state_broadcaster).

Every ``1 / publish_rate`` seconds of sim time it hands a sample of every
movable joint -- name, position, velocity, effort -- to its sink (the node
turns that into a ``sensor_msgs/msg/JointState`` stamped with sim time).
The sample's lists are reused from call to call; a sink must copy them.

The rate is ``publish_rate`` when given (ROS 1 style); otherwise
``update_rate``, since ROS 2's joint_state_broadcaster publishes at every
update of its controller_manager (a ros2_control-style file gives every
controller the controller_manager's rate, 100 Hz by default); otherwise
50 Hz, the pan/tilt example's rate.  ``joints`` (as joint_state_broadcaster names it)
limits the sample to those joints, in that order; empty or absent means
every movable joint.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

from pan_tilt_sim.controllers.base import Controller, JointHandle
from pan_tilt_sim.controllers.parameter_spec import (
    BOOL,
    DOUBLE,
    STRING,
    STRING_ARRAY,
    Param,
    ParameterSpec,
    gt,
    names,
    unique,
)
from pan_tilt_sim.controllers.surface import Endpoint, StateTopic
from pan_tilt_sim.schedule import DUE_EPSILON, PeriodicSchedule

DEFAULT_PUBLISH_RATE = 50.0  # Hz, as in the pan/tilt example's YAML
RATE_FIELDS = ('publish_rate', 'update_rate')  # the first one given sets the rate

JointStateSink = Callable[[float, Sequence[str], Sequence[float], Sequence[float],
                           Sequence[float]], None]


class JointStateController(Controller):
    """Publishes the joints' position, velocity and effort at its rate of sim time."""

    type_names = ('joint_state_controller/JointStateController',
                  'joint_state_broadcaster/JointStateBroadcaster')
    parameters = ParameterSpec([
        Param('publish_rate', DOUBLE, None, 'Samples per second of sim time (ROS 1).',
              (gt(0.0),)),
        Param('update_rate', DOUBLE, None, "The controller's update rate (Hz); the "
              "controller_manager's by default.", (gt(0.0),)),
        Param('joints', STRING_ARRAY, [], 'The joints to publish, in this order; empty: every '
              'movable joint.', (names(), unique()), read_only=True),
        Param('extra_joints', STRING_ARRAY, [], 'Names published with zero state beside the '
              "robot's joints.", (names(), unique()), read_only=True),
        Param('interfaces', STRING_ARRAY, [], 'The state interfaces to publish; empty: all.',
              (unique(),), read_only=True),
        Param('use_local_topics', BOOL, False, "Publish on ~/joint_states (the controller's "
              'namespace) instead of joint_states.', read_only=True),
        Param('map_interface_to_joint_state.position', STRING, 'position',
              'The interface published as JointState.position.', read_only=True),
        Param('map_interface_to_joint_state.velocity', STRING, 'velocity',
              'The interface published as JointState.velocity.', read_only=True),
        Param('map_interface_to_joint_state.effort', STRING, 'effort',
              'The interface published as JointState.effort.', read_only=True),
    ])

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        field = next((name for name in RATE_FIELDS if name in self.params), None)
        rate = self.params[field] if field else DEFAULT_PUBLISH_RATE
        self._schedule = PeriodicSchedule(1.0 / float(rate))
        self._joint_names = tuple(self.params['joints'])
        self._sink: JointStateSink | None = None
        self._handles: list[JointHandle] = []

    @property
    def publish_period(self) -> float:
        """Seconds of sim time between samples."""
        return self._schedule.period

    @property
    def publish_rate(self) -> float:
        """Samples per second of sim time."""
        return 1.0 / self._schedule.period

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the ``sensor_msgs/msg/JointState`` publisher on ``joint_states``."""
        return (StateTopic('joint_states', 'sensor_msgs/msg/JointState', self.set_sink,
                           {'names': tuple(self.names)}),)

    def set_sink(self, sink: JointStateSink | None) -> None:
        """Where samples go: ``sink(time, names, positions, velocities, efforts)``."""
        self._sink = sink

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Take the ``joints`` named, else every movable joint in the description's order."""
        if self._joint_names:
            self._handles = [self.handle(joints, name, 'joints', commanded=False)
                             for name in self._joint_names]
        else:
            self._handles = list(joints.values())
        self.names = [handle.name for handle in self._handles]
        count = len(self._handles)
        self.positions = [0.0] * count
        self.velocities = [0.0] * count
        self.efforts = [0.0] * count
        self.reset()

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
        """Hand a sample to the sink when one is due."""
        schedule = self._schedule
        if time + DUE_EPSILON < schedule.next_due:  # the test of schedule.take, inlined
            return
        schedule.advance(time)
        if self._sink is None:
            return
        positions, velocities, efforts = self.positions, self.velocities, self.efforts
        for index, handle in enumerate(self._handles):
            positions[index] = handle.position
            velocities[index] = handle.velocity
            efforts[index] = handle.effort
        self._sink(time, self.names, positions, velocities, efforts)
