"""What ros_gz_bridge entries do to sim_node's topics: the ROS names and types they give.

sim_node publishes and subscribes its robot's gz topics on ROS under their gz names
(as an identity bridge would).  The ``parameter_bridge`` and ``image_bridge``
stand-ins set the ``gz_bridge`` parameter (entries of
:mod:`pan_tilt_sim.model.gz_bridge`); a topic created afterwards whose name is an
entry's gz topic is created under the entry's ROS name, and a subscription under its
ROS type where sim_node's converts (TwistStamped and Twist): the simulation's own
endpoints move, no message is copied.  A spawned robot is built once every bridge
announced on :data:`ANNOUNCE_TOPIC` has handed over (see :mod:`.robot_spawn`); an
entry for a topic that exists already (its bridge came late: start-up order and
discovery are not in the launch file's hands) is relayed instead, as ros_gz_bridge
copies: the gz name stays and the messages are copied to and from the ROS name.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterable
from typing import Any

from rcl_interfaces.msg import ParameterDescriptor, SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile

from pan_tilt_sim.model.gz_bridge import BridgeEntry, BridgeError, decode

PARAMETER = 'gz_bridge'
# Each bridge stand-in publishes on this hidden topic from its start, so that sim_node
# knows a bridge is coming and builds a spawned robot only once it has handed over.
ANNOUNCE_TOPIC = '/_pan_tilt_sim/gz_bridge'
UNKNOWN_NODE_NAME = '_NODE_NAME_UNKNOWN_'  # rmw's name for a node not discovered yet
TWIST, TWIST_STAMPED = 'geometry_msgs/msg/Twist', 'geometry_msgs/msg/TwistStamped'


def type_name(message_type: type) -> str:
    """``geometry_msgs/msg/Twist`` of the class."""
    package, kind, _module = message_type.__module__.split('.')[:3]
    return f'{package}/{kind}/{message_type.__name__}'


def message_class(name: str) -> type:
    """Return the class of ``package/msg/Name``."""
    package, kind, leaf = name.split('/')
    return getattr(importlib.import_module(f'{package}.{kind}'), leaf)


def _converter(ros_type: str, sim_type: str) -> Callable[[Any], Any] | None:
    """Return a function from a ``ros_type`` message to a ``sim_type`` one, if one exists."""
    if (ros_type, sim_type) == (TWIST_STAMPED, TWIST):
        return lambda message: message.twist
    if (ros_type, sim_type) == (TWIST, TWIST_STAMPED):
        stamped = message_class(TWIST_STAMPED)
        return lambda message: stamped(twist=message)
    return None


class BridgedTopics:
    """The ``gz_bridge`` parameter and the topic routes it gives (see the module)."""

    def __init__(self, node: Node) -> None:
        self._node = node
        self._entries: dict[str, BridgeEntry] = {}  # by gz topic, absolute
        self._created: dict[str, str] = {}  # topic as sim_node names it -> its type name
        self._published: set[str] = set()  # those of them sim_node publishes (else reads)
        # Entries that came after their topic: (gz topic, ROS topic) -> the relay's endpoints.
        self.relays: dict[tuple[str, str], tuple[Any, Any]] = {}
        self._sources: set[str] = set()  # the bridges that handed their entries over
        node.declare_parameter(PARAMETER, Parameter.Type.STRING_ARRAY, ParameterDescriptor(
            description="ros_gz_bridge entries ('gz_topic|ros_topic|ros_type|gz_type|"
            "direction', after the bridge node's name), set by pan_tilt_sim's parameter_bridge "
            "and image_bridge: the ROS names and types of the simulation's gz topics."))
        node.add_on_set_parameters_callback(self._check)
        node.add_post_set_parameters_callback(self._apply)

    def publisher(self, message_type: type, topic: str) -> tuple[type, str]:
        """Return the type and name to create sim_node's publisher of ``topic`` with."""
        resolved = self._resolve(topic)
        self._created[resolved] = type_name(message_type)
        self._published.add(resolved)
        entry = self._entries.get(resolved)
        if entry is None or not entry.to_ros:
            return message_type, topic
        if entry.ros_type != type_name(message_type):
            self._node.get_logger().warning(
                f"gz_bridge: '{entry.gz_topic}' is published as {type_name(message_type)}, "
                f'not {entry.ros_type}: the type stays')
        return message_type, entry.ros_topic

    def subscription(self, message_type: type, topic: str,
                     callback: Callable) -> tuple[type, str, Callable]:
        """Return the type, name and callback to create sim_node's subscription with."""
        resolved = self._resolve(topic)
        self._created[resolved] = type_name(message_type)
        entry = self._entries.get(resolved)
        if entry is None or not entry.from_ros:
            return message_type, topic, callback
        if entry.ros_type == type_name(message_type):
            return message_type, entry.ros_topic, callback
        convert = _converter(entry.ros_type, type_name(message_type))
        if convert is None:
            self._node.get_logger().warning(
                f"gz_bridge: '{entry.gz_topic}' is read as {type_name(message_type)}, not "
                f'{entry.ros_type}: the type stays')
            return message_type, entry.ros_topic, callback
        return (message_class(entry.ros_type), entry.ros_topic,
                lambda message: callback(convert(message)))

    def _resolve(self, topic: str) -> str:
        return self._node.resolve_topic_name(topic)

    def _in_graph(self) -> set[str]:
        """Return the bridge stand-ins announcing themselves now, by full node name.

        An endpoint whose node DDS has not named yet (rmw's placeholder name, right
        after discovery) is left out: it would count one bridge twice, under two names.
        """
        return {f"{info.node_namespace.rstrip('/')}/{info.node_name}"
                for info in self._node.get_publishers_info_by_topic(ANNOUNCE_TOPIC)
                if info.node_name != UNKNOWN_NODE_NAME}

    def known(self) -> int:
        """Return how many bridge stand-ins have been seen: handed over, or in the graph now."""
        return len(self._in_graph() | self._sources)

    def pending(self) -> list[str]:
        """Return the bridge stand-ins in the graph that have not handed their entries over."""
        return sorted(self._in_graph() - self._sources)

    def names_any(self, topics: Iterable[str]) -> bool:
        """Return whether a handed-over entry's gz topic is one of ``topics`` (absolute).

        A topic sim_node has already (another robot's too, ``/tf`` say) does not count:
        its entry may be another robot's bridge's.
        """
        return any(topic in self._entries and topic not in self._created for topic in topics)

    def _entries_of(self, changed: list[Parameter]) -> list[BridgeEntry] | None:
        for parameter in changed:
            if parameter.name == PARAMETER:
                return decode(list(parameter.value or ()))[1]
        return None

    def _check(self, changed: list[Parameter]) -> SetParametersResult:
        try:
            entries = self._entries_of(changed)
        except BridgeError as err:
            return SetParametersResult(successful=False, reason=str(err))
        for entry in entries or ():
            created = self._created.get(entry.gz_topic)
            retyped = (entry.ros_topic == entry.gz_topic and entry.ros_type != created
                       and _converter(entry.ros_type, created) is not None)
            if created is not None and retyped:  # no relay on one name with two types
                return SetParametersResult(successful=False, reason=(
                    f"'{entry.gz_topic}' exists already as {created}: it cannot become "
                    f'{entry.ros_type} now; start the bridge before the robot is spawned'))
        return SetParametersResult(successful=True)

    def _apply(self, changed: list[Parameter]) -> None:
        for parameter in changed:
            if parameter.name == PARAMETER:
                source, entries = decode(list(parameter.value or ()))
                self._sources.add(source)
                for entry in entries:
                    self._entries[entry.gz_topic] = entry
                    if entry.gz_topic in self._created:
                        self._relay(entry)

    def _relay(self, entry: BridgeEntry) -> None:
        """Copy an existing topic's messages to (or from) the entry's ROS name and type."""
        gz_topic, ros_topic = entry.gz_topic, entry.ros_topic
        sim_type = self._created[gz_topic]
        published = gz_topic in self._published
        # On its own name a topic keeps its type (a retype is refused): nothing to copy.
        if ((gz_topic, ros_topic) in self.relays or ros_topic == gz_topic
                or not (entry.to_ros if published else entry.from_ros)):
            return
        node, sim_class = self._node, message_class(sim_type)
        convert = (None if entry.ros_type == sim_type
                   else _converter(entry.ros_type, sim_type))
        if entry.ros_type != sim_type and (published or convert is None):
            node.get_logger().warning(
                f"gz_bridge: '{gz_topic}' is {sim_type}, not {entry.ros_type}: the type stays")
        qos = self._qos(gz_topic, published)
        # rclpy's own create_*: these endpoints are not the simulation's, nothing renames them.
        if published:
            out = Node.create_publisher(node, sim_class, ros_topic, qos)
            into = Node.create_subscription(node, sim_class, gz_topic, out.publish, qos)
        else:
            out = Node.create_publisher(node, sim_class, gz_topic, qos)
            if convert is None:
                into = Node.create_subscription(node, sim_class, ros_topic, out.publish, qos)
            else:
                into = Node.create_subscription(
                    node, message_class(entry.ros_type), ros_topic,
                    lambda message: out.publish(convert(message)), qos)
        self.relays[(gz_topic, ros_topic)] = (into, out)
        node.get_logger().info(
            f"gz_bridge: '{gz_topic}' existed before its bridge handed over: its messages are "
            f"copied {'to' if published else 'from'} '{ros_topic}'")

    def _qos(self, gz_topic: str, published: bool) -> QoSProfile:
        """Return a QoS with the reliability and durability of sim_node's ``gz_topic``."""
        node = self._node
        infos = (node.get_publishers_info_by_topic(gz_topic) if published
                 else node.get_subscriptions_info_by_topic(gz_topic))
        for info in infos:
            if (info.node_name, info.node_namespace) == (node.get_name(), node.get_namespace()):
                return QoSProfile(depth=10, reliability=info.qos_profile.reliability,
                                  durability=info.qos_profile.durability)
        return QoSProfile(depth=10)
