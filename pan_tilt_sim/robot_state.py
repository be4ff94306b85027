"""robot_description and TF, as robot_state_publisher would publish them.

* ``<ns>/robot_description`` (``std_msgs/msg/String``, reliable, transient
  local, depth 1): the processed URDF, published once; late subscribers
  (RViz, robot_state_publisher) still get it.
* When ``tf2_msgs`` is importable and ``publish_tf`` is true: ``/tf_static``
  (transient local) for the fixed joints and the camera's optical frame, and
  ``/tf`` for the moving joints every ``TF_PERIOD_S`` of sim time, computed
  from the URDF's joint origins and the measured joint positions
  (:mod:`pan_tilt_sim.kinematics`).  Without tf2_msgs, one info line says TF
  is off.
"""

from __future__ import annotations

import importlib
from collections.abc import Mapping, Sequence

from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

from pan_tilt_sim import parameters as params
from pan_tilt_sim.description import Mimic
from pan_tilt_sim.engine import Simulation
from pan_tilt_sim.kinematics import KinematicTree, Transform, parse_kinematics
from pan_tilt_sim.ros_interfaces import stamp

TF_PERIOD_S = 0.02  # sim seconds between /tf messages (50 Hz, the joint_states rate)
TF_TOPIC = '/tf'
TF_STATIC_TOPIC = '/tf_static'
TF_QUEUE_DEPTH = 100
DUE_EPSILON = 1e-9
# A TF edge: parent frame, child frame, child pose in the parent frame.
Frame = tuple[str, str, Transform]
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)


def latched_publisher(node: Node, message_type: type, topic: str):
    """Create a publisher whose last message late subscribers still receive."""
    return node.create_publisher(message_type, topic, LATCHED)


def tf_message_type() -> type | None:
    """Return ``tf2_msgs.msg.TFMessage``, or None where tf2_msgs is not installed."""
    try:
        return importlib.import_module('tf2_msgs.msg').TFMessage
    except ImportError:
        return None


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


def joint_position(positions: Mapping[str, float], joint: str,
                   mimics: Mapping[str, Mimic]) -> float:
    """Return ``joint``'s position; a joint the physics does not drive follows its mimic."""
    if joint in positions:
        return positions[joint]
    mimic = mimics.get(joint)
    if mimic is None:
        return 0.0
    return mimic.multiplier * positions.get(mimic.joint, 0.0) + mimic.offset


def static_transforms(tree: KinematicTree, extra: Sequence[Frame] = ()) -> list[Frame]:
    """Return (parent, child, transform) of every fixed joint, then the ``extra`` frames."""
    fixed = [(joint.parent, joint.child, joint.transform()) for joint in tree.fixed_joints]
    return fixed + list(extra)


def moving_transforms(tree: KinematicTree, positions: Mapping[str, float],
                      mimics: Mapping[str, Mimic] | None = None) -> list[Frame]:
    """Return (parent, child, transform) of every moving joint at ``positions``."""
    mimics = mimics or {}
    return [(joint.parent, joint.child,
             joint.transform(joint_position(positions, joint.name, mimics)))
            for joint in tree.moving_joints]


class RobotStatePublisher:
    """Publishes robot_description once and, where tf2_msgs exists, the robot's TF."""

    def __init__(self, node: Node, simulation: Simulation, description_topic: str,
                 extra_static: Sequence[Frame] = ()) -> None:
        self._simulation = simulation
        self._description_publisher = latched_publisher(node, String, description_topic)
        self._description_publisher.publish(String(data=simulation.description.urdf_xml))
        enabled = params.declare(
            node, 'publish_tf', params.BOOL, True,
            'Publish /tf and /tf_static (needs tf2_msgs); turn off when '
            'robot_state_publisher does it.')
        self.tree: KinematicTree = parse_kinematics(simulation.description.urdf_xml)
        self._mimics = {joint.name: joint.mimic for joint in simulation.description.joints
                        if joint.mimic is not None}
        self.static_frames = static_transforms(self.tree, extra_static)
        self._tf_type = tf_message_type() if enabled else None
        self._next_due = 0.0
        if self._tf_type is None:
            if enabled:
                node.get_logger().info(
                    'TF is off: tf2_msgs is not installed (robot_description is published; '
                    'robot_state_publisher can publish TF from it and joint_states)')
            return
        self._tf_publisher = node.create_publisher(self._tf_type, TF_TOPIC, TF_QUEUE_DEPTH)
        self._static_publisher = latched_publisher(node, self._tf_type, TF_STATIC_TOPIC)
        time = simulation.time
        self._static_publisher.publish(self._tf_type(transforms=[
            transform_message(*frame, time) for frame in self.static_frames]))
        self._message = self._tf_type(
            transforms=[TransformStamped() for _ in self.tree.moving_joints])

    @property
    def publishes_tf(self) -> bool:
        """Whether TF is being published."""
        return self._tf_type is not None

    def update(self) -> None:
        """Publish /tf for the moving joints when due."""
        if self._tf_type is None:
            return
        now = self._simulation.time
        if now + DUE_EPSILON < self._next_due:
            return
        self._next_due = (int((now + DUE_EPSILON) / TF_PERIOD_S) + 1) * TF_PERIOD_S
        frames = moving_transforms(self.tree, self._simulation.joint_positions(), self._mimics)
        for frame, message in zip(frames, self._message.transforms, strict=True):
            transform_message(*frame, now, message)
        self._tf_publisher.publish(self._message)
