"""sim_node's run recorded as a rosbag2 bag: the messages it publishes and the commands it takes.

The tee is at sim_node's ``create_publisher`` and ``create_subscription``
(see :class:`~pan_tilt_sim.ros.sim_node.SimNode`): with ``record:=<folder>``
each publisher created after start-up began is wrapped in a
:class:`RecordedPublisher`, and each subscription's callback records the
message it is handed before running.  So the bag holds exactly what
sim_node published -- ``/clock``, ``joint_states``, ``/tf``,
``/tf_static``, ``robot_description``, the controllers' state topics --
and every command it received, with no copy of any publishing logic.
Sensor topics (camera, depth, lidar, IMU, force-torque) are recorded only
with ``record_sensors:=true``: their messages are large and each costs a
rendering or a ray cast that nobody may want.

Design notes: docs/design/ros.md#recordingpy.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import Any

from rclpy.qos import QoSProfile
from rclpy.serialization import serialize_message

from pan_tilt_sim.ros.bag import BagWriter, qos_profile
from pan_tilt_sim.ros.ros_interfaces import NANOSECONDS_PER_SECOND

# Sensor messages: recorded only with record_sensors.
SENSOR_TYPES = frozenset({
    'sensor_msgs/msg/Image', 'sensor_msgs/msg/CameraInfo', 'sensor_msgs/msg/PointCloud2',
    'sensor_msgs/msg/LaserScan', 'sensor_msgs/msg/Imu', 'geometry_msgs/msg/WrenchStamped',
})


def type_name(message_type: type) -> str:
    """ROS's name of a message class: ``sensor_msgs/msg/JointState``."""
    return f"{message_type.__module__.split('.')[0]}/msg/{message_type.__name__}"


def _time_ns(time: Any) -> int:
    return time.sec * NANOSECONDS_PER_SECOND + time.nanosec


def stamp_reader(message_type: type) -> Callable[[Any], int | None] | None:
    """Return how to read a message's own time in ns (None: the type carries none)."""
    fields = message_type.get_fields_and_field_types()
    if fields.get('header') == 'std_msgs/Header':
        return lambda message: _time_ns(message.header.stamp)
    if fields.get('clock') == 'builtin_interfaces/Time':
        return lambda message: _time_ns(message.clock)
    if fields.get('transforms') == 'sequence<geometry_msgs/TransformStamped>':
        return lambda message: (_time_ns(message.transforms[0].header.stamp)
                                if message.transforms else None)
    return None


def offered_qos(profile: QoSProfile) -> list[dict[str, Any]]:
    """Return an rclpy QoS profile as rosbag2's ``offered_qos_profiles`` (one entry)."""
    def words(policy: Any) -> str:
        return policy.name.lower()

    return [qos_profile(
        history=words(profile.history), depth=profile.depth,
        reliability=words(profile.reliability), durability=words(profile.durability),
        deadline_ns=profile.deadline.nanoseconds, lifespan_ns=profile.lifespan.nanoseconds,
        liveliness=words(profile.liveliness),
        liveliness_lease_ns=profile.liveliness_lease_duration.nanoseconds,
        avoid_ros_namespace_conventions=profile.avoid_ros_namespace_conventions)]


class Recorder:
    """Records a node's publications and received messages into a bag folder.

    ``clock`` gives the present sim time in seconds; ``warn`` takes the
    one-line warning when the recording stops for a write error.
    """

    def __init__(self, folder: str, *, clock: Callable[[], float], sensors: bool,
                 warn: Callable[[str], None], field: str = "parameter 'record'") -> None:
        self.bag = BagWriter(folder, field=field, on_failure=warn)
        self._clock = clock
        self._sensors = sensors

    @property
    def folder(self) -> str:
        """The bag folder."""
        return str(self.bag.folder)

    @property
    def recording(self) -> bool:
        """Whether messages are still written (false once closed or after a write error)."""
        return self.bag.recording

    def now_ns(self) -> int:
        """Return the present sim time in nanoseconds."""
        return round(self._clock() * NANOSECONDS_PER_SECOND)

    def records(self, message_type: type) -> bool:
        """Whether messages of ``message_type`` are recorded (sensors only on request)."""
        return self._sensors or type_name(message_type) not in SENSOR_TYPES

    def tee_publisher(self, publisher: Any) -> Any:
        """Return ``publisher`` wrapped so that what it publishes is recorded too."""
        if not self.records(publisher.msg_type):
            return publisher
        key = self.bag.add_topic(publisher.topic_name, type_name(publisher.msg_type),
                                 offered_qos(publisher.qos_profile))
        return RecordedPublisher(publisher, self, key, stamp_reader(publisher.msg_type))

    def tee_subscription(self, subscription: Any) -> None:
        """Make ``subscription``'s callback record each message it is handed, before it runs."""
        if not self.records(subscription.msg_type):
            return
        key = self.bag.add_topic(subscription.topic_name, type_name(subscription.msg_type),
                                 offered_qos(subscription.qos_profile))
        callback = subscription.callback
        write = self.bag.write
        now_ns = self.now_ns
        raw = subscription.raw

        def record(message: Any) -> None:
            write(key, message if raw else serialize_message(message), now_ns())

        if _takes_message_info(callback):
            def recorded_with_info(message: Any, info: Any) -> None:
                record(message)
                callback(message, info)
            subscription.callback = recorded_with_info
        else:
            def recorded(message: Any) -> None:
                record(message)
                callback(message)
            subscription.callback = recorded

    def publisher(self, message_type: type, topic: str, qos: QoSProfile) -> BagPublisher:
        """Return a publisher of ``topic`` whose messages go to the bag only (no DDS)."""
        key = self.bag.add_topic(topic, type_name(message_type), offered_qos(qos))
        return BagPublisher(self, key, stamp_reader(message_type))

    def close(self) -> None:
        """Finish the bag (its MCAP index and metadata.yaml)."""
        self.bag.close()

    def discard(self) -> None:
        """Drop the bag and its folder (the node did not start)."""
        self.bag.discard()


def _takes_message_info(callback: Callable) -> bool:
    """Whether rclpy hands ``callback`` (message, message_info) rather than the message alone."""
    try:
        inspect.signature(callback).bind(object())
    except TypeError:
        return True
    return False


class RecordedPublisher:
    """An rclpy publisher whose messages also go to the bag; otherwise the publisher itself.

    Everything but :meth:`publish` and :meth:`get_subscription_count` is the
    wrapped publisher's (:attr:`publisher`).
    """

    def __init__(self, publisher: Any, recorder: Recorder, key: tuple[str, str],
                 stamp: Callable[[Any], int | None] | None) -> None:
        self.publisher = publisher
        self._recorder = recorder
        self._write = recorder.bag.write
        self._key = key
        self._stamp = stamp
        # Whether DDS has readers, as last asked; until asked (latched topics), publish.
        self._forward = True

    def publish(self, message: Any) -> None:
        """Record ``message`` and publish it (to DDS only where somebody subscribes)."""
        serialized = isinstance(message, bytes)
        data = message if serialized else serialize_message(message)
        if self._recorder.recording:
            time_ns = None if serialized or self._stamp is None else self._stamp(message)
            self._write(self._key, data, self._recorder.now_ns() if time_ns is None else time_ns)
        if self._forward:
            self.publisher.publish(data)

    def get_subscription_count(self) -> int:
        """DDS subscribers, plus one for the bag while it records."""
        count = self.publisher.get_subscription_count()
        self._forward = count > 0
        return count + 1 if self._recorder.recording else count

    def __getattr__(self, name: str) -> Any:
        return getattr(self.publisher, name)


class BagPublisher:
    """Writes the messages ``publish`` is given to the bag, at their stamps (a tool's run)."""

    def __init__(self, recorder: Recorder, key: tuple[str, str],
                 stamp: Callable[[Any], int | None] | None) -> None:
        self._recorder = recorder
        self._key = key
        self._stamp = stamp

    def publish(self, message: Any) -> None:
        """Record ``message`` (at its own stamp, else the present sim time)."""
        time_ns = self._stamp(message) if self._stamp is not None else None
        self._recorder.bag.write(self._key, serialize_message(message),
                                 self._recorder.now_ns() if time_ns is None else time_ns)
