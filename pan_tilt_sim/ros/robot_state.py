"""robot_description and TF, as robot_state_publisher would publish them.

* ``<ns>/robot_description`` (``std_msgs/msg/String``, reliable, transient
  local, depth 1): the URDF as the user wrote it (xacro's output, meshes
  still ``package://``), published once; late subscribers (RViz,
  robot_state_publisher) still get it.
* When ``tf2_msgs`` is importable and ``publish_tf`` is true: ``/tf_static``
  (transient local) for the fixed joints and the camera's optical frame, and
  ``/tf`` for the moving joints every ``TF_PERIOD_S`` of sim time, computed
  from the robot model's joint origins and the measured joint positions
  (mimic joints follow their leader).  Without tf2_msgs TF is off (sim_node's
  start-up line of features off says so).

TF leaves through a :class:`TfOutput`, so the computation can be checked
where tf2_msgs is not installed.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping, Sequence
from typing import Protocol

from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

from pan_tilt_sim.model.robot import RobotModel
from pan_tilt_sim.model.transforms import Transform
from pan_tilt_sim.ros import parameters as params
from pan_tilt_sim.ros.ros_interfaces import stamp
from pan_tilt_sim.schedule import PeriodicSchedule

TF_PERIOD_S = 0.02  # sim seconds between /tf messages (50 Hz, the joint_states rate)
TF_TOPIC = '/tf'
TF_STATIC_TOPIC = '/tf_static'
TF_QUEUE_DEPTH = 100
# A TF edge: parent frame, child frame, child pose in the parent frame.
Frame = tuple[str, str, Transform]
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)


class TfOutput(Protocol):
    """Where TF goes: ``/tf`` and ``/tf_static`` messages of TransformStamped lists."""

    def tf(self, transforms: list[TransformStamped]) -> None:
        """Publish the moving frames."""

    def tf_static(self, transforms: list[TransformStamped]) -> None:
        """Publish the fixed frames (latched)."""

    def has_readers(self) -> bool:
        """Whether anybody subscribes to /tf now."""


def latched_publisher(node: Node, message_type: type, topic: str):
    """Create a publisher whose last message late subscribers still receive."""
    return node.create_publisher(message_type, topic, LATCHED)


def tf_message_type() -> type | None:
    """Return ``tf2_msgs.msg.TFMessage``, or None where tf2_msgs is not installed."""
    try:
        return importlib.import_module('tf2_msgs.msg').TFMessage
    except ImportError:
        return None


class TfPublishers:
    """``/tf`` and ``/tf_static`` publishers of ``tf2_msgs/msg/TFMessage``."""

    def __init__(self, node: Node, message_type: type) -> None:
        self._type = message_type
        self._tf = node.create_publisher(message_type, TF_TOPIC, TF_QUEUE_DEPTH)
        self._static = latched_publisher(node, message_type, TF_STATIC_TOPIC)

    def tf(self, transforms: list[TransformStamped]) -> None:
        """Publish the moving frames on /tf."""
        self._tf.publish(self._type(transforms=transforms))

    def tf_static(self, transforms: list[TransformStamped]) -> None:
        """Publish the fixed frames on /tf_static."""
        self._static.publish(self._type(transforms=transforms))

    def has_readers(self) -> bool:
        """Whether anybody subscribes to /tf now."""
        return self._tf.get_subscription_count() > 0


def create_tf_sink(node: Node) -> TfOutput | None:
    """Return TF publishers on ``node``, or None where tf2_msgs is not installed."""
    message_type = tf_message_type()
    return None if message_type is None else TfPublishers(node, message_type)


def transform_message(parent: str, child: str, transform: Transform, time: float,
                      into: TransformStamped | None = None) -> TransformStamped:
    """Return a ``geometry_msgs/TransformStamped`` from ``parent`` to ``child``."""
    message = TransformStamped() if into is None else into
    stamp(time, message.header.stamp)
    message.header.frame_id = parent
    message.child_frame_id = child
    translation = message.transform.translation
    translation.x, translation.y, translation.z = transform.translation
    rotation = message.transform.rotation
    rotation.x, rotation.y, rotation.z, rotation.w = transform.rotation
    return message


def static_transforms(model: RobotModel, extra: Sequence[Frame] = ()) -> list[Frame]:
    """Return (parent, child, transform) of every fixed joint, then the ``extra`` frames."""
    fixed = [(joint.parent, joint.child, joint.transform()) for joint in model.fixed_joints]
    return fixed + list(extra)


def moving_transforms(model: RobotModel, positions: Mapping[str, float]) -> list[Frame]:
    """Return (parent, child, transform) of every moving joint at ``positions``.

    Joints missing from ``positions`` (mimic joints) follow their leader.
    """
    return [(joint.parent, joint.child,
             joint.transform(model.joint_position(positions, joint.name)))
            for joint in model.moving_joints]


class RobotStatePublisher:
    """Publishes robot_description once and, given a TF sink, the robot's TF."""

    def __init__(self, node: Node, model: RobotModel, urdf_xml: str,
                 description_topic: str | None, clock: Callable[[], float],
                 positions: Callable[[], Mapping[str, float]],
                 extra_static: Sequence[Frame] = (),
                 tf_sink_factory: Callable[[Node], TfOutput | None] | None = None, *,
                 publish_tf_default: bool = True) -> None:
        """``description_topic`` None: the description came from that topic; none is published."""
        self._model = model
        self._clock = clock
        self._positions = positions
        self._description_publisher = None
        if description_topic is not None:
            self._description_publisher = latched_publisher(node, String, description_topic)
            self._description_publisher.publish(String(data=urdf_xml))
        enabled = params.declare(
            node, 'publish_tf', params.BOOL, publish_tf_default,
            'Publish /tf and /tf_static (needs tf2_msgs); turn off when '
            'robot_state_publisher does it.')
        self.static_frames = static_transforms(model, extra_static)
        self._schedule = PeriodicSchedule(TF_PERIOD_S)
        self._readers = True  # until the first refresh_readers()
        factory = create_tf_sink if tf_sink_factory is None else tf_sink_factory
        self.tf_wanted = enabled
        self._sink = factory(node) if enabled else None
        if self._sink is None:
            return  # the node says, with the other features off, why (tf2_msgs missing)
        time = clock()
        self._sink.tf_static([transform_message(*frame, time) for frame in self.static_frames])
        self._messages = [TransformStamped() for _ in model.moving_joints]

    @property
    def publishes_tf(self) -> bool:
        """Whether TF is being published."""
        return self._sink is not None

    def refresh_readers(self) -> None:
        """Ask whether anybody subscribes to /tf (nothing is computed for nobody)."""
        self._readers = self._sink is not None and self._sink.has_readers()

    def next_step(self, step: int, time_step: float) -> int | None:
        """Return the next step after ``step`` at which /tf is due (None: nobody listens)."""
        if not self._readers or self._sink is None:
            return None
        return self._schedule.next_step(step, time_step)

    def update(self) -> None:
        """Publish /tf for the moving joints when due (and somebody listens)."""
        if self._sink is None:
            return
        now = self._clock()
        if not self._schedule.take(now) or not self._readers:
            return
        frames = moving_transforms(self._model, self._positions())
        for frame, message in zip(frames, self._messages, strict=True):
            transform_message(*frame, now, message)
        self._sink.tf(self._messages)

    def stop(self) -> None:
        """Publish no more TF (the robot left the world)."""
        self._sink = None
        self._readers = False

    def reset(self) -> None:
        """Start the TF schedule again (after sim time was reset or moved)."""
        self._schedule.reset()
